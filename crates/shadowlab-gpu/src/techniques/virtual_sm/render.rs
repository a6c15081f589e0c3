//! `virtual`'s page rendering. Pass 1 draws the static copies the frame fills (static chunks
//! only) into their slots of the static pool; pass 2 builds every rendered page in its atlas
//! slot: a page drawn whole is cleared and gets every chunk over it; a page with a static copy
//! gets the copy (copy.wgsl) and then the moving chunks over it. Each page is drawn with its
//! own view-projection (page.wgsl, the page's instance).

use shadowlab_core::techniques::virtual_sm::Build;

use super::allocate::Pages;
use super::draw::{page_draws, Chunks};
use super::resources::Resources;
use super::setup::Pool;
use crate::record::Recorder;
use crate::scene_gpu::GpuScene;
use crate::shaders::compose_depth;
use crate::technique::FrameInputs;
use crate::{binding, raster, Gpu};

const PAGE_WGSL: &str = include_str!("page.wgsl");
pub(super) const COPY_WGSL: &str = include_str!("copy.wgsl");

pub(super) fn page_source() -> String {
    compose_depth(PAGE_WGSL)
}

/// The pipelines and bind groups of both passes.
pub(super) struct PagePass {
    page_res: u32,
    /// The rendered pages' view-projections.
    page_group: wgpu::BindGroup,
    page_pipeline: wgpu::RenderPipeline,
    clear_pipeline: wgpu::RenderPipeline,
    /// The static pool and the per-page copy offsets.
    copy_group: wgpu::BindGroup,
    copy_pipeline: wgpu::RenderPipeline,
}

impl PagePass {
    pub fn new(gpu: &Gpu, scene: &GpuScene, page_res: u32, r: &Resources) -> PagePass {
        let d = &gpu.device;
        let (copy_layout, copy_pipeline) = copy_pipeline(gpu);
        let static_view = r.static_atlas.create_view(&Default::default());
        let copy_group = binding::group(
            gpu,
            "virtual.copy",
            &copy_layout,
            &[wgpu::BindingResource::TextureView(&static_view), r.copy_offsets.as_entire_binding()],
        );
        let page_layout = binding::layout(d, "virtual.page", wgpu::ShaderStages::VERTEX, &[binding::storage(true)]);
        let page_group = binding::group(gpu, "virtual.page", &page_layout, &[r.page_mats.as_entire_binding()]);
        let page_pipeline = raster::depth_pipeline(gpu, "virtual.page", &page_source(), &[&page_layout, &scene.layout], scene.has_cutouts);
        let clear_pipeline = clear_pipeline(gpu, &page_source(), &[&page_layout, &scene.layout]);
        PagePass { page_res, page_group, page_pipeline, clear_pipeline, copy_group, copy_pipeline }
    }

