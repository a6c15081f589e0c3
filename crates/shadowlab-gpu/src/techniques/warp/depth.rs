//! The warped depth pass (`render`'s `shadow_map` stage, depth.wgsl): the scene, or the
//! subdivision's pieces, drawn with the warp applied per vertex; the fragment stage writes the
//! interpolated depth (depth_plain.wgsl) or, with `exact_depth`, the triangle's depth at the
//! warp's preimage of the fragment (depth_exact.wgsl). Its lookup bindings (the uniform, the DV
//! bounds, the warps) are shared with the occluder and subdivision passes.

use std::ops::Range;

use super::{base_constants, compose, layout_at, WarpParams, Warped, LOOKUP_WGSL, PARAMS_WGSL};
use crate::record::Recorder;
use crate::scene_gpu::GpuScene;
use crate::shaders::flag;
use crate::technique::FrameInputs;
use crate::{binding, raster, Gpu};

const DEPTH_WGSL: &str = include_str!("depth.wgsl");
const DEPTH_PLAIN_WGSL: &str = include_str!("depth_plain.wgsl");
const DEPTH_EXACT_WGSL: &str = include_str!("depth_exact.wgsl");
const DEPTH_VS_WGSL: &str = include_str!("depth_vs.wgsl");
const DEPTH_CLIP_WGSL: &str = include_str!("depth_clip.wgsl");

/// The depth pass; `exact`: the fragment stage writes the plane's depth at the inverted warp.
pub(super) fn source(exact: bool) -> String {
    let fs = if exact { DEPTH_EXACT_WGSL } else { DEPTH_PLAIN_WGSL };
    compose(&format!("{PARAMS_WGSL}{LOOKUP_WGSL}{DEPTH_WGSL}{DEPTH_VS_WGSL}{fs}"), true)
}

/// The paraboloid depth pass that clips behind the split plane instead of discarding
/// (depth_clip.wgsl; needs `wgpu::Features::CLIP_DISTANCES`).
pub(super) fn clipped_source() -> String {
    format!("enable clip_distances;\n{}", compose(&format!("{PARAMS_WGSL}{LOOKUP_WGSL}{DEPTH_WGSL}{DEPTH_CLIP_WGSL}"), true))
}

/// lookup.wgsl's bindings 6-9: the uniform, the DV bounds, the two warps.
pub(super) fn lookup_entries() -> [(u32, wgpu::BindingType); 4] {
    let tex = binding::texture_float();
    [(6, binding::uniform()), (7, binding::storage(true)), (8, tex), (9, tex)]
}

/// The depth pass's pipeline constants (depth.wgsl): the knobs of `p` that choose code paths,
/// and whether the scene has alpha cut-outs.
pub(super) fn constants(p: &WarpParams, cutouts: bool) -> Vec<(&'static str, f64)> {
    let mut c = base_constants(p);
    c.extend([
        ("SUBDIVIDED", flag(p.subdiv > 0.0)),
        ("EXACT_DEPTH", flag(p.exact_depth != 0)),
        ("EXACT_INVERSE", flag(p.exact_inverse > 0.5)),
        ("CUTOUTS", flag(cutouts)),
    ]);
    c
}

/// The lookup layout (bindings 6-9, the pieces at 10) and the warped depth pipeline, specialised
/// to `p` ([`constants`]). A map with interpolated depth over a scene without cut-outs has no
/// fragment stage (the rasteriser then tests depth early, as `sm`) when it discards nothing:
/// planar maps, and paraboloid ones where the device clips behind the split plane
/// ([`clipped_source`]; without clip distances the fragment stage discards there).
pub(super) fn pipeline(gpu: &Gpu, name: &str, scene: &GpuScene, p: &WarpParams) -> (wgpu::BindGroupLayout, wgpu::RenderPipeline) {
    let look = lookup_entries();
    let layout = layout_at(
        gpu,
        &format!("{name}.depth"),
        wgpu::ShaderStages::VERTEX_FRAGMENT,
        &[look[0], look[1], look[2], look[3], (10, binding::storage(true))],
    );
    let pipeline = pipeline_in(gpu, name, scene, p, &layout);
    (layout, pipeline)
}

/// [`pipeline`] with the lookup layout `layout`.
pub(super) fn pipeline_in(gpu: &Gpu, name: &str, scene: &GpuScene, p: &WarpParams, layout: &wgpu::BindGroupLayout) -> wgpu::RenderPipeline {
    let exact = p.exact_depth != 0;
    let clipped = p.projection != 0 && !exact && !scene.has_cutouts && gpu.clip_distances();
    let fragment = exact || scene.has_cutouts || (p.projection != 0 && !clipped);
    let label = format!("{name}.shadow_map");
    let layouts = [layout, &scene.layout];
    let src = if clipped { clipped_source() } else { source(exact) };
    raster::depth_pipeline_with(gpu, &label, &src, &layouts, fragment, &constants(p, scene.has_cutouts))
}

/// The exact-depth pass with the depth test and writes off ([`raster::counting_pipeline`]): the
/// report counts its fragments, each one inversion of the warp.
pub(super) fn counting_pipeline(
    gpu: &Gpu,
    name: &str,
    lookup: &wgpu::BindGroupLayout,
    scene: &SceneBinding,
    p: &WarpParams,
) -> wgpu::RenderPipeline {
    let label = format!("{name}.exact_depth_count");
    let mut c = constants(p, scene.cutouts);
    c.push(("COUNT_INVERSIONS", 1.0));
    raster::counting_pipeline(gpu, &label, &source(true), &[lookup, &scene.layout], &c)
}

