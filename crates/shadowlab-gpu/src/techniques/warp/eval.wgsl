// Warped shadow-map evaluation: each evaluated sample is offset (normal offset, constant and
// slope-scaled bias) in world units of one *warped* texel at the sample, projected, cropped to
// the desired view, warped through the same function as the depth pass, and compared with an
// NxN kernel of warped texels. The warped texel's world size (`bias_mode`, ext.y) comes from the
// warp's Jacobian J (finite differences over one texel): mode 0, the cropped texel divided by
// the smallest singular value of J (isotropic: the largest footprint, which leaks where the
// warp compresses one direction); mode 1, divided only where J magnifies every direction; mode
// 2, the footprint along the receiver's depth-gradient direction, `gradient_footprint`
// (docs/bench/warp_bias.md); mode 3, mode 2's largest at the sample and one texel to each side;
// mode 4, mode 2's with J the secant Jacobian of the warped texel the sample falls in
// (`texel_jacobian`: exact across the warp's kinks, docs/bench/warp_kinks.md). Also counts the samples per warped texel
// (sampling statistics after warping).

// The map, its samples' counts and the light's axis come from the entry point's file
// (eval_main.wgsl for one map: `map_texel`, `map_compare`, `count_texel`, `light_axis`).

// The knobs that choose code paths, fixed per map at pipeline creation (eval.rs `constants`,
// equal to the uniform's `bias_mode`, `dv_mode` and `perspective`; PARABOLOID and WARPED in
// params.wgsl).
override BIAS_MODE: u32;
override CLOSE_CRACKS: bool;
override PERSPECTIVE: bool;

// The nearest depth of the 3x3 texels around uv: closes the sub-texel cracks that adaptive
// subdivision leaves at T-junctions (the finer side's midpoints are warped, the coarser side's
// edge is straight), at the price of growing occluders by one warped texel.
fn min_depth_3x3(uv: vec2<f32>, res: u32) -> f32 {
    let c = vec2<i32>(clamp(uv * f32(res), vec2<f32>(0.0), vec2<f32>(f32(res) - 1.0)));
    var d = 1.0;
    for (var y = -1; y <= 1; y++) {
        for (var x = -1; x <= 1; x++) {
            let t = clamp(c + vec2<i32>(x, y), vec2<i32>(0), vec2<i32>(i32(res) - 1));
            d = min(d, map_texel(t));
        }
    }
    return d;
}

// Singular values (smallest, largest) of the 2x2 matrix with columns a and b (warp.rs
// `singular_values`).
fn singular_values(a: vec2<f32>, b: vec2<f32>) -> vec2<f32> {
    let e = dot(a, a);
    let g = dot(b, b);
    let f = dot(a, b);
    let tr = 0.5 * (e + g);
    let det = e * g - f * f;
    let d = sqrt(max(tr * tr - det, 0.0));
    return sqrt(max(vec2<f32>(tr - d, tr + d), vec2<f32>(0.0)));
}

