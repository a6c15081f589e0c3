//! `virtual`'s culling chunks: triangle ranges with their light-coordinate rectangles, the
//! static ones bounded once at creation, the moving ones every frame (bounds.rs), and the
//! chunks a page draws.

use glam::Vec2;
use shadowlab_core::scene::Bounds;
use shadowlab_core::techniques::virtual_sm::{Clipmap, PageKey};

use super::bounds::ChunkBounds;
use crate::scene_gpu::GpuScene;
use crate::{Gpu, GpuError};

/// Triangles per culling chunk (iasm's chunks): a page draws the chunks whose light-space
/// rectangle overlaps it. Smaller: tighter culling, more draws per page.
pub const CHUNK_TRIANGLES: u32 = 1024;

/// Triangles per chunk of moving geometry: its swept boxes invalidate the pages under them
/// every frame, so they are kept small (a long swaying cable in 1024-triangle chunks is one
/// box over its whole length). Smaller: tighter invalidation, more boxes read back per frame.
pub const DYNAMIC_CHUNK_TRIANGLES: u32 = 64;

/// A chunk: triangle range and its rectangle in level-0 light coordinates per face
/// (`Clipmap::light_rect`; unbounded where it spans the whole map; one face unless a cube).
pub(super) struct Chunk {
    pub first: u32,
    pub end: u32,
    rects: Vec<(Vec2, Vec2)>,
}

impl Chunk {
    pub fn new(first: u32, end: u32, world: &Bounds, c: &Clipmap) -> Chunk {
        let all = (Vec2::splat(f32::NEG_INFINITY), Vec2::splat(f32::INFINITY));
        let rects = (0..c.faces()).map(|f| c.light_rect(f, world).unwrap_or(all)).collect();
        Chunk { first, end, rects }
    }
}

/// The rectangle of page `k` in level-0 light coordinates.
fn page_rect(c: &Clipmap, k: &PageKey) -> (Vec2, Vec2) {
    let s = c.texel(k.level) * c.page_res as f32;
    (Vec2::new(k.x as f32 * s, k.y as f32 * s), Vec2::new((k.x as f32 + 1.0) * s, (k.y as f32 + 1.0) * s))
}

/// Triangle ranges of the chunks overlapping page `k` (adjacent chunks merged).
pub(super) fn page_draws(chunks: &[Chunk], c: &Clipmap, k: &PageKey) -> Vec<(u32, u32)> {
    let (lo, hi) = page_rect(c, k);
    let f = c.face(k.level) as usize;
    let mut out: Vec<(u32, u32)> = Vec::new();
    for ch in chunks {
        let (clo, chi) = ch.rects[f];
        if chi.x < lo.x || clo.x > hi.x || chi.y < lo.y || clo.y > hi.y {
            continue;
        }
        match out.last_mut() {
            Some(last) if last.1 == ch.first => last.1 = ch.end,
            _ => out.push((ch.first, ch.end)),
        }
    }
    out
}

/// Whether a moving chunk (`chunks[moving0..]`) lies over page `k` now.
pub(super) fn moving_over(chunks: &[Chunk], moving0: usize, c: &Clipmap, k: &PageKey) -> bool {
    !page_draws(&chunks[moving0..], c, k).is_empty()
}

/// The culling chunks: static ones (`0..dynamic_first`) first, then the moving ones.
pub(super) struct Chunks {
    pub list: Vec<Chunk>,
    /// Index of the first moving chunk in `list`.
    pub moving0: usize,
    /// The moving chunks' bounds, recomputed every frame (None: nothing moves).
    pub dynamic: Option<ChunkBounds>,
    /// The moving chunks' boxes of the last frame (None before the first).
    boxes: Option<Vec<Bounds>>,
}

impl Chunks {
    /// Static chunks bounded once here, on the GPU; moving ones get the scene's bounds until
    /// the first frame bounds them. `proto`: the light's clipmap at creation.
    pub fn new(gpu: &Gpu, scene: &GpuScene, split: u32, proto: &Clipmap) -> Result<Chunks, GpuError> {
        let mut list = Vec::new();
        if split > 0 {
            let b = ChunkBounds::new(gpu, scene, "virtual.static_bounds", 0, split, CHUNK_TRIANGLES);
            let mut enc = gpu.device.create_command_encoder(&Default::default());
            b.record(gpu, &mut enc, scene);
            gpu.submit(enc.finish());
            gpu.take_error()?;
            let boxes = ChunkBounds::parse(&gpu.read_buffer_as::<u32>(&b.boxes, b.count as usize * 6));
            for (i, w) in boxes.iter().enumerate() {
                let first = i as u32 * CHUNK_TRIANGLES;
                list.push(Chunk::new(first, (first + CHUNK_TRIANGLES).min(split), w, proto));
            }
        }
        let moving0 = list.len();
        let dynamic = (split < scene.triangle_count)
            .then(|| ChunkBounds::new(gpu, scene, "virtual.dynamic_bounds", split, scene.triangle_count, DYNAMIC_CHUNK_TRIANGLES));
        if let Some(b) = &dynamic {
            for i in 0..b.count {
                let first = split + i * DYNAMIC_CHUNK_TRIANGLES;
                list.push(Chunk::new(first, (first + DYNAMIC_CHUNK_TRIANGLES).min(scene.triangle_count), &scene.bounds, proto));
            }
        }
        Ok(Chunks { list, moving0, dynamic, boxes: None })
    }

    /// Takes this frame's boxes of the moving chunks (`words`, read back with the requests) and
    /// their rectangles in clipmap `c`; returns the box swept by each chunk that moved since the
    /// last frame (old and new box), over which resident pages are stale. Nothing without moving
    /// chunks.
    pub fn update(&mut self, words: &[u32], c: &Clipmap) -> Vec<Bounds> {
        if self.dynamic.is_none() {
            return Vec::new();
        }
        let now = ChunkBounds::parse(words);
        let mut swept = Vec::new();
        if let Some(before) = &self.boxes {
            for (a, b) in before.iter().zip(&now) {
                if a != b {
                    let mut s = *a;
                    s.grow(b.min);
                    s.grow(b.max);
                    swept.push(s);
                }
            }
        }
        for (i, b) in now.iter().enumerate() {
            let ch = &mut self.list[self.moving0 + i];
            *ch = Chunk::new(ch.first, ch.end, b, c);
        }
        self.boxes = Some(now);
        swept
    }
}
