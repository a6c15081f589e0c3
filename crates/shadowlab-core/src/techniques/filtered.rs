//! Filterable shadow-map representations (CPU half of `vsm`, `esm`, `evsm`, `msm`; seed 004
//! section 2.1). Each turns a depth `z` into a vector `b(z)` that can be averaged (blurred,
//! bilinearly interpolated), and turns an averaged vector plus a receiver depth `d` into a
//! visibility that is an upper bound on the fraction of the filtered region that is lit,
//! `P(z >= d)`: never darker than PCF over the same weights. The WGSL in
//! `shadowlab-gpu/src/techniques/filtered/moments.wgsl` uses the same formulas in f32.
//!
//! Depth convention: linear light-space depth in [0, 1], 0 = near the light.

/// Minimum variance of VSM and EVSM (depth units squared). Seed 004 section 4 (1e-10 for all
/// scenes). Too low: f32 cancellation noise in `E[z^2] - E[z]^2` shows as acne on sloped
/// receivers; too high: everything near an occluder brightens (more leaks).
pub const DEFAULT_MIN_VARIANCE: f64 = 1e-10;
/// ESM exponent. Seed 004 section 4 (c = 80). Too low: receivers near their occluder stay lit
/// (leaks at contact); too high: overflow of `e^{cz}` in f32 (c > 88).
pub const DEFAULT_ESM_C: f64 = 80.0;
/// EVSM exponents on depth remapped to [-1, 1]. Seed 004 section 4 (c+ = 20, c- = 5). Too high:
/// f32 overflow / cancellation in the second moment (e^{2c}); too low: more leaks.
pub const DEFAULT_EVSM_C_POS: f64 = 20.0;
pub const DEFAULT_EVSM_C_NEG: f64 = 5.0;
/// MSM moment bias (blend towards (0.5, 0.5, 0.5, 0.5)). Seed 004 section 4 (3e-6 with 32-bit
/// floats). Too low: the 3x3 Hankel matrix is singular (noise, NaN) on flat regions; too high:
/// leaks.
pub const DEFAULT_MOMENT_BIAS: f64 = 3e-6;

/// One-sided Chebyshev (Cantelli) bound on `P(x >= t)` from the mean and the mean of squares,
/// with the variance clamped below at `min_var`. 1 when `t <= mean`.
pub fn chebyshev(mean: f64, mean_sq: f64, t: f64, min_var: f64) -> f64 {
    if t <= mean {
        return 1.0;
    }
    let var = (mean_sq - mean * mean).max(min_var);
    let dt = t - mean;
    var / (var + dt * dt)
}

/// VSM: `b(z) = (z, z^2)`.
pub fn vsm_moments(z: f64) -> [f64; 2] {
    [z, z * z]
}

pub fn vsm_visibility(m: [f64; 2], d: f64, min_var: f64) -> f64 {
    chebyshev(m[0], m[1], d, min_var)
}

/// ESM: `b(z) = e^{cz}`.
pub fn esm_moment(z: f64, c: f64) -> f64 {
    (c * z).exp()
}

/// Markov's inequality: `P(e^{cz} >= e^{cd}) <= E[e^{cz}] e^{-cd}`, clamped to 1.
pub fn esm_visibility(m: f64, d: f64, c: f64) -> f64 {
    (m * (-c * d).exp()).clamp(0.0, 1.0)
}

/// EVSM warps of depth remapped to [-1, 1]: `(e^{c+ z'}, -e^{-c- z'})`, both increasing in `z`.
pub fn evsm_warp(z: f64, c_pos: f64, c_neg: f64) -> [f64; 2] {
    let zr = 2.0 * z - 1.0;
    [(c_pos * zr).exp(), -(-c_neg * zr).exp()]
}

/// EVSM: `b(z) = (p, p^2, n, n^2)` of the two warps.
pub fn evsm_moments(z: f64, c_pos: f64, c_neg: f64) -> [f64; 4] {
    let [p, n] = evsm_warp(z, c_pos, c_neg);
    [p, p * p, n, n * n]
}