// World footprint of one warped texel along the receiver's depth-gradient direction (bias mode
// 2): m = the unit direction, across the light, in which the receiver's depth changes (the
// normal's part across l); A = d(cropped texels)/d(metres) across the light at p (two projected
// steps); J = the warp's Jacobian. One warped texel spans M = A^-1 J^-1 metres, so its extent
// along m is |M^T m| = |J^-T A^-T m|. Where the receiver faces the light (no gradient), the
// geometric mean T / sqrt(det J). Capped at `ext.z` cropped texels (0: 1 / MIN_WARP_SCALE).
// `t`: world size of one cropped texel at p.
fn gradient_footprint(p: vec3<f32>, n: vec3<f32>, l: vec3<f32>, r: vec4<f32>, j: mat2x2<f32>, t: f32) -> f32 {
    let res = wp.res;
    let cap = select(1.0 / MIN_WARP_SCALE, wp.footprint_cap, wp.footprint_cap > 0.0) * t;
    let detj = j[0].x * j[1].y - j[1].x * j[0].y;
    let geo = t / sqrt(max(abs(detj), 1e-12));
    var a = vec3<f32>(1.0, 0.0, 0.0);
    if abs(l.x) > 0.8 {
        a = vec3<f32>(0.0, 1.0, 0.0);
    }
    let e1 = normalize(cross(l, a));
    let e2 = cross(l, e1);
    let lat = vec2<f32>(dot(n, e1), dot(n, e2));
    let c0 = base_clip(wp, p);
    let c1 = base_clip(wp, p + e1 * t);
    let c2 = base_clip(wp, p + e2 * t);
    if length(lat) < 1e-3 || min(min(c0.w, c1.w), c2.w) <= 1e-7 || abs(detj) < 1e-12 {
        return min(geo, cap);
    }
    let m = lat / length(lat);
    let v0 = to_dv(clip_to_map(c0).xy, r) * res;
    // columns: cropped texels per metre along e1, e2
    let a1 = (to_dv(clip_to_map(c1).xy, r) * res - v0) / t;
    let a2 = (to_dv(clip_to_map(c2).xy, r) * res - v0) / t;
    let deta = a1.x * a2.y - a2.x * a1.y;
    if abs(deta) < 1e-12 {
        return min(geo, cap);
    }
    // y = A^-T m: solve A^T y = m (rows of A^T: a1, a2)
    let y = vec2<f32>(a2.y * m.x - a1.y * m.y, -a2.x * m.x + a1.x * m.y) / deta;
    // z = J^-T y: solve J^T z = y (rows of J^T: j[0], j[1])
    let z = vec2<f32>(j[1].y * y.x - j[0].y * y.y, -j[1].x * y.x + j[0].x * y.y) / detj;
    return min(length(z), cap);
}

// Secant Jacobian of the warped texel that contains c (bias mode 4): the texel's corners pulled
// back through the warp exactly (lookup.wgsl `unwarp_exact`) span M (cropped per warped
// texel), J = M^-1 / res. Where the warp is linear over the texel this is the Jacobian; across
// a kink it is the texel's own extent, which the central difference at the sample can
// underestimate several times (docs/bench/warp_kinks.md). None (w = 0) off the map.
fn texel_jacobian(c: vec2<f32>) -> mat2x2<f32> {
    let res = wp.res;
    if any(c < vec2<f32>(0.0)) || any(c >= vec2<f32>(1.0)) {
        return mat2x2<f32>(vec2<f32>(0.0), vec2<f32>(0.0));
    }
    let t = floor(c * res);
    let a = unwarp_exact(t / res, vec2<f32>(-1.0));
    let m0 = unwarp_exact((t + vec2<f32>(1.0, 0.0)) / res, vec2<f32>(-1.0)) - a;
    let m1 = unwarp_exact((t + vec2<f32>(0.0, 1.0)) / res, vec2<f32>(-1.0)) - a;
    let det = (m0.x * m1.y - m1.x * m0.y) * res;
    if abs(det) < 1e-20 {
        return mat2x2<f32>(vec2<f32>(0.0), vec2<f32>(0.0));
    }
    return mat2x2<f32>(vec2<f32>(m1.y, -m0.y) / det, vec2<f32>(-m1.x, m0.x) / det);
}

// Central-difference Jacobian of the warp at u over +-h: columns d warp / dx, d warp / dy.
fn jacobian(u: vec2<f32>, h: f32) -> mat2x2<f32> {
    let jx = (warp(u + vec2<f32>(h, 0.0)) - warp(u - vec2<f32>(h, 0.0))) / (2.0 * h);
    let jy = (warp(u + vec2<f32>(0.0, h)) - warp(u - vec2<f32>(0.0, h))) / (2.0 * h);
    return mat2x2<f32>(jx, jy);
}

