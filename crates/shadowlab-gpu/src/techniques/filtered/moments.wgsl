// Filterable shadow-map representations (seed 004 section 2.1): encoders b(z), the upper-bound
// visibility of an averaged b, and the single-depth (seed 004 section 3.2) form that takes the
// 4 depths of a textureGather plus their bilinear weights. Same formulas as
// shadowlab_core::moments (f64 there, f32 here). Depth z, d: linear light-space depth in
// [0, 1], 0 = near the light. Self-contained (no bindings) so other passes can include it.
// Gather weights: w = ((1-fx) fy, fx fy, fx (1-fy), (1-fx)(1-fy)) for the gather order
// (x0 y1, x1 y1, x1 y0, x0 y0), fx, fy = fract(uv * res - 0.5).

fn vsm_encode(z: f32) -> vec4<f32> {
    return vec4<f32>(z, z * z, 0.0, 0.0);
}

fn esm_encode(z: f32, c: f32) -> vec4<f32> {
    return vec4<f32>(exp(c * z), 0.0, 0.0, 0.0);
}

// (e^{c+ z'}, -e^{-c- z'}) with z' = 2z - 1
fn evsm_warp(z: f32, c_pos: f32, c_neg: f32) -> vec2<f32> {
    let zr = 2.0 * z - 1.0;
    return vec2<f32>(exp(c_pos * zr), -exp(-c_neg * zr));
}

fn evsm_encode(z: f32, c_pos: f32, c_neg: f32) -> vec4<f32> {
    let w = evsm_warp(z, c_pos, c_neg);
    return vec4<f32>(w.x, w.x * w.x, w.y, w.y * w.y);
}

fn msm_encode(z: f32) -> vec4<f32> {
    let z2 = z * z;
    return vec4<f32>(z, z2, z2 * z, z2 * z2);
}

// One-sided Chebyshev (Cantelli) bound on P(x >= t), variance clamped at min_var.
fn chebyshev_bound(mean: f32, mean_sq: f32, t: f32, min_var: f32) -> f32 {
    if t <= mean {
        return 1.0;
    }
    let variance = max(mean_sq - mean * mean, min_var);
    let dt = t - mean;
    return variance / (variance + dt * dt);
}

fn vsm_visibility(m: vec4<f32>, d: f32, min_var: f32) -> f32 {
    return chebyshev_bound(m.x, m.y, d, min_var);
}

// Markov: E[e^{cz}] e^{-cd}, clamped to 1.
fn esm_visibility(m: vec4<f32>, d: f32, c: f32) -> f32 {
    return clamp(m.x * exp(-c * d), 0.0, 1.0);
}

// min of both warps' Chebyshev bounds; min_var (depth units) scaled by each warp's slope at d.
fn evsm_visibility(m: vec4<f32>, d: f32, c_pos: f32, c_neg: f32, min_var: f32) -> f32 {
    let w = evsm_warp(d, c_pos, c_neg);
    let dp = 2.0 * c_pos * w.x;
    let dn = 2.0 * c_neg * w.y;
    let vp = chebyshev_bound(m.x, m.y, w.x, min_var * dp * dp);
    let vn = chebyshev_bound(m.z, m.w, w.y, min_var * dn * dn);
    return min(vp, vn);
}