/// The minimum of the Chebyshev bounds of both warps. `min_var` is in depth units; each warp's
/// minimum variance is `min_var` times the square of the warp's derivative at `d` (so the same
/// value means the same depth tolerance for VSM and EVSM).
pub fn evsm_visibility(m: [f64; 4], d: f64, c_pos: f64, c_neg: f64, min_var: f64) -> f64 {
    let [p, n] = evsm_warp(d, c_pos, c_neg);
    let (dp, dn) = (2.0 * c_pos * p, 2.0 * c_neg * n);
    let vp = chebyshev(m[0], m[1], p, min_var * dp * dp);
    let vn = chebyshev(m[2], m[3], n, min_var * dn * dn);
    vp.min(vn)
}

/// MSM: `b(z) = (z, z^2, z^3, z^4)`.
pub fn msm_moments(z: f64) -> [f64; 4] {
    let z2 = z * z;
    [z, z2, z2 * z, z2 * z2]
}

/// Hamburger 4-moment shadow intensity (Peters and Klein 2015, algorithm 2): a lower bound on
/// the fraction of the filtered region in front of `d` (`P(z < d)`), after blending the moments
/// towards (0.5, 0.5, 0.5, 0.5) by `bias`. The visibility is `1 - G`.
pub fn msm_shadow_intensity(b: [f64; 4], d: f64, bias: f64) -> f64 {
    let b = b.map(|x| (1.0 - bias) * x + bias * 0.5);
    // Cholesky (LDL^T) solve of the Hankel matrix [[1,b1,b2],[b1,b2,b3],[b2,b3,b4]] c = (1, d, d^2).
    let l10 = b[0];
    let l20 = b[1];
    let d1 = b[1] - l10 * l10;
    let l21 = (b[2] - l20 * l10) / d1;
    let d2 = b[3] - l20 * l20 - l21 * l21 * d1;
    // forward: L y = r
    let y0 = 1.0;
    let y1 = d - l10 * y0;
    let y2 = d * d - l20 * y0 - l21 * y1;
    // D and back substitution: L^T c = D^-1 y
    let c2 = y2 / d2;
    let c1 = y1 / d1 - l21 * c2;
    let c0 = y0 - l10 * c1 - l20 * c2;
    // roots of c2 z^2 + c1 z + c0 = 0
    let p = c1 / c2;
    let q = c0 / c2;
    let r = (p * p * 0.25 - q).max(0.0).sqrt();
    let z2 = -0.5 * p - r;
    let z3 = -0.5 * p + r;
    let g = if d <= z2 {
        0.0
    } else if d <= z3 {
        (d * z3 - b[0] * (d + z3) + b[1]) / ((z3 - z2) * (d - z2))
    } else {
        1.0 - (z2 * z3 - b[0] * (z2 + z3) + b[1]) / ((d - z2) * (d - z3))
    };
    if g.is_finite() {
        g.clamp(0.0, 1.0)
    } else {
        // numerically singular (f32 on the GPU): the two-moment (Chebyshev) bound
        1.0 - chebyshev(b[0], b[1], d, 0.0)
    }
}

pub fn msm_visibility(b: [f64; 4], d: f64, bias: f64) -> f64 {
    1.0 - msm_shadow_intensity(b, d, bias)
}

/// Weighted average of `b(z_i)` (a pre-filter or a bilinear interpolation; weights sum to 1).
pub fn filter<const N: usize>(depths: &[f64], weights: &[f64], b: impl Fn(f64) -> [f64; N]) -> [f64; N] {
    let mut m = [0.0; N];
    for (z, w) in depths.iter().zip(weights) {
        for (mi, bi) in m.iter_mut().zip(b(*z)) {
            *mi += w * bi;
        }
    }
    m
}

/// PCF over the same weights: the exact lit fraction `sum w_i [z_i >= d]`.
pub fn pcf(depths: &[f64], weights: &[f64], d: f64) -> f64 {
    depths.iter().zip(weights).filter(|(z, _)| **z >= d).map(|(_, w)| w).sum()
}