/// What a pass needs of the scene after the frame: its bind group layout and cut-outs, and the
/// last frame's group and triangles drawn (set by `render`).
pub(crate) struct SceneBinding {
    pub layout: wgpu::BindGroupLayout,
    pub cutouts: bool,
    pub last: Option<(wgpu::BindGroup, Range<u32>)>,
    /// The report's fragment count: its pipeline, query set and resolve buffer, made on the
    /// first report and kept (the viewer reports after every evaluation).
    pub counting: std::sync::OnceLock<(wgpu::RenderPipeline, wgpu::QuerySet, wgpu::Buffer)>,
}

impl Warped {
    /// The uniform, the DV bounds and the two warps' views.
    pub(super) fn lookup_resources(&self) -> [wgpu::BindingResource<'_>; 4] {
        [
            self.uniform.as_entire_binding(),
            self.dv_binding(),
            wgpu::BindingResource::TextureView(&self.views[0]),
            wgpu::BindingResource::TextureView(&self.views[1]),
        ]
    }

    /// The depth pass's bindings: the lookup resources and the pieces (binding 10).
    pub(super) fn depth_entries(&self) -> Vec<wgpu::BindGroupEntry<'_>> {
        let pieces = if self.params.subdiv > 0.0 { &self.pieces } else { &self.counters };
        let look = self.lookup_resources();
        let mut entries: Vec<wgpu::BindGroupEntry> =
            look.iter().enumerate().map(|(i, r)| wgpu::BindGroupEntry { binding: 6 + i as u32, resource: r.clone() }).collect();
        entries.push(wgpu::BindGroupEntry { binding: 10, resource: pieces.as_entire_binding() });
        entries
    }

    /// The depth pass's group (kept).
    pub(super) fn depth_group(&self, gpu: &Gpu) -> wgpu::BindGroup {
        self.groups.depth.entries(gpu, self.name(), &self.lookup_layout, &self.depth_entries())
    }

    /// The `shadow_map` stage: the pieces the subdivision left (drawn indirectly), or the scene.
    pub(super) fn draw_shadow_map(&mut self, f: &FrameInputs, rec: &mut Recorder, depth_group: &wgpu::BindGroup) {
        let name = self.name();
        rec.stage(&format!("{name}.shadow_map"), |enc| {
            let mut pass = raster::begin_pass(enc, &format!("{name}.shadow_map"), &[], &self.views[2]);
            pass.set_pipeline(&self.depth_pipeline);
            self.draw_pieces(&mut pass, depth_group, &f.scene.group, self.triangles(f.scene), self.flat_pipeline.as_ref());
        });
        self.scene.last = Some((f.scene.group.clone(), self.triangles(f.scene)));
    }

    /// The map's draw after its pipeline is set: the pieces (indirect: its own, or its share of
    /// its owner's, the flat ones with `flat`) or the scene.
    fn draw_pieces(
        &self,
        pass: &mut wgpu::RenderPass,
        depth_group: &wgpu::BindGroup,
        scene_group: &wgpu::BindGroup,
        triangles: Range<u32>,
        flat: Option<&wgpu::RenderPipeline>,
    ) {
        pass.set_bind_group(0, depth_group, &[]);
        pass.set_bind_group(1, scene_group, &[]);
        if let Some(d) = &self.owner_draw {
            d.draw(pass, flat);
        } else if self.params.subdiv > 0.0 {
            pass.draw_indirect(&self.counters, 16);
        } else {
            pass.draw(triangles.start * 3..triangles.end * 3, 0..1);
        }
    }

    /// Fragments the last frame's exact-depth pass inverted the warp for (discarded ones, behind
    /// a paraboloid's split plane or cut out, and those of pieces without a plane or within
    /// `exact_tol`, not counted): its draw again, with the depth test off, under an occlusion
    /// query (the map is kept).
    /// 0 without `exact_depth` (no fragment inverts the warp); None before a frame. Maps
    /// subdivided by their owner (`cube-notw`'s faces, `dpsm`'s hemispheres) keep theirs listed.
    pub(super) fn exact_depth_fragments(&self, gpu: &Gpu) -> Option<u64> {
        let (scene_group, triangles) = self.scene.last.as_ref()?;
        if self.params.exact_depth == 0 {
            return Some(0);
        }
        let (pipeline, set, resolve) = self.scene.counting.get_or_init(|| {
            let pipeline = counting_pipeline(gpu, self.name(), &self.lookup_layout, &self.scene, &self.params);
            let set = gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("warp.exact_count"),
                ty: wgpu::QueryType::Occlusion,
                count: 1,
            });
            let resolve = gpu.buffer(&wgpu::BufferDescriptor {
                label: Some("warp.exact_count"),
                size: 8,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            (pipeline, set, resolve)
        });
        let depth_group = self.depth_group(gpu);
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("warp.exact_count"),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &self.views[2],
                    depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: Some(set),
                multiview_mask: None,
            });
            pass.set_pipeline(pipeline);
            pass.begin_occlusion_query(0);
            // (the flat pieces invert nothing: not drawn)
            self.draw_pieces(&mut pass, &depth_group, scene_group, triangles.clone(), None);
            pass.end_occlusion_query();
        }
        enc.resolve_query_set(set, 0..1, resolve, 0);
        gpu.submit(enc.finish());
        Some(gpu.read_buffer_as::<u64>(resolve, 1)[0])
    }
}
