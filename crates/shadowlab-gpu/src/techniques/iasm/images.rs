//! `iasm` report: memory, per-tile counters, sampling statistics, and two pictures (the tiles'
//! depth as a 4x4 mosaic at a common size, and the tile resolutions with their importance).

use shadowlab_core::metrics::sampling_stats;
use shadowlab_core::techniques::iasm::{self as core, Placement, THESIS_RESOLUTIONS, TILE_COUNT};

use super::atlas::Atlas;
use super::fit::{ViewFit, FIT_BYTES};
use super::plan::Plan;
use super::uniforms::IasmParams;
use crate::technique::{NamedImage, TechniqueReport};
use crate::techniques::pictures::depth_image;
use crate::Gpu;

/// Side of one tile in the pictures.
const CELL: u32 = 128;

/// The report of the frame planned as `plan` over the square `placement`, its tiles' depth in
/// `atlas` (store=atlas) or `shadow`, the samples per texel in `counts`.
pub(super) fn report(
    gpu: &Gpu,
    plan: &Plan,
    placement: &Placement,
    atlas: Option<&Atlas>,
    fit: Option<&ViewFit>,
    shadow: &wgpu::Buffer,
    counts: &wgpu::Buffer,
) -> TechniqueReport {
    let texels = core::texels(&THESIS_RESOLUTIONS);
    let counts: Vec<u32> = gpu.read_buffer_as(counts, texels as usize);
    let (shadow, bytes) = match atlas {
        None => (gpu.read_buffer_as(shadow, texels as usize), texels * core::TEXEL_BYTES),
        Some(a) => (atlas_as_buffer(plan, a, gpu), a.texture.width() as u64 * a.texture.height() as u64 * 4),
    };
    let mut r = TechniqueReport { shadow_data_bytes: bytes, sampling: Some(sampling_stats(&counts)), ..Default::default() };
    let c = &mut r.counters;
    c.insert("fetches_per_pixel".into(), 1.0);
    c.insert("shadow_buffer_texels".into(), texels as f64);
    // resolution, offset and the two planes per tile (the uniform), not counted above
    c.insert("tile_metadata_bytes".into(), std::mem::size_of::<IasmParams>() as f64);
    c.insert("square_side".into(), placement.size as f64);
    c.insert("square_x0".into(), placement.origin.x as f64);
    c.insert("square_y0".into(), placement.origin.y as f64);
    if let Some(f) = fit {
        c.insert("fit_source".into(), f.source as u32 as f64);
        c.insert("fit_bytes".into(), FIT_BYTES as f64);
        if let Some(b) = f.bounds {
            c.insert("fit_samples".into(), b.samples as f64);
            for (k, v) in [("x0", b.lo.x), ("y0", b.lo.y), ("x1", b.hi.x), ("y1", b.hi.y)] {
                c.insert(format!("fit_bounds_{k}"), v as f64);
            }
        }
    }
    c.insert("empty_tiles".into(), plan.empty.iter().filter(|e| **e).count() as f64);
    let mut draws = 0;
    let mut tris = 0u64;
    for i in 0..TILE_COUNT {
        let d = plan.draws.get(i).map_or(&[][..], |v| v.as_slice());
        let tt: u64 = d.iter().map(|(a, b)| (b - a) as u64 / 3).sum();
        draws += d.len();
        tris += tt;
        c.insert(format!("tile{i:02}.res"), if plan.empty[i] { 0.0 } else { plan.res[i] as f64 });
        c.insert(format!("tile{i:02}.draws"), d.len() as f64);
        c.insert(format!("tile{i:02}.triangles"), tt as f64);
        c.insert(format!("tile{i:02}.samples"), plan.stats.samples[i] as f64);
        c.insert(format!("tile{i:02}.importance"), plan.stats.importance[i]);
    }
    c.insert("draws_total".into(), draws as f64);
    // evaluated samples outside the square: lit for want of shadow data (the camera on the
    // square's edge with the thesis placement sees ground beyond it)
    let inside: f64 = plan.stats.samples.iter().map(|&n| n as f64).sum();
    let outside = plan.stats.outside as f64;
    c.insert("outside_samples".into(), outside);
    c.insert("outside_pct".into(), if inside + outside > 0.0 { 100.0 * outside / (inside + outside) } else { 0.0 });
    c.insert("triangles_drawn".into(), tris as f64);
    r.images.push(mosaic(plan, &shadow));
    r.images.push(resolution_picture(plan));
    r
}