// Hamburger 4-moment shadow intensity (Peters and Klein 2015, algorithm 2) with the moments
// blended towards 0.5 by `bias`; visibility = 1 - G.
fn msm_visibility(moments: vec4<f32>, d: f32, bias: f32) -> f32 {
    let b = mix(moments, vec4<f32>(0.5), bias);
    // LDL^T solve of [[1,b1,b2],[b1,b2,b3],[b2,b3,b4]] c = (1, d, d^2)
    let l10 = b.x;
    let l20 = b.y;
    let d1 = b.y - l10 * l10;
    let l21 = (b.z - l20 * l10) / d1;
    let d2 = b.w - l20 * l20 - l21 * l21 * d1;
    let y1 = d - l10;
    let y2 = d * d - l20 - l21 * y1;
    let c2 = y2 / d2;
    let c1 = y1 / d1 - l21 * c2;
    let c0 = 1.0 - l10 * c1 - l20 * c2;
    let p = c1 / c2;
    let q = c0 / c2;
    let r = sqrt(max(p * p * 0.25 - q, 0.0));
    let z2 = -0.5 * p - r;
    let z3 = -0.5 * p + r;
    var g = 0.0;
    if d <= z2 {
        g = 0.0;
    } else if d <= z3 {
        g = (d * z3 - b.x * (d + z3) + b.y) / ((z3 - z2) * (d - z2));
    } else {
        g = 1.0 - (z2 * z3 - b.x * (z2 + z3) + b.y) / ((d - z2) * (d - z3));
    }
    // NaN/inf (degenerate moments): the Chebyshev bound, like the CPU version
    if !(abs(g) <= 1e30) {
        return chebyshev_bound(b.x, b.y, d, 0.0);
    }
    return 1.0 - clamp(g, 0.0, 1.0);
}

// Single-depth variants: 4 gathered depths z, bilinear weights w, receiver depth d.
fn vsm_visibility_gather(z: vec4<f32>, w: vec4<f32>, d: f32, min_var: f32) -> f32 {
    let m = w.x * vsm_encode(z.x) + w.y * vsm_encode(z.y) + w.z * vsm_encode(z.z) + w.w * vsm_encode(z.w);
    return vsm_visibility(m, d, min_var);
}

fn esm_visibility_gather(z: vec4<f32>, w: vec4<f32>, d: f32, c: f32) -> f32 {
    // e^{c (z_i - d)} summed directly: no e^{cz} overflow for any c
    let e = exp(c * (z - vec4<f32>(d)));
    return clamp(dot(w, e), 0.0, 1.0);
}

fn evsm_visibility_gather(z: vec4<f32>, w: vec4<f32>, d: f32, c_pos: f32, c_neg: f32, min_var: f32) -> f32 {
    let m = w.x * evsm_encode(z.x, c_pos, c_neg) + w.y * evsm_encode(z.y, c_pos, c_neg) + w.z * evsm_encode(z.z, c_pos, c_neg)
        + w.w * evsm_encode(z.w, c_pos, c_neg);
    return evsm_visibility(m, d, c_pos, c_neg, min_var);
}

fn msm_visibility_gather(z: vec4<f32>, w: vec4<f32>, d: f32, bias: f32) -> f32 {
    let m = w.x * msm_encode(z.x) + w.y * msm_encode(z.y) + w.z * msm_encode(z.z) + w.w * msm_encode(z.w);
    return msm_visibility(m, d, bias);
}

// The visibility of representation `mode` (0 VSM, 1 ESM, 2 EVSM, else MSM) rebuilt from a 2x2
// gather `z` with bilinear weights `w`, for receiver depth `d`. `shape`: (minimum variance, ESM
// c, EVSM c+, EVSM c-); `moment_bias`: MSM's.
fn visibility_gather_of(mode: u32, z: vec4<f32>, w: vec4<f32>, d: f32, shape: vec4<f32>, moment_bias: f32) -> f32 {
    switch mode {
        case 0u: {
            return vsm_visibility_gather(z, w, d, shape.x);
        }
        case 1u: {
            return esm_visibility_gather(z, w, d, shape.y);
        }
        case 2u: {
            return evsm_visibility_gather(z, w, d, shape.z, shape.w, shape.x);
        }
        default: {
            return msm_visibility_gather(z, w, d, moment_bias);
        }
    }
}

// Bilinear weights in gather order for uv on a res x res map.
fn gather_weights(uv: vec2<f32>, res: f32) -> vec4<f32> {
    let f = fract(uv * res - 0.5);
    return vec4<f32>((1.0 - f.x) * f.y, f.x * f.y, f.x * (1.0 - f.y), (1.0 - f.x) * (1.0 - f.y));
}
