//! Page drawing helpers of `virtual`: the culling chunks (triangle ranges with their
//! light-coordinate rectangles), the chunks a page draws, the slot-clear pipeline and the
//! static/dynamic split's copy pipeline.

use glam::Vec2;
use shadowlab_core::scene::Bounds;
use shadowlab_core::techniques::virtual_sm::{Clipmap, PageKey};

use crate::{binding, raster, Gpu};

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

/// The slot clear: `vs_clear` at depth 1, depth test Always, no fragment stage.
pub(super) fn clear_pipeline(gpu: &Gpu, source: &str, layouts: &[&wgpu::BindGroupLayout]) -> wgpu::RenderPipeline {
    let module = gpu.shader("virtual.clear", source);
    let layout = gpu.pipeline_layout("virtual.clear", layouts);
    gpu.device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("virtual.clear"),
        layout: Some(&layout),
        vertex: wgpu::VertexState { module: &module, entry_point: Some("vs_clear"), compilation_options: Default::default(), buffers: &[] },
        primitive: Default::default(),
        depth_stencil: Some(depth_always()),
        multisample: Default::default(),
        fragment: None,
        multiview_mask: None,
        cache: None,
    })
}

/// Whether a moving chunk (`chunks[moving0..]`) lies over page `k` now.
pub(super) fn moving_over(chunks: &[Chunk], moving0: usize, c: &Clipmap, k: &PageKey) -> bool {
    !page_draws(&chunks[moving0..], c, k).is_empty()
}

/// The static/dynamic split's copy (copy.wgsl): its bind group layout (the static pool, the
/// per-page offsets) and pipeline (depth test Always, `frag_depth` from the static copy).
pub(super) fn copy_pipeline(gpu: &Gpu) -> (wgpu::BindGroupLayout, wgpu::RenderPipeline) {
    let stages = wgpu::ShaderStages::VERTEX_FRAGMENT;
    let layout = binding::layout(&gpu.device, "virtual.copy", stages, &[binding::texture_depth(), binding::storage(true)]);
    let module = gpu.shader("virtual.copy", super::COPY_WGSL);
    let pl = gpu.pipeline_layout("virtual.copy", &[&layout]);
    let pipeline = gpu.device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("virtual.copy"),
        layout: Some(&pl),
        vertex: wgpu::VertexState { module: &module, entry_point: Some("vs_copy"), compilation_options: Default::default(), buffers: &[] },
        primitive: Default::default(),
        depth_stencil: Some(depth_always()),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs_copy"),
            compilation_options: Default::default(),
            targets: &[],
        }),
        multiview_mask: None,
        cache: None,
    });
    (layout, pipeline)
}

/// Depth written unconditionally (the slot clear and the static copy).
fn depth_always() -> wgpu::DepthStencilState {
    wgpu::DepthStencilState {
        format: raster::DEPTH_FORMAT,
        depth_write_enabled: Some(true),
        depth_compare: Some(wgpu::CompareFunction::Always),
        stencil: Default::default(),
        bias: Default::default(),
    }
}