// The visibility of one view sample through the map (and, counting, its warped texel counted).
fn eval_sample(s: Sample) {
    let p = s.p;
    let n = s.n;
    let l = to_light(light, p);
    let res = wp.res;
    let r = dv_rect();

    let m0 = clip_to_map(base_clip(wp, p));
    let u0 = to_dv(m0.xy, r);
    let c0 = warp(u0);
    if COUNT_SAMPLES && all(c0 >= vec2<f32>(0.0)) && all(c0 < vec2<f32>(1.0)) {
        let t = vec2<u32>(c0 * res);
        count_texel(t.y * u32(res) + t.x);
    }

    // world size of one cropped texel at p, then of one warped texel
    var texel = wp.texel_world * max(r.z - r.x, r.w - r.y);
    if PERSPECTIVE {
        texel *= max(dot(p - light.position.xyz, light_axis()), 0.0);
    }
    if PARABOLOID {
        // texel.x = 2 / res radians per texel at the rim; (1 + n.z) x that in general
        texel *= distance(p, light.position.xyz) * (1.0 + max(hemisphere_side(wp, p), 0.0));
    }
    if WARPED {
        let j = jacobian(u0, 0.5 / res);
        let sv = singular_values(j[0], j[1]);
        if BIAS_MODE >= 4u {
            // mode 4: the secant Jacobian of the warped texel the sample falls in (the central
            // difference where that texel is off the map or collapsed)
            var jt = texel_jacobian(c0);
            if jt[0].x * jt[1].y - jt[1].x * jt[0].y == 0.0 {
                jt = j;
            }
            texel = gradient_footprint(p, n, l, r, jt, texel);
        } else if BIAS_MODE == 3u {
            // mode 3: the largest gradient footprint at u0 and one texel to each side (the
            // warp's kinks: the Jacobian changes within a texel)
            var f = gradient_footprint(p, n, l, r, j, texel);
            for (var k = 0; k < 4; k++) {
                let o = select(vec2<f32>(f32(2 * (k & 1) - 1), 0.0), vec2<f32>(0.0, f32(2 * (k & 1) - 1)), k >= 2) / res;
                f = max(f, gradient_footprint(p, n, l, r, jacobian(u0 + o, 0.5 / res), texel));
            }
            texel = f;
        } else if BIAS_MODE == 2u {
            texel = gradient_footprint(p, n, l, r, j, texel);
        } else if BIAS_MODE == 1u {
            // the cropped texel, shrunk only where the warp magnifies in every direction
            texel /= clamp(sv.x, 1.0, 1e3);
        } else {
            // clamped: a collapsed (unsampled) region would ask for an unbounded bias
            texel /= clamp(sv.x, MIN_WARP_SCALE, 1e3);
        }
    }
    let cos_t = clamp(dot(n, l), 1e-4, 1.0);
    let tan_t = min(sqrt(1.0 - cos_t * cos_t) / cos_t, wp.max_slope);
    let k = i32(wp.pcf);
    let half = f32(k - 1) * 0.5;
    let q = p + n * (wp.normal_offset * texel) + l * ((wp.bias + (wp.slope_bias + half) * tan_t) * texel);
    let a = base_clip(wp, q);
    let m = clip_to_map(a);
    var u = warp(to_dv(m.xy, r));
    if PARABOLOID && a.w > 0.0 {
        // a biased point that crossed the split plane reads the map's border texels
        u = clamp(u, vec2<f32>(0.0), vec2<f32>(1.0));
    }
    if a.w <= 0.0 || any(u < vec2<f32>(0.0)) || any(u > vec2<f32>(1.0)) || m.z > 1.0 {
        visibility[s.i] = 1.0;
        return;
    }
    var lit = 0.0;
    for (var y = 0; y < k; y++) {
        for (var x = 0; x < k; x++) {
            let uv = u + (vec2<f32>(f32(x), f32(y)) - half) / res;
            let z = m.z;
            if CLOSE_CRACKS {
                lit += select(0.0, 1.0, z <= min_depth_3x3(uv, u32(res)));
            } else {
                lit += map_compare(uv, z);
            }
        }
    }
    visibility[s.i] = lit / f32(k * k);
}

// Smallest local magnification of the warp used for the bias (1/8: at most 8 cropped texels).
// Courtyard sun 1024: 1/16 -> 1.099 % wrong, 1/8 -> 1.117, 1/4 -> 1.199; within 0.03 points
// on the other setups (docs/bench/warp.md).
const MIN_WARP_SCALE: f32 = 0.125;
