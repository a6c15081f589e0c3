//! PNG and .npy writers for images and raw buffers.

use std::path::Path;

use anyhow::{Context, Result};
use npyz::WriterBuilder;

pub fn png(path: &Path, width: u32, height: u32, rgba: &[u8]) -> Result<()> {
    image::save_buffer(path, rgba, width, height, image::ExtendedColorType::Rgba8).with_context(|| format!("writing {}", path.display()))
}

/// Writes `data` (row-major) as an .npy array of the given shape.
pub fn npy<T: npyz::AutoSerialize + Copy>(path: &Path, shape: &[u64], data: &[T]) -> Result<()> {
    let file = std::io::BufWriter::new(std::fs::File::create(path).with_context(|| format!("creating {}", path.display()))?);
    let mut w = npyz::WriteOptions::new().default_dtype().shape(shape).writer(file).begin_nd()?;
    w.extend(data.iter().copied())?;
    w.finish()?;
    Ok(())
}

/// position.npy (H,W,3 f32, NaN where empty), normal.npy (H,W,3), mask.npy (H,W u8).
pub fn gbuffer(dir: &Path, w: u32, h: u32, position: &[[f32; 4]], normal: &[[f32; 4]], mask: &[u32]) -> Result<()> {
    let shape3 = [h as u64, w as u64, 3];
    let pos: Vec<f32> = position.iter().flat_map(|p| if p[3] > 0.0 { [p[0], p[1], p[2]] } else { [f32::NAN; 3] }).collect();
    npy(&dir.join("position.npy"), &shape3, &pos)?;
    let nrm: Vec<f32> =
        normal.iter().zip(position).flat_map(|(n, p)| if p[3] > 0.0 { [n[0], n[1], n[2]] } else { [f32::NAN; 3] }).collect();
    npy(&dir.join("normal.npy"), &shape3, &nrm)?;
    let m: Vec<u8> = mask.iter().map(|&x| (x != 0) as u8).collect();
    npy(&dir.join("mask.npy"), &[h as u64, w as u64], &m)
}
