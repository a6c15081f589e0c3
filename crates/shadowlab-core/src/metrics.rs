//! Quality metrics against the reference, over the evaluated pixels (GUIDE.md, "Metrics").

use serde::{Deserialize, Serialize};

/// The quality figures against `rt` every record carries (a frame, a technique's summary over
/// frames, metrics.json, a sweep row), declared once: the records embed it flattened, so the
/// fields sit at their top level.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ErrorMetrics {
    /// % of evaluated pixels where (v >= 0.5) != (v_rt >= 0.5).
    pub wrong_pct: f64,
    /// v >= 0.5 where v_rt < 0.5: light leaks, missed occluders.
    pub false_lit_pct: f64,
    /// v < 0.5 where v_rt >= 0.5: acne, over-darkening.
    pub false_shadow_pct: f64,
    /// Mean |v - v_rt| (fractional techniques are penalised for soft edges).
    pub mae: f64,
    pub evaluated_pixels: u64,
}

/// Compares visibility `v` with the reference `v_rt` over pixels with `mask != 0`.
pub fn compare(v: &[f32], v_rt: &[f32], mask: &[u32]) -> ErrorMetrics {
    assert_eq!(v.len(), v_rt.len());
    assert_eq!(v.len(), mask.len());
    let (mut n, mut fl, mut fs, mut abs) = (0u64, 0u64, 0u64, 0f64);
    for i in 0..v.len() {
        if mask[i] == 0 {
            continue;
        }
        n += 1;
        let (a, b) = (v[i] >= 0.5, v_rt[i] >= 0.5);
        fl += (a && !b) as u64;
        fs += (!a && b) as u64;
        abs += (v[i] - v_rt[i]).abs() as f64;
    }
    let pct = |k: u64| if n == 0 { 0.0 } else { 100.0 * k as f64 / n as f64 };
    ErrorMetrics {
        wrong_pct: pct(fl + fs),
        false_lit_pct: pct(fl),
        false_shadow_pct: pct(fs),
        mae: if n == 0 { 0.0 } else { abs / n as f64 },
        evaluated_pixels: n,
    }
}

/// Temporal flicker between two consecutive frames (GUIDE.md): % of pixels evaluated in both
/// whose thresholded visibility changes while the reference's does not. Pixels are compared at
/// the same screen position (a moving camera changes what they see; where it does, `rt`
/// usually changes too and the pixel is not counted).
pub fn flicker_pct(prev: &[f32], cur: &[f32], prev_rt: &[f32], cur_rt: &[f32], prev_mask: &[u32], cur_mask: &[u32]) -> f64 {
    let n = cur.len();
    assert!(prev.len() == n && prev_rt.len() == n && cur_rt.len() == n && prev_mask.len() == n && cur_mask.len() == n);
    let (mut both, mut flips) = (0u64, 0u64);
    for i in 0..n {
        if prev_mask[i] == 0 || cur_mask[i] == 0 {
            continue;
        }
        both += 1;
        flips += ((prev[i] >= 0.5) != (cur[i] >= 0.5) && (prev_rt[i] >= 0.5) == (cur_rt[i] >= 0.5)) as u64;
    }
    if both == 0 {
        0.0
    } else {
        100.0 * flips as f64 / both as f64
    }
}

/// How the view samples land in a shadow map: the quantities warping aims to even out.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SamplingStats {
    /// Texels hit by at least one view sample / all texels.
    pub used_texel_fraction: f64,
    pub samples_per_used_texel_mean: f64,
    pub samples_per_used_texel_max: u32,
    /// Coefficient of variation (std / mean) of the count over used texels.
    pub samples_per_used_texel_cv: f64,
}

pub fn sampling_stats(counts: &[u32]) -> SamplingStats {
    let used: Vec<f64> = counts.iter().filter(|&&c| c > 0).map(|&c| c as f64).collect();
    if used.is_empty() {
        return SamplingStats::default();
    }
    let mean = used.iter().sum::<f64>() / used.len() as f64;
    let var = used.iter().map(|c| (c - mean).powi(2)).sum::<f64>() / used.len() as f64;
    SamplingStats {
        used_texel_fraction: used.len() as f64 / counts.len() as f64,
        samples_per_used_texel_mean: mean,
        samples_per_used_texel_max: counts.iter().copied().max().unwrap_or(0),
        samples_per_used_texel_cv: var.sqrt() / mean,
    }
}

