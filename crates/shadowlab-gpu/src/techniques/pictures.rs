//! Pictures several techniques offer the report: a shadow map's depth and the view samples
//! counted per texel.

use crate::technique::NamedImage;

/// Grey depth picture, stretched to the range of covered texels (1.0 = empty shows black).
pub fn depth_image(name: &str, res: u32, depth: &[f32]) -> NamedImage {
    let (lo, hi) = depth.iter().filter(|d| **d < 1.0).fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &d| (a.min(d), b.max(d)));
    let rgba = depth
        .iter()
        .flat_map(|&d| {
            let g = if d >= 1.0 || hi <= lo { 0 } else { (255.0 * (1.0 - (d - lo) / (hi - lo)) * 0.85 + 30.0) as u8 };
            [g, g, g, 255]
        })
        .collect();
    NamedImage { name: name.into(), width: res, height: res, rgba }
}

/// Heat picture of the sample count per texel (log scale; black = unused).
pub fn count_image(name: &str, res: u32, counts: &[u32]) -> NamedImage {
    let max = counts.iter().copied().max().unwrap_or(1).max(1) as f32;
    let rgba = counts
        .iter()
        .flat_map(|&c| {
            if c == 0 {
                return [0, 0, 0, 255];
            }
            let t = (c as f32).ln_1p() / max.ln_1p();
            [(255.0 * t.sqrt()) as u8, (255.0 * t * t) as u8, (255.0 * (1.0 - t) * 0.6) as u8, 255]
        })
        .collect();
    NamedImage { name: name.into(), width: res, height: res, rgba }
}