/// Bilinear weights of the 2x2 texels around `uv * res` (texel centres at half-integers), in
/// the order of a WGSL `textureGather`: (-,+), (+,+), (+,-), (-,-) in (x, y) = (u, v) order,
/// i.e. x0y1, x1y1, x1y0, x0y0. Returns the top-left texel of the 2x2 and the weights.
pub fn bilinear_gather(uv: [f64; 2], res: u32) -> ([i64; 2], [f64; 4]) {
    let x = uv[0] * res as f64 - 0.5;
    let y = uv[1] * res as f64 - 0.5;
    let (fx, fy) = (x - x.floor(), y - y.floor());
    let w = [(1.0 - fx) * fy, fx * fy, fx * (1.0 - fy), (1.0 - fx) * (1.0 - fy)];
    ([x.floor() as i64, y.floor() as i64], w)
}

/// Gaussian kernel of odd width `k` (sigma = (k - 1) / 4, so the ends sit at two sigma),
/// normalised; `k = 1` is the identity. The weights of `blur.wgsl`.
pub fn gaussian_kernel(k: u32) -> Vec<f64> {
    let h = (k / 2) as i64;
    if h == 0 {
        return vec![1.0];
    }
    let sigma = (k as f64 - 1.0) / 4.0;
    let w: Vec<f64> = (-h..=h).map(|i| (-(i * i) as f64 / (2.0 * sigma * sigma)).exp()).collect();
    let s: f64 = w.iter().sum();
    w.into_iter().map(|x| x / s).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// xorshift64*: deterministic and dependency-free.
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// A filtered region: 2 to 3 depth clusters (occluders in front of receivers, like a 2x2
    /// gather or a blurred footprint), random weights summing to 1, and receiver depths chosen
    /// both at random and right at the cluster depths.
    fn random_region(rng: &mut Rng) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let n = 4 + (rng.next() * 45.0) as usize;
        let clusters: Vec<f64> = (0..1 + (rng.next() * 3.0) as usize).map(|_| rng.next()).collect();
        let spread = [0.0, 1e-4, 1e-2, 0.1][(rng.next() * 4.0) as usize];
        let depths: Vec<f64> = (0..n)
            .map(|_| (clusters[(rng.next() * clusters.len() as f64) as usize] + spread * (rng.next() - 0.5)).clamp(0.0, 1.0))
            .collect();
        let w: Vec<f64> = (0..n).map(|_| rng.next() + 1e-3).collect();
        let s: f64 = w.iter().sum();
        let w = w.iter().map(|x| x / s).collect();
        let mut ds: Vec<f64> = (0..4).map(|_| rng.next()).collect();
        ds.extend(clusters.iter().flat_map(|c| [c - 1e-3, *c, c + 1e-3, c + 0.05]));
        (depths, w, ds)
    }

    /// Runs `vis(depths, weights, d)` over many random regions and returns the largest amount
    /// by which it falls below PCF (0 when it is always an upper bound).
    fn worst_underestimate(vis: impl Fn(&[f64], &[f64], f64) -> f64) -> f64 {
        let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
        let mut worst: f64 = 0.0;
        for _ in 0..20_000 {
            let (z, w, ds) = random_region(&mut rng);
            for d in ds {
                let v = vis(&z, &w, d);
                assert!((0.0..=1.0).contains(&v), "visibility {v} out of [0, 1]");
                worst = worst.max(pcf(&z, &w, d) - v);
            }
        }
        worst
    }

    #[test]
    fn vsm_is_an_upper_bound_on_pcf() {
        let worst = worst_underestimate(|z, w, d| vsm_visibility(filter(z, w, vsm_moments), d, DEFAULT_MIN_VARIANCE));
        // Cantelli's inequality is exact in f64; only rounding remains
        assert!(worst <= 1e-9, "VSM below PCF by {worst}");
    }

    #[test]
    fn esm_is_an_upper_bound_on_pcf() {
        let worst = worst_underestimate(|z, w, d| esm_visibility(filter(z, w, |x| [esm_moment(x, DEFAULT_ESM_C)])[0], d, DEFAULT_ESM_C));
        assert!(worst <= 1e-9, "ESM below PCF by {worst}");
    }

    #[test]
    fn evsm_is_an_upper_bound_on_pcf() {
        let (cp, cn) = (DEFAULT_EVSM_C_POS, DEFAULT_EVSM_C_NEG);
        let worst =
            worst_underestimate(|z, w, d| evsm_visibility(filter(z, w, |x| evsm_moments(x, cp, cn)), d, cp, cn, DEFAULT_MIN_VARIANCE));
        assert!(worst <= 1e-9, "EVSM below PCF by {worst}");
    }

    #[test]
    fn msm_is_an_upper_bound_on_pcf_up_to_the_moment_bias() {
        // Without bias the bound is exact but the Hankel matrix of fewer than 3 distinct depths is
        // singular; the bias blends in (0.5, ...) and so moves the bound by O(bias / variance).
        // Measured worst case over these regions: 1.5e-6 (about the bias itself); 1e-4 allowed.
        let worst = worst_underestimate(|z, w, d| msm_visibility(filter(z, w, msm_moments), d, DEFAULT_MOMENT_BIAS));
        eprintln!("MSM worst underestimate {worst}");
        assert!(worst <= 1e-4, "MSM below PCF by {worst}");
    }

    #[test]
    fn filtered_maps_darken_fully_behind_one_occluder() {
        // a single occluder depth 0.3 over the whole region, receiver at 0.6
        let (z, w) = (vec![0.3; 4], vec![0.25; 4]);
        assert!(vsm_visibility(filter(&z, &w, vsm_moments), 0.6, DEFAULT_MIN_VARIANCE) < 1e-6);
        assert!(esm_visibility(filter(&z, &w, |x| [esm_moment(x, DEFAULT_ESM_C)])[0], 0.6, DEFAULT_ESM_C) < 1e-6);
        let (cp, cn) = (DEFAULT_EVSM_C_POS, DEFAULT_EVSM_C_NEG);
        assert!(evsm_visibility(filter(&z, &w, |x| evsm_moments(x, cp, cn)), 0.6, cp, cn, DEFAULT_MIN_VARIANCE) < 1e-6);
        assert!(msm_visibility(filter(&z, &w, msm_moments), 0.6, DEFAULT_MOMENT_BIAS) < 1e-3);
        // ... and stay lit on the occluder itself
        for v in [
            vsm_visibility(filter(&z, &w, vsm_moments), 0.3, DEFAULT_MIN_VARIANCE),
            esm_visibility(filter(&z, &w, |x| [esm_moment(x, DEFAULT_ESM_C)])[0], 0.3, DEFAULT_ESM_C),
            evsm_visibility(filter(&z, &w, |x| evsm_moments(x, cp, cn)), 0.3, cp, cn, DEFAULT_MIN_VARIANCE),
            msm_visibility(filter(&z, &w, msm_moments), 0.3, DEFAULT_MOMENT_BIAS),
        ] {
            assert!(v > 0.99, "{v}");
        }
    }

    #[test]
    fn vsm_leaks_where_one_occluder_is_in_front_of_another() {
        // seed 004 figure 2: half the region is a near wire (0.1), half the lamp (0.5); a receiver
        // at 0.55 is fully shadowed, yet Chebyshev gives var / (var + (0.55 - 0.3)^2) = 0.04 / 0.1025
        let (z, w) = (vec![0.1, 0.1, 0.5, 0.5], vec![0.25; 4]);
        let v = vsm_visibility(filter(&z, &w, vsm_moments), 0.55, DEFAULT_MIN_VARIANCE);
        assert!((v - 0.04 / 0.1025).abs() < 1e-9, "{v}");
        assert_eq!(pcf(&z, &w, 0.55), 0.0);
    }

    #[test]
    fn hamburger_matches_a_three_atom_distribution_exactly() {
        // Atoms 0.2, 0.5, 0.8 with weights 0.3, 0.3, 0.4. With the receiver on an atom the
        // canonical representation through d is the distribution itself, so (bias 0) G is the
        // exact weight in front of d.
        let (z, w) = ([0.2, 0.5, 0.8], [0.3, 0.3, 0.4]);
        let b = filter(&z, &w, msm_moments);
        for (d, g) in [(0.2, 0.0), (0.5, 0.3), (0.8, 0.6)] {
            let got = msm_shadow_intensity(b, d, 0.0);
            assert!((got - g).abs() < 1e-9, "d={d}: G={got}, expected {g}");
        }
        // in front of all atoms: lit
        assert_eq!(msm_shadow_intensity(b, 0.05, 0.0), 0.0);
    }

    #[test]
    fn hamburger_on_two_depths_recovers_the_weight_with_the_default_bias() {
        // Two depths a < b with weight w at a: P(z < d) = w for a < d <= b. The Hankel matrix is
        // singular without bias; with the default bias the answer is within 1 %.
        let (z, w) = ([0.3, 0.7], [0.4, 0.6]);
        let b = filter(&z, &w, msm_moments);
        for d in [0.45, 0.5, 0.6, 0.69] {
            let g = msm_shadow_intensity(b, d, DEFAULT_MOMENT_BIAS);
            assert!((g - 0.4).abs() < 0.01, "d={d}: G={g}");
        }
        assert!(msm_shadow_intensity(b, 0.95, DEFAULT_MOMENT_BIAS) > 0.99);
        assert!(msm_shadow_intensity(b, 0.1, DEFAULT_MOMENT_BIAS) < 0.01);
    }

    #[test]
    fn esm_limits() {
        // one depth: a step as c grows (exp(-c * 0.05) -> 0 behind, exactly 1 in front)
        let m = |c| esm_moment(0.4, c);
        assert!(esm_visibility(m(80.0), 0.4, 80.0) > 1.0 - 1e-12);
        assert_eq!(esm_visibility(m(80.0), 0.3, 80.0), 1.0);
        assert!((esm_visibility(m(80.0), 0.45, 80.0) - (-4.0f64).exp()).abs() < 1e-12);
        assert!(esm_visibility(m(400.0), 0.45, 400.0) < 1e-8);
        // c -> 0: everything lit (no shadow at all)
        assert!(esm_visibility(m(1e-6), 0.9, 1e-6) > 0.999_999);
        // c -> infinity on a mixture: lit as soon as any depth in the region is at or behind d
        // (a max filter), however small its weight
        let (z, w) = ([0.2, 0.2, 0.2, 0.6], [0.33, 0.33, 0.33, 0.01]);
        let c = 600.0;
        assert_eq!(esm_visibility(filter(&z, &w, |x| [esm_moment(x, c)])[0], 0.5, c), 1.0);
        assert!(esm_visibility(filter(&z, &w, |x| [esm_moment(x, c)])[0], 0.65, c) < 1e-6);
    }

    #[test]
    fn bilinear_weights_sum_to_one_and_hit_texel_centres() {
        let (t, w) = bilinear_gather([0.5 / 8.0 + 3.0 / 8.0, 0.5 / 8.0 + 5.0 / 8.0], 8);
        assert_eq!(t, [3, 5]);
        assert_eq!(w, [0.0, 0.0, 0.0, 1.0]); // x0y0 only
        let (t, w) = bilinear_gather([0.5, 0.5], 8); // between texels 3 and 4
        assert_eq!(t, [3, 3]);
        assert!(w.iter().all(|x| (x - 0.25).abs() < 1e-12));
    }

    #[test]
    fn gaussian_kernel_is_normalised_and_symmetric() {
        assert_eq!(gaussian_kernel(1), vec![1.0]);
        for k in [3, 5, 9, 15] {
            let g = gaussian_kernel(k);
            assert_eq!(g.len(), k as usize);
            assert!((g.iter().sum::<f64>() - 1.0).abs() < 1e-12);
            assert!((0..g.len()).all(|i| (g[i] - g[g.len() - 1 - i]).abs() < 1e-15));
            assert!(g[k as usize / 2] > g[0]);
        }
    }
}