/// Pixels within one pixel (8-neighbourhood) of a visibility edge of the reference: the lower
/// bound on rays for a technique that traces only where it is unsure.
pub fn edge_pixels(v_rt: &[f32], mask: &[u32], width: usize, height: usize) -> u64 {
    let lit = |x: usize, y: usize| v_rt[y * width + x] >= 0.5;
    let mut n = 0;
    for y in 0..height {
        for x in 0..width {
            if mask[y * width + x] == 0 {
                continue;
            }
            let me = lit(x, y);
            let mut edge = false;
            for dy in -1i64..=1 {
                for dx in -1i64..=1 {
                    let (nx, ny) = (x as i64 + dx, y as i64 + dy);
                    if nx >= 0 && ny >= 0 && (nx as usize) < width && (ny as usize) < height {
                        let j = ny as usize * width + nx as usize;
                        edge |= mask[j] != 0 && lit(nx as usize, ny as usize) != me;
                    }
                }
            }
            n += edge as u64;
        }
    }
    n
}

/// The seeds' error image: the shaded image in grey, wrong pixels in red (false-lit) and, when
/// `split` is set, false-shadow pixels in blue. `shaded` is RGBA8.
pub fn error_image(shaded: &[u8], v: &[f32], v_rt: &[f32], mask: &[u32], split: bool) -> Vec<u8> {
    let mut out = Vec::with_capacity(shaded.len());
    for i in 0..mask.len() {
        let px = &shaded[4 * i..4 * i + 4];
        let g = (0.299 * px[0] as f32 + 0.587 * px[1] as f32 + 0.114 * px[2] as f32) as u8;
        let (a, b) = (v[i] >= 0.5, v_rt[i] >= 0.5);
        let c = if mask[i] != 0 && a != b {
            if a || !split {
                [230, 20, 20]
            } else {
                [30, 80, 240]
            }
        } else {
            [g, g, g]
        };
        out.extend_from_slice(&[c[0], c[1], c[2], 255]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn flicker_counts_flips_the_reference_does_not_make() {
        let m = [1, 1, 1, 1, 0];
        let prev = [1.0, 1.0, 0.0, 0.0, 1.0];
        let cur = [0.0, 1.0, 1.0, 0.0, 0.0];
        let prev_rt = [1.0, 1.0, 0.0, 1.0, 1.0];
        let cur_rt = [1.0, 1.0, 1.0, 1.0, 1.0];
        // pixel 0 flips alone (counted), pixel 2 flips with rt (not), pixel 4 is masked
        assert_eq!(flicker_pct(&prev, &cur, &prev_rt, &cur_rt, &m, &m), 25.0);
        assert_eq!(flicker_pct(&prev, &prev, &prev_rt, &cur_rt, &m, &m), 0.0);
        assert_eq!(flicker_pct(&prev, &cur, &prev_rt, &cur_rt, &[0; 5], &m), 0.0);
    }
    #[test]
    fn compare_counts_known_cases() {
        let rt = [1.0, 1.0, 0.0, 0.0, 1.0];
        let v = [1.0, 0.2, 0.7, 0.0, 0.0];
        let mask = [1, 1, 1, 1, 0];
        let m = compare(&v, &rt, &mask);
        assert_eq!(m.evaluated_pixels, 4);
        assert_eq!(m.wrong_pct, 50.0);
        assert_eq!(m.false_lit_pct, 25.0);
        assert_eq!(m.false_shadow_pct, 25.0);
        assert!((m.mae - (0.8 + 0.7) / 4.0).abs() < 1e-6);
    }
    #[test]
    fn sampling_of_known_counts() {
        let s = sampling_stats(&[0, 2, 2, 0, 4, 0, 0, 0]);
        assert_eq!(s.used_texel_fraction, 3.0 / 8.0);
        assert!((s.samples_per_used_texel_mean - 8.0 / 3.0).abs() < 1e-12);
        assert_eq!(s.samples_per_used_texel_max, 4);
        assert!(s.samples_per_used_texel_cv > 0.0);
        assert_eq!(sampling_stats(&[3, 3]).samples_per_used_texel_cv, 0.0);
    }
    #[test]
    fn edge_pixels_of_a_step() {
        // 4x2 image, left half shadowed: the two middle columns are edge pixels
        let rt = [0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 1.0];
        assert_eq!(edge_pixels(&rt, &[1; 8], 4, 2), 4);
    }
    #[test]
    fn error_image_marks_wrong_pixels() {
        let shaded = [100u8; 8];
        let img = error_image(&shaded, &[1.0, 0.0], &[0.0, 1.0], &[1, 1], true);
        assert_eq!(&img[0..3], &[230, 20, 20]);
        assert_eq!(&img[4..7], &[30, 80, 240]);
    }
}
