//! Multiple-depth shadow maps (seed 003, Pagot, Comba, Oliveira): the CPU half of `mdsm`.
//!
//! An n-SM stores n depths per texel, sorted `Z1 >= Z2 >= ... >= Zn` (seed 003 section 4.2),
//! n <= 4 so that one RGBA32F texel holds them all. Depths are post-projective with 0 near the
//! light (as `sm`), so "Z < d" means "the stored surface is in front of the receiver at d".
//!
//! **The n-shadow test.** Seed 003 section 4.2 reads: "sc = 1, if d > Zn, otherwise
//! sc = (i - 1)/n, where Zi is the largest Z value smaller than d". Taken literally with the
//! descending order this is contradictory (if d <= Zn no Z is smaller than d, and if d > Zn the
//! first clause already answers). The reading that is consistent with everything else in the
//! section (w = n + 1 equally spaced outcomes, 1-ST = the ordinary test, Figure 4's 2-SM giving
//! 0, 0.5, 1) is: s = the number of stored depths in front of d (`Zj < d`, the strict test of
//! the ordinary shadow map, section 2.1), the shadow coverage is `s/n`, and the lit fraction
//! `1 - s/n` equals the paper's `(i - 1)/n` with `i` the index of the largest Z smaller than d
//! (`i = n + 1` when none is). [`n_shadow_test`] returns s, found the paper's way (a walk down
//! the sorted list that stops at the first Z smaller than d); the test module checks it against
//! the plain count.
//!
//! **PCF(k, n).** k taps on a `sqrt(k) x sqrt(k)` grid one texel apart, centred on the
//! projected sample (for even widths the taps straddle it: PCF(4, n) reads the 2x2 texels whose
//! centres are nearest, as bilinear filtering would); the result is the lit fraction
//! `sum_t (n - s_t) / (n k)`, one of at most `n k + 1` values (seed 003 Table 1).
//!
//! **Selection.** Besides the ordinary map depth (always kept, section 4.3) the other n - 1
//! depths come from a `sqrt(q) x sqrt(q)` search region centred on the texel (clamped at the
//! map border), with one of the paper's two strategies ([`Select`]). The stored values are
//! always samples of the base map, never blends, so the GPU selection can be checked bit for bit.

/// Most depths per texel: the four channels of one RGBA32F texel (seed 003 section 4.4).
pub const MAX_DEPTHS: usize = 4;
/// The PCF tap counts the issue asks for: square grids 1x1 .. 5x5.
pub const PCF_TAPS: [u32; 5] = [1, 4, 9, 16, 25];
/// Search-region sizes accepted: odd squares, so that the region is centred on the texel.
pub const SEARCH_SIZES: [u32; 4] = [9, 25, 49, 81];
/// Default search region: 3x3 = 9 samples. Seed 003 gives no q explicitly; its worked cost
/// example (section 6: a 2-SM with PCF 3x3 beats PCF 4x4 when f > 1.28 x 512^2 with r = 7)
/// implies q = 1.28 x 7 = 8.96, i.e. a 3x3 neighbourhood. Larger q widens the soft zone (and
/// needs more bias on slopes); smaller is impossible for a centred region.
pub const DEFAULT_Q: u32 = 9;

crate::param_choice! {
    /// How the n - 1 additional depths are chosen from the q samples (seed 003 section 4.3;
    /// `mdsm`'s `select`).
    pub enum Select {
        /// O(q): extremes of the region. n = 2: the extreme (min or max) farther from the base depth
        /// (the paper says "maximum or minimum"; taking the farther one softens both sides of an
        /// edge symmetrically, ties take the minimum); n = 3: min and max (the paper's own 3-SM);
        /// n = 4: min, max and the second extreme on the farther side (2nd smallest or 2nd largest).
        MinMax = "minmax",
        /// O(q log q): sort the q samples, split them into n groups of equal count; the group that
        /// holds the base depth (at the middle of its run of equal values) is represented by the base
        /// depth, every other group by its median (lower median for even counts).
        Sort = "sort",
    }
}

