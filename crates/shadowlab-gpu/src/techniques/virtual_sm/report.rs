//! `virtual`'s report: pages marked, rendered, cached and fallen back in the last frame, the
//! pool's and page table's bytes, samples per level, and a picture of the marked pages.

use shadowlab_core::techniques::virtual_sm::{Build, PageKey};

use super::allocate::Pages;
use super::setup::Setup;
use super::uniforms::MAX_LEVELS;
use crate::technique::{NamedImage, TechniqueReport};
use crate::Gpu;

/// A colour per level (cycled): fine levels warm, coarse cold.
const LEVEL_COLOURS: [[u8; 3]; 8] =
    [[230, 40, 40], [240, 140, 30], [230, 220, 40], [60, 200, 60], [40, 200, 200], [50, 110, 230], [140, 60, 220], [220, 60, 180]];

/// The report of the last frame's `pages`, with the samples per level in `counts`.
pub(super) fn report(gpu: &Gpu, s: &Setup, pages: &Pages, counts: &wgpu::Buffer) -> TechniqueReport {
    let a = &pages.alloc;
    let slots = s.pool.cols * s.pool.rows;
    let static_slots = pages.statics.slots();
    let pool_bytes = (slots + static_slots) as u64 * (s.page_res as u64).pow(2) * 4;
    let n = s.virtual_res / s.page_res;
    let table_bytes = s.levels as u64 * (n as u64).pow(2) * 4;
    let mut r = TechniqueReport { shadow_data_bytes: pool_bytes + table_bytes, ..Default::default() };
    let c = &mut r.counters;
    c.insert("pages_marked".into(), pages.requested.len() as f64);
    c.insert("pages_rendered".into(), a.render.len() as f64);
    c.insert("pages_cached".into(), a.cached as f64);
    c.insert("pages_fallen_back".into(), a.fallen_back.len() as f64);
    c.insert("pages_rendered_total".into(), pages.rendered_total as f64);
    c.insert("frames".into(), pages.frames as f64);
    c.insert("pages_invalidated".into(), pages.invalidated as f64);
    c.insert("pages_fallback_added".into(), pages.fallback_added as f64);
    c.insert("pages_invalidated_total".into(), pages.invalidated_total as f64);
    c.insert("pool_pages".into(), slots as f64);
    // the static/dynamic split: how the rendered pages were built, and the triangles drawn
    let count = |f: fn(&Build) -> bool| pages.builds.iter().filter(|b| f(b)).count() as f64;
    c.insert("pages_drawn_whole".into(), count(|b| *b == Build::Full));
    c.insert("static_copies_drawn".into(), count(|b| matches!(b, Build::Fill(_))));
    c.insert("pages_from_static_copy".into(), count(|b| matches!(b, Build::Copy(_))));
    c.insert("static_pool_pages".into(), static_slots as f64);
    c.insert("static_copies_resident".into(), pages.statics.resident() as f64);
    c.insert("triangles_drawn".into(), pages.triangles_drawn as f64);
    c.insert("pool_bytes".into(), pool_bytes as f64);
    c.insert("page_table_bytes".into(), table_bytes as f64);
    c.insert("request_bytes".into(), table_bytes as f64);
    let counts: Vec<u32> = gpu.read_buffer_as(counts, MAX_LEVELS + 1);
    let total: u64 = counts.iter().map(|&x| x as u64).sum();
    // per level index (a cube's: mip x 6 + face); the samples per mip (all faces)
    for k in 0..s.levels as usize {
        let marked = pages.requested.iter().filter(|p| p.level == k as u32).count();
        if marked > 0 {
            c.insert(format!("pages_marked_level_{k}"), marked as f64);
        }
    }
    for m in 0..s.mips as usize {
        if counts[m] > 0 {
            c.insert(format!("pixels_in_level_{m}"), counts[m] as f64 / total.max(1) as f64);
        }
    }
    if s.faces > 1 {
        c.insert("faces".into(), s.faces as f64);
        for f in 0..s.faces {
            let marked = pages.requested.iter().filter(|p| p.level % s.faces == f).count();
            c.insert(format!("pages_marked_face_{f}"), marked as f64);
        }
    }
    let unresolved = counts[MAX_LEVELS];
    c.insert("pixels_unresolved".into(), unresolved as f64);
    if !a.fallen_back.is_empty() {
        let finest = a.fallen_back.iter().map(|p| p.level / s.faces).min().unwrap_or(0);
        r.degraded.push(format!(
            "virtual: page pool full ({slots} pages): {} pages fell back to coarser levels (finest level {finest}; {} fallback pages added)",
            a.fallen_back.len(),
            pages.fallback_added
        ));
    }
    if unresolved > 0 {
        r.degraded.push(format!("virtual: {unresolved} pixels found no mapped page at any level and were taken as lit"));
    }
    r.images.push(marked_picture(s, pages));
    r
}

/// The marked pages of each level that has any, as an N x N grid of the level's window,
/// side by side, each marked page in its level's colour (a cube: its mip's; fallen-back pages
/// dimmed).
fn marked_picture(s: &Setup, pages: &Pages) -> NamedImage {
    let n = (s.virtual_res / s.page_res) as usize;
    let levels: Vec<u32> = (0..s.levels).filter(|k| pages.requested.iter().any(|p| p.level == *k)).collect();
    let cells = levels.len().max(1);
    let (w, h) = (cells * (n + 2), n + 2);
    let mut rgba = vec![0u8; w * h * 4];
    for px in rgba.chunks_exact_mut(4) {
        px.copy_from_slice(&[24, 24, 24, 255]);
    }
    let fallen: std::collections::BTreeSet<PageKey> = pages.alloc.fallen_back.iter().copied().collect();
    if let Some(c) = &pages.clipmap {
        for (i, &k) in levels.iter().enumerate() {
            let o = c.origins[k as usize];
            for p in pages.requested.iter().filter(|p| p.level == k) {
                let (x, y) = ((p.x - o.x) as usize, (p.y - o.y) as usize);
                let col = LEVEL_COLOURS[(k / s.faces) as usize % LEVEL_COLOURS.len()];
                let dim = if fallen.contains(p) { 3 } else { 1 };
                let at = ((y + 1) * w + i * (n + 2) + x + 1) * 4;
                rgba[at..at + 4].copy_from_slice(&[col[0] / dim, col[1] / dim, col[2] / dim, 255]);
            }
        }
    }
    NamedImage { name: "marked pages per level (coloured by level)".into(), width: w as u32, height: h as u32, rgba }
}
