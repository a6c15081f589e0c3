// Applying a finished warp (depth, subdivision and evaluation passes). The map's bindings come
// first: lookup_bind.wgsl's (one map: the uniform `wp`, the DV rectangle `dv_rect` and the two
// warps at bindings 6-9 of group 0) or cube-notw's layered ones (cube/eval_notw.wgsl: the
// evaluated face's layer). warp_x holds one row function per texture row (one row for RTW),
// warp_y one column function per texture column; `warp_x_at(k, row)` and `warp_y_at(col, k)`
// read them, `warp_x_size()` and `warp_y_size()` give their sizes.

// Base map coordinates -> DV-cropped coordinates.
fn to_dv(m: vec2<f32>, r: vec4<f32>) -> vec2<f32> {
    return (m - r.xy) / (r.zw - r.xy);
}

// o_x^(i)(x): row i (clamped to the texture), 0 outside [0,1).
fn offset_x(i: u32, x: f32) -> f32 {
    let d = warp_x_size();
    if x < 0.0 || x >= 1.0 {
        return 0.0;
    }
    let row = min(i, d.y - 1u);
    let s = x * f32(d.x);
    let k = min(u32(s), d.x - 1u);
    var left = 0.0;
    if k > 0u {
        left = warp_x_at(k - 1u, row);
    }
    return edge_lerp(left, warp_x_at(k, row), s, k);
}

// o_y^(j)(y): column j (clamped to the texture), 0 outside [0,1).
fn offset_y(j: u32, y: f32) -> f32 {
    let d = warp_y_size();
    if y < 0.0 || y >= 1.0 {
        return 0.0;
    }
    let col = min(j, d.x - 1u);
    let s = y * f32(d.y);
    let k = min(u32(s), d.y - 1u);
    var left = 0.0;
    if k > 0u {
        left = warp_y_at(col, k - 1u);
    }
    return edge_lerp(left, warp_y_at(col, k), s, k);
}

// Seed 000 eq. 6: (x + o_x^(i)(x), y + o_y^(j)(y)), i = floor(y w), j = floor(x' w); with
// `flags.x` the offsets are interpolated between the two nearest functions instead. The offsets
// are scaled by the warp strength `ext.x` (1 = the seeds' warp; 0 = the identity, i.e. DV only).
fn warp(u: vec2<f32>) -> vec2<f32> {
    if !WARPED {
        return u;
    }
    let res = u32(wp.res);
    let interp = wp.interp != 0u;
    let a = neighbours(u.y, res, interp);
    let alpha = wp.strength;
    let xw = u.x + alpha * mix(offset_x(u32(a.x), u.x), offset_x(u32(a.y), u.x), a.z);
    let b = neighbours(xw, res, interp);
    return vec2<f32>(xw, u.y + alpha * mix(offset_y(u32(b.x), u.y), offset_y(u32(b.y), u.y), b.z));
}

// x' of one 1D function pair at texel edge k of n (x = k / n): x + alpha * the offsets of
// functions a and b mixed by t; the row functions (warp_x) if `rows`, else the columns (warp_y).
fn edge_warp(rows: bool, a: u32, b: u32, t: f32, k: u32, n: u32) -> f32 {
    if k == 0u || k >= n {
        return f32(min(k, n)) / f32(n);
    }
    var oa = 0.0;
    var ob = 0.0;
    if rows {
        let h = warp_x_size().y - 1u;
        oa = warp_x_at(k - 1u, min(a, h));
        ob = warp_x_at(k - 1u, min(b, h));
    } else {
        let w = warp_y_size().x - 1u;
        oa = warp_y_at(min(a, w), k - 1u);
        ob = warp_y_at(min(b, w), k - 1u);
    }
    return f32(k) / f32(n) + wp.strength * mix(oa, ob, t);
}

// The x with edge_warp's function(x) = goal, exactly (warp.rs `invert_pl`): the function is
// monotonic and piecewise linear with kinks at the texel edges only, so a search over the edges
// finds the segment (f(lo) <= goal < f(lo + 1)) and its line gives x. With a guess in [0,1] the
// search gallops out from the guess's edge (steps 1, 2, 4, ...) before it bisects: two or three
// evaluations where the guess is within a texel, instead of log2(n); a negative guess bisects
// the whole range. Where f increases from edge to edge in f32 that segment is unique, so both
// searches find it; where rounding makes f flat or dip by an ulp they may stop at neighbouring
// edges of equal value, whose lines give the same x to rounding. Outside [0,1) the warp is the
// identity.
fn invert_1d(rows: bool, a: u32, b: u32, t: f32, goal: f32, guess: f32) -> f32 {
    if goal < 0.0 || goal >= 1.0 {
        return goal;
    }
    var n = warp_y_size().y;
    if rows {
        n = warp_x_size().x;
    }
    // invariant: f(lo) <= goal < f(hi), f(0) = 0 and f(n) = 1
    var lo = 0u;
    var hi = n;
    var flo = 0.0;
    var fhi = 1.0;
    if guess >= 0.0 {
        let g = min(u32(min(guess, 1.0) * f32(n)), n - 1u);
        let fg = edge_warp(rows, a, b, t, g, n);
        var step = 1u;
        if fg <= goal {
            lo = g;
            flo = fg;
            while lo + step < n {
                let f = edge_warp(rows, a, b, t, lo + step, n);
                if f > goal {
                    hi = lo + step;
                    fhi = f;
                    break;
                }
                lo += step;
                flo = f;
                step *= 2u;
            }
        } else {
            hi = g;
            fhi = fg;
            while hi >= step {
                let f = edge_warp(rows, a, b, t, hi - step, n);
                if f <= goal {
                    lo = hi - step;
                    flo = f;
                    break;
                }
                hi -= step;
                fhi = f;
                step *= 2u;
            }
        }
    }
    while hi - lo > 1u {
        let mid = (lo + hi) / 2u;
        let f = edge_warp(rows, a, b, t, mid, n);
        if f <= goal {
            lo = mid;
            flo = f;
        } else {
            hi = mid;
            fhi = f;
        }
    }
    let s = select(0.0, clamp((goal - flo) / (fhi - flo), 0.0, 1.0), fhi > flo);
    return (f32(lo) + s) / f32(n);
}