impl Select {
    /// Index in the `select` parameter's choices (`minmax`, `sort`).
    pub fn from_index(i: u32) -> Option<Select> {
        match i {
            0 => Some(Select::MinMax),
            1 => Some(Select::Sort),
            _ => None,
        }
    }
}

/// Side of a PCF grid for `k` taps, if `k` is one of [`PCF_TAPS`].
pub fn pcf_width(k: u32) -> Option<u32> {
    PCF_TAPS.contains(&k).then(|| (k as f64).sqrt() as u32)
}

/// Side of the search region for `q` samples, if `q` is one of [`SEARCH_SIZES`].
pub fn search_width(q: u32) -> Option<u32> {
    SEARCH_SIZES.contains(&q).then(|| (q as f64).sqrt() as u32)
}

/// Tap offsets of PCF(k, ·) in texels from the projected sample, row by row.
pub fn pcf_offsets(k: u32) -> Vec<[f32; 2]> {
    let w = pcf_width(k).expect("k must be one of PCF_TAPS");
    let half = (w as f32 - 1.0) * 0.5;
    (0..w).flat_map(|y| (0..w).map(move |x| [x as f32 - half, y as f32 - half])).collect()
}

/// The n-shadow test: s = how many of the sorted depths `z` (Z1 >= ... >= Zn) lie in front of
/// `d` (`Zj < d`). Walks from Z1 to the first Zi < d (the paper's i); all later ones are smaller
/// still, so s = n - i + 1, and 0 when no Z is smaller than d.
pub fn n_shadow_test(z: &[f32], d: f32) -> u32 {
    let n = z.len() as u32;
    for (i, &zi) in z.iter().enumerate() {
        if zi < d {
            return n - i as u32;
        }
    }
    0
}

/// Shadow coverage `sc = s/n` of seed 003 section 4.2 (1 = fully shadowed).
pub fn shadow_coverage(z: &[f32], d: f32) -> f32 {
    n_shadow_test(z, d) as f32 / z.len() as f32
}

/// PCF(k, n): lit fraction over the taps, `sum (n - s_t) / (n k)`; `taps` holds one sorted
/// texel per tap. The same integer sum and one division as the WGSL, so results are identical.
pub fn pcf(taps: &[&[f32]], d: f32) -> f32 {
    let n = taps.first().map_or(1, |t| t.len()) as u32;
    let lit: u32 = taps.iter().map(|z| n - n_shadow_test(z, d)).sum();
    lit as f32 / (n * taps.len() as u32) as f32
}

/// Seed 003 Table 1: the most distinct outcomes PCF(k, n) can produce.
pub fn max_distinct(k: u32, n: u32) -> u32 {
    n * k + 1
}

/// The q samples around texel (x, y) of a `res x res` map, row by row, coordinates clamped to
/// the map (border texels repeat); the texel itself is at index q / 2.
pub fn region(map: &[f32], res: usize, x: usize, y: usize, q: u32) -> Vec<f32> {
    let w = search_width(q).expect("q must be one of SEARCH_SIZES") as i64;
    let r = (w - 1) / 2;
    let c = |v: i64| v.clamp(0, res as i64 - 1) as usize;
    let mut out = Vec::with_capacity(q as usize);
    for dy in -r..=r {
        for dx in -r..=r {
            out.push(map[c(y as i64 + dy) * res + c(x as i64 + dx)]);
        }
    }
    out
}

/// The n depths of one texel from its search region `samples` (base depth at `base`), sorted
/// descending, written to the first n channels; the unused channels repeat Zn so the texel
/// stays sorted. Only sample values are stored (no arithmetic), as in the WGSL.
pub fn select(samples: &[f32], base: usize, n: usize, strategy: Select) -> [f32; MAX_DEPTHS] {
    assert!((1..=MAX_DEPTHS).contains(&n) && base < samples.len());
    let b = samples[base];
    let mut z: Vec<f32> = vec![b];
    if n > 1 {
        match strategy {
            Select::MinMax => minmax(samples, b, n, &mut z),
            Select::Sort => sorted_groups(samples, b, n, &mut z),
        }
    }
    z.sort_by(|a, b| b.total_cmp(a));
    let mut out = [z[n - 1]; MAX_DEPTHS];
    out[..n].copy_from_slice(&z);
    out
}