/// The atlas's tiles copied into the linear layout in the buffer's encoding (bits of 1 - z; 0 =
/// nothing), for the same picture.
fn atlas_as_buffer(plan: &Plan, a: &Atlas, gpu: &Gpu) -> Vec<u32> {
    let depth: Vec<f32> = bytemuck::pod_collect_to_vec(&gpu.read_texture(&a.texture, 4));
    let w = a.texture.width();
    let mut out = vec![0u32; core::texels(&THESIS_RESOLUTIONS) as usize];
    for (rank, &i) in plan.order.iter().enumerate() {
        let (r, [x0, y0]) = (plan.res[i], a.slots[rank]);
        for y in 0..r {
            for x in 0..r {
                let z = depth[((y0 + y) * w + x0 + x) as usize];
                if z < 1.0 {
                    out[(plan.off[i] + y * r + x) as usize] = (1.0 - z).to_bits();
                }
            }
        }
    }
    out
}

/// The tiles' stored depth in light-space units (comparable across tiles), each tile resampled
/// to CELL x CELL, laid out as the 4x4 square; cleared texels and empty tiles are black.
fn mosaic(plan: &Plan, shadow: &[u32]) -> NamedImage {
    let side = 4 * CELL;
    let mut world = vec![f32::NAN; (side * side) as usize];
    for i in 0..TILE_COUNT {
        if plan.empty[i] {
            continue;
        }
        let (tx, ty, r) = ((i % 4) as u32, (i / 4) as u32, plan.res[i]);
        for y in 0..CELL {
            for x in 0..CELL {
                let w = shadow[(plan.off[i] + (y * r / CELL) * r + x * r / CELL) as usize];
                if w != 0 {
                    let z = 1.0 - f32::from_bits(w);
                    world[((ty * CELL + y) * side + tx * CELL + x) as usize] = plan.near[i] + z * (plan.far[i] - plan.near[i]);
                }
            }
        }
    }
    let (lo, hi) = world.iter().filter(|v| v.is_finite()).fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
    let norm: Vec<f32> = world.iter().map(|&v| if v.is_finite() && hi > lo { 0.999 * (v - lo) / (hi - lo) } else { 1.0 }).collect();
    depth_image("tiles' depth (4x4 mosaic, common size)", side, &norm)
}

/// Each tile filled by its resolution (brightness: log2 r from 16 to 1024) and importance share
/// (red to yellow); empty tiles black; a grey grid between tiles.
fn resolution_picture(plan: &Plan) -> NamedImage {
    let side = 4 * CELL;
    let total: f64 = plan.stats.importance.iter().sum::<f64>().max(1e-9);
    let mut rgba = vec![0u8; (side * side * 4) as usize];
    for y in 0..side {
        for x in 0..side {
            let i = ((y / CELL) * 4 + x / CELL) as usize;
            let px = &mut rgba[((y * side + x) * 4) as usize..][..4];
            if x % CELL < 2 || y % CELL < 2 {
                px.copy_from_slice(&[90, 90, 90, 255]);
                continue;
            }
            if plan.empty[i] {
                px.copy_from_slice(&[0, 0, 0, 255]);
                continue;
            }
            let b = ((plan.res[i] as f32).log2() - 4.0) / 6.0;
            let share = (plan.stats.importance[i] / total) as f32;
            // bar along the bottom of the tile: importance share
            let bar = (y % CELL) > CELL - 16 && ((x % CELL) as f32) < share * CELL as f32;
            let v = (40.0 + 215.0 * b) as u8;
            let col = if bar { [255, 255, 255, 255] } else { [v, (v as f32 * (0.3 + 0.7 * share.sqrt())) as u8, 40, 255] };
            px.copy_from_slice(&col);
        }
    }
    NamedImage { name: "tile resolution (brightness), importance share (white bar)".into(), width: side, height: side, rgba }
}
