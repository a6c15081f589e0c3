// Warped shadow-map evaluation: each evaluated sample is offset (normal offset, constant and
// slope-scaled bias) in world units of one *warped* texel at the sample, projected, cropped to
// the desired view, warped through the same function as the depth pass, and compared with an
// NxN kernel of warped texels. The warped texel's world size is the cropped texel divided by
// the warp's local scale (`footprint` mode; default the smallest singular value of the warp's
// Jacobian, finite differences over one texel): where the warp magnifies, texels shrink and so
// does the bias. Also counts the samples per
// warped texel (sampling statistics after warping).

@group(0) @binding(10) var shadow_map: texture_depth_2d;
@group(0) @binding(11) var cmp: sampler_comparison;
@group(0) @binding(12) var<storage, read_write> counts: array<atomic<u32>>;

// The nearest depth of the 3x3 texels around uv: closes the sub-texel cracks that adaptive
// subdivision leaves at T-junctions (the finer side's midpoints are warped, the coarser side's
// edge is straight), at the price of growing occluders by one warped texel.
fn min_depth_3x3(uv: vec2<f32>, res: u32) -> f32 {
    let c = vec2<i32>(clamp(uv * f32(res), vec2<f32>(0.0), vec2<f32>(f32(res) - 1.0)));
    var d = 1.0;
    for (var y = -1; y <= 1; y++) {
        for (var x = -1; x <= 1; x++) {
            let t = clamp(c + vec2<i32>(x, y), vec2<i32>(0), vec2<i32>(i32(res) - 1));
            d = min(d, textureLoad(shadow_map, t, 0));
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

// The warp's local scale that one warped texel's world size divides by (warp.rs
// `footprint_scale`): the Jacobian's smallest singular value (the texel's longest world extent),
// its largest (shortest extent), 1 (cropped texels: bias as without the warp) or sqrt(det) (the
// mean); clamped below by `min_scale`.
fn footprint_scale(j: mat2x2<f32>) -> f32 {
    let sv = singular_values(j[0], j[1]);
    let mode = u32(wp.look.x + 0.5);
    var s = sv.x;
    if mode == 1u {
        s = sv.y;
    } else if mode == 2u {
        s = 1.0;
    } else if mode == 3u {
        s = sqrt(sv.x * sv.y);
    }
    return clamp(s, wp.look.y, 1e3);
}

// The plane through q with normal n as map depth over cropped coordinates, d = dot(g, v) + c
// (w = 1; 0 when seen edge-on from the light or behind a spot): fitted through q and two points
// `size` away along the surface (depth is affine in map coordinates on a plane, depth.wgsl).
fn receiver_plane(q: vec3<f32>, n: vec3<f32>, size: f32, r: vec4<f32>) -> vec4<f32> {
    var a = vec3<f32>(1.0, 0.0, 0.0);
    if abs(n.x) > 0.8 {
        a = vec3<f32>(0.0, 1.0, 0.0);
    }
    let t1 = normalize(cross(n, a));
    let t2 = cross(n, t1);
    let c0 = base_clip(wp, q);
    let c1 = base_clip(wp, q + t1 * size);
    let c2 = base_clip(wp, q + t2 * size);
    if min(min(c0.w, c1.w), c2.w) <= 1e-7 {
        return vec4<f32>(0.0);
    }
    let m0 = clip_to_map(c0);
    let m1 = clip_to_map(c1);
    let m2 = clip_to_map(c2);
    let v0 = to_dv(m0.xy, r);
    let e1 = to_dv(m1.xy, r) - v0;
    let e2 = to_dv(m2.xy, r) - v0;
    let det = e1.x * e2.y - e1.y * e2.x;
    if det * det <= RECEIVER_EDGE_ON * dot(e1, e1) * dot(e2, e2) || det == 0.0 {
        return vec4<f32>(0.0);
    }
    let d1 = m1.z - m0.z;
    let d2 = m2.z - m0.z;
    let g = vec2<f32>(d1 * e2.y - d2 * e1.y, e1.x * d2 - e2.x * d1) / det;
    return vec4<f32>(g, m0.z - dot(g, v0), 1.0);
}

// The receiver plane's depth at the preimage of the centre of the warped texel holding uv: the
// point the texel's exact depth was written for (depth_exact.wgsl pulls the same centre back by
// the same `unwarp`), so a planar receiver compares against its own depth exactly and the bias
// no longer has to cover the texel's footprint times the slope. Falls back to `z` (the biased
// point's own depth) when the inversion fails.
fn receiver_depth(plane: vec4<f32>, uv: vec2<f32>, guess: vec2<f32>, z: f32) -> f32 {
    let res = wp.texel.z;
    let tc = (floor(uv * res) + 0.5) / res;
    let inv = unwarp(tc, guess);
    if inv.z > 0.25 {
        return z;
    }
    return dot(plane.xy, inv.xy) + plane.z;
}

// Central-difference Jacobian of the warp at u over +-h: columns d warp / dx, d warp / dy.
fn jacobian(u: vec2<f32>, h: f32) -> mat2x2<f32> {
    let jx = (warp(u + vec2<f32>(h, 0.0)) - warp(u - vec2<f32>(h, 0.0))) / (2.0 * h);
    let jy = (warp(u + vec2<f32>(0.0, h)) - warp(u - vec2<f32>(0.0, h))) / (2.0 * h);
    return mat2x2<f32>(jx, jy);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    var s: Sample;
    // a paraboloid map writes only its hemisphere's samples; the other map writes the rest
    if !load_sample(id, &s) || !owns_sample(wp, s.p) {
        return;
    }
    let p = s.p;
    let n = s.n;
    let l = to_light(light, p);
    let res = wp.texel.z;
    let r = dv_rect();

    let m0 = clip_to_map(base_clip(wp, p));
    let u0 = to_dv(m0.xy, r);
    let c0 = warp(u0);
    if all(c0 >= vec2<f32>(0.0)) && all(c0 < vec2<f32>(1.0)) {
        let t = vec2<u32>(c0 * res);
        atomicAdd(&counts[t.y * u32(res) + t.x], 1u);
    }

    // world size of one cropped texel at p, then of one warped texel
    var texel = wp.texel.x * max(r.z - r.x, r.w - r.y);
    if wp.texel.y > 0.5 {
        texel *= max(dot(p - light.position.xyz, light.direction.xyz), 0.0);
    }
    if is_paraboloid(wp) {
        // texel.x = 2 / res radians per texel at the rim; (1 + n.z) x that in general
        texel *= distance(p, light.position.xyz) * (1.0 + max(hemisphere_side(wp, p), 0.0));
    }
    if wp.cfg.z > 0.5 {
        // clamped: a collapsed (unsampled) region would ask for an unbounded bias
        var scale = footprint_scale(jacobian(u0, 0.5 / res));
        if wp.look.z > 0.5 {
            // also the secants over +-reach cropped texels: the warped texel around the sample
            // can reach back into neighbouring, more compressed cropped texels
            scale = min(scale, footprint_scale(jacobian(u0, wp.look.z / res)));
        }
        texel /= scale;
    }
    let cos_t = clamp(dot(n, l), 1e-4, 1.0);
    let tan_t = min(sqrt(1.0 - cos_t * cos_t) / cos_t, wp.bias.w);
    let k = i32(wp.texel.w);
    let half = f32(k - 1) * 0.5;
    let q = p + n * (wp.bias.z * texel) + l * ((wp.bias.x + (wp.bias.y + half) * tan_t) * texel);
    let a = base_clip(wp, q);
    let m = clip_to_map(a);
    var u = warp(to_dv(m.xy, r));
    if is_paraboloid(wp) && a.w > 0.0 {
        // a biased point that crossed the split plane reads the map's border texels
        u = clamp(u, vec2<f32>(0.0), vec2<f32>(1.0));
    }
    if a.w <= 0.0 || any(u < vec2<f32>(0.0)) || any(u > vec2<f32>(1.0)) || m.z > 1.0 {
        visibility[s.i] = 1.0;
        return;
    }
    // receiver plane: the biased point's plane (parallel to the surface) as depth over cropped
    // coordinates, to be evaluated where each tested texel's depth was written
    var plane = vec4<f32>(0.0);
    let uq = to_dv(m.xy, r);
    if wp.look.w > 0.5 && !is_paraboloid(wp) {
        plane = receiver_plane(q, n, texel, r);
    }
    var lit = 0.0;
    for (var y = 0; y < k; y++) {
        for (var x = 0; x < k; x++) {
            let uv = u + (vec2<f32>(f32(x), f32(y)) - half) / res;
            var z = m.z;
            if plane.w != 0.0 {
                z = receiver_depth(plane, uv, uq, z);
            }
            if wp.cfg.y > 1.5 {
                lit += select(0.0, 1.0, z <= min_depth_3x3(uv, u32(res)));
            } else {
                lit += textureSampleCompareLevel(shadow_map, cmp, uv, z);
            }
        }
    }
    visibility[s.i] = lit / f32(k * k);
}

// sin^2 of the angle between the projected tangents below which a receiver counts as edge-on.
const RECEIVER_EDGE_ON: f32 = 1e-6;