fn minmax(samples: &[f32], b: f32, n: usize, z: &mut Vec<f32>) {
    // one pass keeps the two smallest and the two largest (with multiplicity)
    let (mut lo, mut lo2, mut hi, mut hi2) = (f32::INFINITY, f32::INFINITY, f32::NEG_INFINITY, f32::NEG_INFINITY);
    for &v in samples {
        if v < lo {
            lo2 = lo;
            lo = v;
        } else if v < lo2 {
            lo2 = v;
        }
        if v > hi {
            hi2 = hi;
            hi = v;
        } else if v > hi2 {
            hi2 = v;
        }
    }
    let max_farther = hi - b > b - lo;
    match n {
        2 => z.push(if max_farther { hi } else { lo }),
        3 => z.extend([lo, hi]),
        _ => z.extend([lo, hi, if max_farther { hi2 } else { lo2 }]),
    }
}

fn sorted_groups(samples: &[f32], b: f32, n: usize, z: &mut Vec<f32>) {
    let mut s = samples.to_vec();
    s.sort_by(|a, b| b.total_cmp(a)); // descending, O(q log q)
    let q = s.len();
    let first = s.iter().position(|&v| v == b).expect("base is a sample");
    let last = q - 1 - s.iter().rev().position(|&v| v == b).expect("base is a sample");
    let rank = (first + last) / 2;
    for g in 0..n {
        let (lo, hi) = (g * q / n, (g + 1) * q / n);
        if !(lo..hi).contains(&rank) {
            z.push(s[(lo + hi - 1) / 2]);
        }
    }
}

/// Seed 003 equation 2: texture fetches to select the additional depths of a whole map.
pub fn cost_select(q: u32, w_sm: u32, h_sm: u32) -> f64 {
    q as f64 * w_sm as f64 * h_sm as f64
}

/// Equation 3: fetches to shade f fragments with a k-tap PCF of a 1-SM.
pub fn cost_scene(f: f64, k: u32) -> f64 {
    f * k as f64
}

/// Equation 4: selection plus shading with k taps of an n-SM.
pub fn cost_nsm_scene(q: u32, w_sm: u32, h_sm: u32, f: f64, k: u32) -> f64 {
    cost_select(q, w_sm, h_sm) + cost_scene(f, k)
}

/// Equation 5: the fragment count above which PCF(k, n) (with its selection pass) costs less
/// than PCF(k + r, 1): `f > q w h / r`. None when r = 0 (never).
pub fn crossover_fragments(q: u32, w_sm: u32, h_sm: u32, r: u32) -> Option<f64> {
    (r > 0).then(|| cost_select(q, w_sm, h_sm) / r as f64)
}

/// Equation 6 (deferred shading, f = screen pixels): the n-SM is cheaper when the screen is
/// `lambda_h x lambda_w` times the map with `lambda_h lambda_w > q / r`.
pub fn deferred_cheaper(lambda_h: f64, lambda_w: f64, q: u32, r: u32) -> bool {
    r > 0 && lambda_h * lambda_w > q as f64 / r as f64
}

/// Time-based crossover on a real machine: the fragment count where `select_ms` (the selection
/// pass) is paid back by the saved per-fragment time `ms_per_fragment_big - ms_per_fragment_small`.
pub fn crossover_measured(select_ms: f64, ms_per_fragment_big: f64, ms_per_fragment_small: f64) -> Option<f64> {
    let saved = ms_per_fragment_big - ms_per_fragment_small;
    (saved > 0.0).then(|| select_ms / saved)
}