    /// Both passes over the pages `p` allocated in the last `prepare` into the slots of `pool`;
    /// returns the triangles drawn.
    pub fn render(&self, f: &FrameInputs, rec: &mut Recorder, p: &Pages, chunks: &Chunks, r: &Resources, pool: &Pool) -> u64 {
        let (Some(c), false) = (&p.clipmap, p.alloc.render.is_empty()) else { return 0 };
        let (pr, m0, list) = (self.page_res, chunks.moving0, &chunks.list);
        let (static_cols, cols) = (pool.static_cols, pool.cols);
        let origin = |slot: u32, cols: u32| ((slot % cols) * pr, (slot / cols) * pr);
        // per rendered page: the chunks of pass 1 (static copy) and of pass 2
        let mut fills = Vec::new();
        let mut draws = Vec::new();
        for (i, ((k, _), b)) in p.alloc.render.iter().zip(&p.builds).enumerate() {
            match b {
                Build::Full => draws.push(page_draws(list, c, k)),
                Build::Fill(s) => {
                    fills.push((i as u32, origin(*s, static_cols), page_draws(&list[..m0], c, k)));
                    draws.push(page_draws(&list[m0..], c, k));
                }
                Build::Copy(_) => draws.push(page_draws(&list[m0..], c, k)),
            }
        }
        let mut triangles = 0;
        if !fills.is_empty() {
            let slots: Vec<(u32, (u32, u32))> = fills.iter().map(|(i, o, _)| (*i, *o)).collect();
            self.page_pass(rec, "virtual.render_static", &r.static_atlas, f, &slots, |pass, i| {
                pass.set_pipeline(&self.clear_pipeline);
                pass.draw(0..3, 0..1);
                pass.set_pipeline(&self.page_pipeline);
                let (_, _, ranges) = fills.iter().find(|e| e.0 == i).expect("a fill per slot");
                triangles += draw_ranges(pass, ranges, i);
            });
        }
        let slots: Vec<(u32, (u32, u32))> = p.alloc.render.iter().enumerate().map(|(i, (_, s))| (i as u32, origin(*s, cols))).collect();
        self.page_pass(rec, "virtual.render", &r.atlas, f, &slots, |pass, i| {
            if p.builds[i as usize] == Build::Full {
                pass.set_pipeline(&self.clear_pipeline);
                pass.draw(0..3, 0..1);
            } else {
                pass.set_pipeline(&self.copy_pipeline);
                pass.set_bind_group(0, &self.copy_group, &[]);
                pass.draw(0..3, i..i + 1);
                pass.set_bind_group(0, &self.page_group, &[]);
            }
            pass.set_pipeline(&self.page_pipeline);
            triangles += draw_ranges(pass, &draws[i as usize], i);
        });
        triangles
    }

    /// One pass over `target` that, per page `(instance, origin)` in `slots`, sets the page's
    /// viewport and runs `draw` (which binds its own pipelines).
    fn page_pass(
        &self,
        rec: &mut Recorder,
        stage: &str,
        target: &wgpu::Texture,
        f: &FrameInputs,
        slots: &[(u32, (u32, u32))],
        mut draw: impl FnMut(&mut wgpu::RenderPass<'_>, u32),
    ) {
        let view = target.create_view(&Default::default());
        let pr = self.page_res;
        rec.stage(stage, |enc| {
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some(stage),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &view,
                    depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_bind_group(0, &self.page_group, &[]);
            pass.set_bind_group(1, &f.scene.group, &[]);
            for &(i, (x, y)) in slots {
                pass.set_viewport(x as f32, y as f32, pr as f32, pr as f32, 0.0, 1.0);
                pass.set_scissor_rect(x, y, pr, pr);
                draw(&mut pass, i);
            }
        });
    }
}

/// Draws triangle ranges with instance `i` (page i's view-projection).
fn draw_ranges(pass: &mut wgpu::RenderPass<'_>, ranges: &[(u32, u32)], i: u32) -> u64 {
    for &(a, b) in ranges {
        pass.draw(a * 3..b * 3, i..i + 1);
    }
    ranges.iter().map(|&(a, b)| (b - a) as u64).sum()
}

/// The slot clear: `vs_clear` at depth 1, depth test Always, no fragment stage.
fn clear_pipeline(gpu: &Gpu, source: &str, layouts: &[&wgpu::BindGroupLayout]) -> wgpu::RenderPipeline {
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

/// The static/dynamic split's copy (copy.wgsl): its bind group layout (the static pool, the
/// per-page offsets) and pipeline (depth test Always, `frag_depth` from the static copy).
fn copy_pipeline(gpu: &Gpu) -> (wgpu::BindGroupLayout, wgpu::RenderPipeline) {
    let stages = wgpu::ShaderStages::VERTEX_FRAGMENT;
    let layout = binding::layout(&gpu.device, "virtual.copy", stages, &[binding::texture_depth(), binding::storage(true)]);
    let module = gpu.shader("virtual.copy", COPY_WGSL);
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