// The exact inverse of `warp` (warp.rs `Warp2D::unapply`): the column pass reads its functions
// at x', which the goal gives, so y is one 1D inversion; the row pass reads its functions at
// y, so x is another. `guess`: a point near the answer to search from (negative: none).
fn unwarp_exact(t: vec2<f32>, guess: vec2<f32>) -> vec2<f32> {
    if !WARPED {
        return t;
    }
    let res = u32(wp.res);
    let interp = wp.interp != 0u;
    let b = neighbours(t.x, res, interp);
    let y = invert_1d(false, u32(b.x), u32(b.y), b.z, t.y, guess.y);
    let a = neighbours(y, res, interp);
    return vec2<f32>(invert_1d(true, u32(a.x), u32(a.y), a.z, t.x, guess.x), y);
}

// Clip position of a world point in the warped map (Algorithm 1 of seed 000): crop to the DV,
// warp, back to clip space. Behind a spot light only the (affine) crop applies.
fn warped_clip(p: vec3<f32>, r: vec4<f32>) -> vec4<f32> {
    return dv_clip(p, r, true);
}

// The clip position of p in the DV-cropped map, `warped` or not (the occluder pass of
// occluders.wgsl draws the unwarped crop).
fn dv_clip(p: vec3<f32>, r: vec4<f32>, warped: bool) -> vec4<f32> {
    let a = base_clip(wp, p);
    if a.w <= 1e-7 {
        let m = vec2<f32>(a.x * 0.5 + 0.5 * a.w, 0.5 * a.w - a.y * 0.5);
        let u = (m - r.xy * a.w) / (r.zw - r.xy);
        return vec4<f32>(u.x * 2.0 - a.w, a.w - 2.0 * u.y, a.z, a.w);
    }
    var u = to_dv(clip_to_map(a).xy, r);
    if warped {
        u = warp(u);
    }
    return vec4<f32>((u.x * 2.0 - 1.0) * a.w, (1.0 - 2.0 * u.y) * a.w, a.z, a.w);
}

// Pulls a warped map coordinate t back through the warp: Newton steps on warp(u) = t from the
// guess u (forward-difference Jacobian over half a texel), each step capped at UNWARP_MAX_STEP
// cropped texels; the warp has a kink per texel, so the best iterate is kept. Returns (u,
// residual in warped texels). The exact depth pass (depth_exact.wgsl) uses it.
fn unwarp(t: vec2<f32>, guess: vec2<f32>) -> vec3<f32> {
    let res = wp.res;
    let h = 0.5 / res;
    var u = guess;
    var best = u;
    var best_e = 1e30;
    for (var i = 0; i <= UNWARP_STEPS; i++) {
        let w = warp(u);
        let f = w - t;
        let e = dot(f, f);
        if e < best_e {
            best_e = e;
            best = u;
        }
        if i == UNWARP_STEPS || e < UNWARP_TOLERANCE * UNWARP_TOLERANCE / (res * res) {
            break;
        }
        let jx = (warp(u + vec2<f32>(h, 0.0)) - w) / h;
        let jy = (warp(u + vec2<f32>(0.0, h)) - w) / h;
        let det = jx.x * jy.y - jy.x * jx.y;
        if abs(det) < 1e-6 {
            break;
        }
        var s = vec2<f32>(jy.y * f.x - jy.x * f.y, jx.x * f.y - jx.y * f.x) / det;
        let len = length(s);
        if len > UNWARP_MAX_STEP / res {
            s *= UNWARP_MAX_STEP / res / len;
        }
        u -= s;
    }
    return vec3<f32>(best, sqrt(best_e) * res);
}

// Newton steps: the screen-linear guess is within the bend threshold (1-2 texels) of the answer.
const UNWARP_STEPS: i32 = 3;
// Converged when the warped point is this close to the target (warped texels).
const UNWARP_TOLERANCE: f32 = 0.01;
// Largest Newton step (cropped texels).
const UNWARP_MAX_STEP: f32 = 4.0;