/// Number of distinct values among the masked entries of `v` (exact float equality).
pub fn distinct_values(v: &[f32], mask: &[u32]) -> usize {
    let mut bits: Vec<u32> = v.iter().zip(mask).filter(|(_, m)| **m != 0).map(|(x, _)| x.to_bits()).collect();
    bits.sort_unstable();
    bits.dedup();
    bits.len()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn count(z: &[f32], d: f32) -> u32 {
        z.iter().filter(|&&zj| zj < d).count() as u32
    }

    #[test]
    fn one_depth_test_is_the_ordinary_shadow_test() {
        assert_eq!(n_shadow_test(&[0.5], 0.6), 1); // stored surface in front: shadow
        assert_eq!(n_shadow_test(&[0.5], 0.5), 0); // equal: lit (strict test, as `sm`'s LessEqual)
        assert_eq!(n_shadow_test(&[0.5], 0.4), 0);
    }

    #[test]
    fn n_shadow_test_hand_built() {
        let z = [0.9, 0.6, 0.3]; // Z1 >= Z2 >= Z3
        assert_eq!(shadow_coverage(&z, 0.2), 0.0); // in front of everything: lit
        assert_eq!(shadow_coverage(&z, 0.3), 0.0); // equal to Z3: not in front
        assert_eq!(shadow_coverage(&z, 0.5), 1.0 / 3.0); // behind Z3 only (i = 3: lit (i-1)/n = 2/3)
        assert_eq!(shadow_coverage(&z, 0.7), 2.0 / 3.0);
        assert_eq!(shadow_coverage(&z, 0.95), 1.0); // behind Z1: fully shadowed
                                                    // Figure 4's 2-SM: 0, 0.5, 1
        let z2 = [0.8, 0.4];
        let v: Vec<f32> = [0.1, 0.5, 0.9].iter().map(|&d| shadow_coverage(&z2, d)).collect();
        assert_eq!(v, vec![0.0, 0.5, 1.0]);
    }

    #[test]
    fn sorted_walk_equals_count_on_random_texels() {
        let mut r = 12345u32;
        let mut rnd = || {
            r = r.wrapping_mul(1664525).wrapping_add(1013904223);
            (r >> 8) as f32 / (1 << 24) as f32
        };
        for n in 1..=4 {
            for _ in 0..2000 {
                let mut z: Vec<f32> = (0..n).map(|_| (rnd() * 8.0).floor() / 8.0).collect(); // ties happen
                z.sort_by(|a, b| b.total_cmp(a));
                let d = (rnd() * 9.0).floor() / 8.0;
                assert_eq!(n_shadow_test(&z, d), count(&z, d), "{z:?} {d}");
                // the paper's lit fraction (i - 1)/n, i = index of the largest Z smaller than d
                let i = z.iter().position(|&zj| zj < d).map_or(n + 1, |p| p + 1);
                assert_eq!(n as u32 - n_shadow_test(&z, d), (i - 1) as u32); // lit count n - s = i - 1
            }
        }
    }

    #[test]
    fn pcf_tap_layout() {
        assert_eq!(pcf_offsets(1), vec![[0.0, 0.0]]);
        assert_eq!(pcf_offsets(4), vec![[-0.5, -0.5], [0.5, -0.5], [-0.5, 0.5], [0.5, 0.5]]);
        assert_eq!(pcf_offsets(9)[0], [-1.0, -1.0]);
        assert_eq!(pcf_offsets(25)[24], [2.0, 2.0]);
        assert_eq!(pcf_offsets(16).len(), 16);
        assert!(pcf_width(2).is_none() && pcf_width(8).is_none() && pcf_width(36).is_none());
        assert!(search_width(4).is_none() && search_width(9) == Some(3));
    }

    #[test]
    fn pcf_hand_built() {
        let a: &[f32] = &[0.8, 0.4];
        let b: &[f32] = &[0.8, 0.8];
        let c: &[f32] = &[0.2, 0.1];
        // d = 0.5: a -> s 1 (lit 1), b -> s 0 (lit 2), c -> s 2 (lit 0); 3 of 6 lit
        assert_eq!(pcf(&[a, b, c], 0.5), 0.5);
        assert_eq!(pcf(&[b, b, b, b], 0.5), 1.0);
        assert_eq!(pcf(&[c, c, c, c], 0.5), 0.0);
        assert_eq!(pcf(&[a, b, b, b], 0.5), 7.0 / 8.0);
    }

    /// PCF(k, n) reaches all n k + 1 values: tap t holds texels whose depths put d behind
    /// exactly s_t of them; sweeping the total s over 0..=nk gives every lit count.
    #[test]
    fn pcf_reaches_every_one_of_nk_plus_1_values() {
        for n in 1..=4usize {
            for k in PCF_TAPS {
                let d = 0.5;
                let texel = |s: usize| -> Vec<f32> { (0..n).map(|j| if j < n - s { 0.9 } else { 0.1 }).collect() };
                let mut seen = Vec::new();
                for total in 0..=n * k as usize {
                    // spread `total` occluding depths over the taps, n per tap at most
                    let texels: Vec<Vec<f32>> = (0..k as usize).map(|t| texel(total.saturating_sub(t * n).min(n))).collect();
                    let taps: Vec<&[f32]> = texels.iter().map(|t| t.as_slice()).collect();
                    let v = pcf(&taps, d);
                    assert_eq!(v, (n * k as usize - total) as f32 / (n * k as usize) as f32);
                    seen.push(v.to_bits());
                }
                seen.sort_unstable();
                seen.dedup();
                assert_eq!(seen.len() as u32, max_distinct(k, n as u32), "k {k} n {n}");
            }
        }
        // Table 1 rows
        assert_eq!([1, 2, 3, 4].map(|n| max_distinct(9, n)), [10, 19, 28, 37]);
        assert_eq!(max_distinct(16, 1), 17);
    }

    #[test]
    fn region_is_centred_and_clamped() {
        let res = 4;
        let map: Vec<f32> = (0..16).map(|i| i as f32).collect();
        assert_eq!(region(&map, res, 1, 1, 9), vec![0.0, 1.0, 2.0, 4.0, 5.0, 6.0, 8.0, 9.0, 10.0]);
        assert_eq!(region(&map, res, 0, 0, 9), vec![0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 4.0, 4.0, 5.0]);
        let r = region(&map, res, 3, 3, 25);
        assert_eq!(r.len(), 25);
        assert_eq!(r[12], 15.0);
    }

    #[test]
    fn selection_keeps_the_base_depth_and_sorts() {
        // an edge: receiver at 0.8 on the left, occluder at 0.2 on the right
        let edge_r = [0.8, 0.8, 0.2, 0.8, 0.8, 0.2, 0.8, 0.8, 0.2]; // base (index 4) on the receiver
        let edge_o = [0.8, 0.2, 0.2, 0.8, 0.2, 0.2, 0.8, 0.2, 0.2]; // base on the occluder
        assert_eq!(select(&edge_r, 4, 1, Select::MinMax), [0.8; 4]);
        assert_eq!(select(&edge_r, 4, 2, Select::MinMax), [0.8, 0.2, 0.2, 0.2]); // min is farther
        assert_eq!(select(&edge_o, 4, 2, Select::MinMax), [0.8, 0.2, 0.2, 0.2]); // max is farther
        let flat = [0.5; 9];
        assert_eq!(select(&flat, 4, 4, Select::MinMax), [0.5; 4]);
        let ramp = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.95];
        // base 0.5: max 0.95 is farther (0.45 > 0.4): n=4 adds the second largest, 0.8
        assert_eq!(select(&ramp, 4, 3, Select::MinMax), [0.95, 0.5, 0.1, 0.1]);
        assert_eq!(select(&ramp, 4, 4, Select::MinMax), [0.95, 0.8, 0.5, 0.1]);
        // sort into groups: q = 9, n = 3 -> sorted indices [0,3) [3,6) [6,9); base 0.5 sits at
        // rank 4 (group 1), the others are represented by their medians 0.8 (index 1) and 0.2 (7)
        assert_eq!(select(&ramp, 4, 3, Select::Sort), [0.8, 0.5, 0.2, 0.2]);
        // n = 4: groups [0,2) [2,4) [4,6) [6,9): base at rank 4 -> group 2; medians 0.95, 0.7, 0.2
        assert_eq!(select(&ramp, 4, 4, Select::Sort), [0.95, 0.7, 0.5, 0.2]);
        // a receiver texel with one occluding sample: the median of the near group is still the
        // receiver (sort follows the majority), while minmax picks the occluder
        let one = [0.8, 0.8, 0.8, 0.8, 0.8, 0.8, 0.8, 0.8, 0.2];
        assert_eq!(select(&one, 4, 2, Select::Sort), [0.8; 4]);
        assert_eq!(select(&one, 4, 2, Select::MinMax)[..2], [0.8, 0.2]);
        for n in 1..=4 {
            for s in [Select::MinMax, Select::Sort] {
                let z = select(&ramp, 4, n, s);
                assert!(z[..n].contains(&0.5), "{s:?} n {n}: base depth kept");
                assert!(z.windows(2).all(|w| w[0] >= w[1]), "{s:?} n {n}: sorted {z:?}");
            }
        }
    }

    #[test]
    fn edge_texels_give_half_shadow_with_2_sm() {
        // a receiver point (d = 0.79, the receiver at 0.8 biased) seen through the 2-ST: the
        // texels on both sides of the edge give 1/2 with minmax, texels away from it 0 and 1,
        // so PCF(1, 2) already has three levels across an edge
        let d = 0.79;
        let recv_inner = select(&[0.8; 9], 4, 2, Select::MinMax);
        let recv_edge = select(&[0.8, 0.8, 0.2, 0.8, 0.8, 0.2, 0.8, 0.8, 0.2], 4, 2, Select::MinMax);
        let occ_edge = select(&[0.8, 0.2, 0.2, 0.8, 0.2, 0.2, 0.8, 0.2, 0.2], 4, 2, Select::MinMax);
        let occ_inner = select(&[0.2; 9], 4, 2, Select::MinMax);
        let sc: Vec<f32> = [recv_inner, recv_edge, occ_edge, occ_inner].iter().map(|z| shadow_coverage(&z[..2], d)).collect();
        assert_eq!(sc, vec![0.0, 0.5, 0.5, 1.0]);
    }

    #[test]
    fn cost_model_matches_the_paper_example() {
        // section 6: 512^2 map, q = 9 (3x3), PCF 4x4 vs 2-SM PCF 3x3 -> r = 7, f > 1.28 x 512^2
        let f = crossover_fragments(9, 512, 512, 7).unwrap();
        assert!((f / (512.0 * 512.0) - 9.0 / 7.0).abs() < 1e-12);
        assert!((f / (512.0 * 512.0) - 1.28).abs() < 0.01);
        assert!(crossover_fragments(9, 512, 512, 0).is_none());
        // at the crossover both costs are equal (equations 3 and 4 with k + r and k)
        assert!((cost_nsm_scene(9, 512, 512, f, 9) - cost_scene(f, 16)).abs() < 1e-6);
        assert!(cost_nsm_scene(9, 512, 512, 2.0 * f, 9) < cost_scene(2.0 * f, 16));
        // equation 6: equal sizes never pay off for q > r; 656^2 screen over a 512^2 map does
        assert!(!deferred_cheaper(1.0, 1.0, 9, 7));
        // lambda^2 > 9/7: the square screen must exceed 512 sqrt(9/7) = 580.6 pixels a side (the
        // paper's 656^2 multiplies the side, not the area, by 1.28; it is past the crossover too)
        assert!(deferred_cheaper(656.0 / 512.0, 656.0 / 512.0, 9, 7));
        assert!(deferred_cheaper(581.0 / 512.0, 581.0 / 512.0, 9, 7));
        assert!(!deferred_cheaper(580.0 / 512.0, 580.0 / 512.0, 9, 7));
        assert_eq!(crossover_measured(2.0, 3.0, 1.0), Some(1.0));
        assert_eq!(crossover_measured(2.0, 1e-6, 1e-6), None);
    }

    #[test]
    fn distinct_values_counts_masked_pixels_only() {
        assert_eq!(distinct_values(&[0.0, 0.5, 0.5, 1.0, 0.25], &[1, 1, 1, 1, 0]), 3);
        assert_eq!(distinct_values(&[], &[]), 0);
    }
}
