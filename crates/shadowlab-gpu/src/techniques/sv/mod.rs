//! `sv`: silhouette-based stencil shadow volumes with z-fail (Carmack's reverse) counting, the
//! ground truth of seeds 000 and 002. Robust on real meshes: every non-degenerate triangle casts
//! its own volume (so open surfaces and single-sided triangles cast, like the `rt` reference),
//! and the side quads of all volumes on one edge sum to the edge's signed multiplicity (MKZP14;
//! shadowlab-core `edges`), which handles open edges and edges shared by three or more
//! triangles. Closed volumes: light caps (the triangles themselves), dark caps and sides pushed
//! to infinity (w = 0) with unclipped depth where the adapter has `DEPTH_CLIP_CONTROL`, else by
//! the `far` distance. Alpha-masked geometry is solid (counted as `cutout_triangles`).
//!
//! Passes: `sv.silhouettes` (compute: facing per triangle, multiplicity per edge, side records
//! appended for an indirect draw), `sv.stencil` (the G-buffer depth copied into a depth-stencil
//! target, then sides and caps with two-sided increment/decrement-wrap stencil on depth fail),
//! `sv.resolve` (a full-screen pass with the stencil test "equal 0" writes a lit flag; a compute
//! pass turns it into `visibility`).

mod pipelines;

use bytemuck::{Pod, Zeroable};
use shadowlab_core::light::Light;
use shadowlab_core::params::{ParamDef, ParamSet, ParamTable};
use shadowlab_core::techniques::sv::EdgeList;

use crate::record::Recorder;
use crate::scene_gpu::GpuScene;
use crate::technique::{FrameInputs, Technique, TechniqueInfo, TechniqueReport};
use crate::{raster, Gpu, GpuError};
use pipelines::{dispatch_1d, Pipelines, LIT_FORMAT};

pub use pipelines::shaders;

/// Extrusion distance in scene diagonals; 0 = to infinity (w = 0, needs unclipped depth).
/// Finite: any point inside the scene bounds moved by one diagonal leaves them, so 1 is the
/// least that works; but the extruded ends must stay inside the camera's far plane (clipped
/// volume ends miscount where they lie behind receivers).
pub const DEFAULT_FAR: f64 = 0.0;
/// Receiver depth moved towards the camera by this many f32 ulps, so that ties between a
/// receiver and a light cap at the same depth (its own triangle, coplanar duplicates) resolve as
/// "cap behind". Measured at 1024x1024 (docs/bench/sv.md): 0 leaves 97 wrong pixels away from
/// shadow edges on sponza (half of them at N.L < 0.1), 4 leaves 6; wrong pixels summed over
/// courtyard, room (spot), sponza, conference (spot) fall from 572 to 476. Too high: occluders
/// within that depth of a receiver are missed (contact shadows; 16 ulps: 480 wrong on sponza).
pub const DEFAULT_DEPTH_OFFSET: f64 = 4.0;

shadowlab_core::param_set! {
    /// `sv`'s parameters.
    pub struct SvSettings {
        pub far: f64 = ParamDef::number("far", DEFAULT_FAR, 0.0, 1000.0, "extrusion distance in scene diagonals (>= 1); 0 = infinite (w = 0) with unclipped depth, or 2 where the adapter lacks DEPTH_CLIP_CONTROL", "infinite extrusion: Everitt & Kilgard 2002; unclipped depth replaces their depth clamp"),
        pub depth_offset: u32 = ParamDef::integer("depth_offset", DEFAULT_DEPTH_OFFSET, 0.0, 65536.0, "receiver depth moved towards the camera, f32 ulps; against self-shadowing of a surface by its own light cap", "shadowlab sweep 0/4/16/64/1024 ulps, 2026-11-22 (docs/bench/sv.md)"),
    }
    rules {
        fn validate(&self) -> Result<(), String> {
            let far = self.far;
            if far > 0.0 && far < 1.0 {
                return Err(format!("far={far}: a finite extrusion must be at least 1 scene diagonal (or 0 = infinite)"));
            }
            Ok(())
        }
    }
}

pub const INFO: TechniqueInfo = TechniqueInfo {
    name: "sv",
    summary: "silhouette shadow volumes: per-edge multiplicity (open and non-manifold edges), z-fail stencil, infinite extrusion; alpha-masked geometry casts as solid",
    cost: "compute pass over the edge list + fill of every volume side and cap over the screen (fill-rate bound); no shadow map",
    quality: "exact hard shadows of the geometry (the seeds' ground truth); alpha cut-outs are treated as solid, so leaves cast blocks",
    source: "Crow 1977; z-fail: Everitt & Kilgard 2002; multiplicity: Milet, Kobrtek, Zemcik, Peciva 2014 (MKZP14 in seed 000)",
    lights: &["directional", "spot", "point"],
    params: ParamTable::of::<SvSettings>(),
    stalls: "",
    needs: "11 storage buffers per shader stage (WebGPU default: 8); optional: DEPTH_CLIP_CONTROL (unclipped depth for the infinite extrusion) and DEPTH32FLOAT_STENCIL8, used where offered",
    storage_buffers: 11,
    compare: &[""],
    shaders,
    create: |gpu, scene, p, light| Ok(Box::new(ShadowVolumes::new(gpu, scene, &SvSettings::from_values(p), light)?)),
};

/// WGSL `SvParams` (silhouette.wgsl, volume.wgsl, resolve.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct SvParams {
    pub triangles: u32,
    pub edges: u32,
    /// Vertices per side record (3 or 6).
    pub side_vertices: u32,
    /// Receiver depth offset (f32 ulps).
    pub depth_offset: u32,
    /// Extrusion distance (world; 0 = infinite).
    pub extrude: f32,
    pub pad0: f32,
    pub pad1: f32,
    pub pad2: f32,
}

/// Per-view targets, made for the G-buffer size.
struct Targets {
    width: u32,
    height: u32,
    /// The depth-stencil and lit targets' views.
    depth: wgpu::TextureView,
    lit: wgpu::TextureView,
}

pub struct ShadowVolumes {
    /// The evaluation's, the silhouette pass's, the volumes' and the resolve's bind groups, kept.
    pub(crate) groups: crate::binding::GroupCache,
    kept: [crate::binding::GroupCache; 3],
    params: SvParams,
    uniform: wgpu::Buffer,
    list: EdgeList,
    edges: wgpu::Buffer,
    adj: wgpu::Buffer,
    facing: wgpu::Buffer,
    sides: wgpu::Buffer,
    draw: wgpu::Buffer,
    stats: wgpu::Buffer,
    p: Pipelines,
    depth_format: wgpu::TextureFormat,
    infinite: bool,
    targets: Option<Targets>,
    /// The last frame's volume and scene bind groups and vertex count, for the fill count.
    last: Option<(wgpu::BindGroup, wgpu::BindGroup, u32)>,
}

impl ShadowVolumes {
    pub fn new(gpu: &Gpu, scene: &GpuScene, p: &SvSettings, light: &Light) -> Result<ShadowVolumes, GpuError> {
        let features = gpu.device.features();
        let unclipped = features.contains(wgpu::Features::DEPTH_CLIP_CONTROL);
        p.validate().map_err(|e| GpuError::Invalid(format!("sv {e}")))?;
        let far = p.far;
        let infinite = far == 0.0 && unclipped;
        let far = if far == 0.0 && !unclipped { 2.0 } else { far };
        let depth_format = if features.contains(wgpu::Features::DEPTH32FLOAT_STENCIL8) {
            wgpu::TextureFormat::Depth32FloatStencil8
        } else {
            wgpu::TextureFormat::Depth24PlusStencil8
        };
        let positions = Pipelines::gather_positions(gpu, scene);
        let list = EdgeList::build(&positions);
        let vps = if infinite && matches!(light, Light::Directional { .. }) { 3 } else { 6 };
        let params = SvParams {
            triangles: scene.triangle_count,
            edges: list.edges.len() as u32,
            side_vertices: vps,
            depth_offset: p.depth_offset,
            extrude: if infinite { 0.0 } else { (far * scene.bounds.diagonal() as f64) as f32 },
            pad0: 0.0,
            pad1: 0.0,
            pad2: 0.0,
        };
        let max = gpu.limits.max_storage_buffer_binding_size;
        if list.bytes() > max || list.adj.len() as u64 * 4 > max {
            return Err(GpuError::Invalid(format!("sv: edge list of {} bytes is over this device's storage binding limit", list.bytes())));
        }
        let st = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
        let edges = gpu.buffer_init("sv.edges", bytemuck::cast_slice(&list.edges), st);
        let adj = gpu.buffer_init("sv.adj", bytemuck::cast_slice(&list.adj), st);
        let facing = gpu.storage("sv.facing", scene.triangle_count as u64 * 4);
        // at most sum |m| <= sum of valences = adj.len() side records
        let sides = gpu.storage("sv.sides", list.adj.len() as u64 * 4);
        let draw = gpu.buffer_init("sv.draw", bytemuck::cast_slice(&[0u32, 1, 0, 0]), st | wgpu::BufferUsages::INDIRECT);
        let stats = gpu.storage("sv.stats", 16);
        let p = Pipelines::new(gpu, &scene.layout, depth_format, unclipped);
        let uniform = gpu.uniform("sv.params", &params);
        Ok(ShadowVolumes {
            kept: Default::default(),
            groups: Default::default(),
            params,
            uniform,
            list,
            edges,
            adj,
            facing,
            sides,
            draw,
            stats,
            p,
            depth_format,
            infinite,
            targets: None,
            last: None,
        })
    }

    fn targets(&mut self, gpu: &Gpu, w: u32, h: u32) -> &Targets {
        if self.targets.as_ref().is_none_or(|t| (t.width, t.height) != (w, h)) {
            let depth = raster::render_target(gpu, "sv.depth_stencil", w, h, self.depth_format, wgpu::TextureUsages::empty());
            let lit = raster::render_target(gpu, "sv.lit", w, h, LIT_FORMAT, wgpu::TextureUsages::empty());
            let (depth, lit) = (depth.create_view(&Default::default()), lit.create_view(&Default::default()));
            self.targets = Some(Targets { width: w, height: h, depth, lit });
        }
        self.targets.as_ref().unwrap()
    }
}

impl ShadowVolumes {
    /// Fragments the last frame's volume geometry rasterises (sides and caps, every sample
    /// counted whatever its depth): an occlusion query over the same draws with the tests off.
    fn fill_fragments(&self, gpu: &Gpu) -> Option<u64> {
        let (vol_group, scene_group, verts) = self.last.as_ref()?;
        let t = self.targets.as_ref()?;
        let set =
            gpu.device.create_query_set(&wgpu::QuerySetDescriptor { label: Some("sv.fill"), ty: wgpu::QueryType::Occlusion, count: 1 });
        let resolve = gpu.buffer(&wgpu::BufferDescriptor {
            label: Some("sv.fill"),
            size: 8,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let ds = &t.depth;
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("sv.fill"),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment { view: ds, depth_ops: None, stencil_ops: None }),
                timestamp_writes: None,
                occlusion_query_set: Some(&set),
                multiview_mask: None,
            });
            pass.set_bind_group(0, vol_group, &[]);
            pass.set_bind_group(1, scene_group, &[]);
            pass.begin_occlusion_query(0);
            pass.set_pipeline(&self.p.fill[0]);
            pass.draw_indirect(&self.draw, 0);
            pass.set_pipeline(&self.p.fill[1]);
            pass.draw(0..*verts, 0..1);
            pass.set_pipeline(&self.p.fill[2]);
            pass.draw(0..*verts, 0..1);
            pass.end_occlusion_query();
        }
        enc.resolve_query_set(&set, 0..1, &resolve, 0);
        gpu.submit(enc.finish());
        Some(gpu.read_buffer_as::<u64>(&resolve, 1)[0])
    }
}

impl Technique for ShadowVolumes {
    fn render(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        rec.write_buffer(&self.draw, 0, bytemuck::cast_slice(&[0u32, 1, 0, 0]));
        rec.write_buffer(&self.stats, 0, &[0u8; 16]);
        let group = self.kept[0].get(
            gpu,
            "sv.silhouettes",
            &self.p.sil_layout,
            &[
                f.light_buf.as_entire_binding(),
                self.uniform.as_entire_binding(),
                self.edges.as_entire_binding(),
                self.adj.as_entire_binding(),
                self.facing.as_entire_binding(),
                self.sides.as_entire_binding(),
                self.draw.as_entire_binding(),
                self.stats.as_entire_binding(),
            ],
        );
        let (tris, edges) = (self.params.triangles, self.params.edges);
        rec.stage("sv.silhouettes", |enc| {
            dispatch_1d(gpu, enc, "sv.facing", &self.p.facing, &[&group, &f.scene.group], tris);
            dispatch_1d(gpu, enc, "sv.edges", &self.p.edges, &[&group, &f.scene.group], edges);
        });
        Ok(())
    }

    fn evaluate(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        let (w, h) = (f.gbuffer.width, f.gbuffer.height);
        self.targets(gpu, w, h);
        let t = self.targets.as_ref().unwrap();
        let vol_group = self.kept[1].get(
            gpu,
            "sv.volumes",
            &self.p.vol_layout,
            &[
                f.frame.as_entire_binding(),
                f.light_buf.as_entire_binding(),
                self.uniform.as_entire_binding(),
                self.edges.as_entire_binding(),
                self.facing.as_entire_binding(),
                self.sides.as_entire_binding(),
            ],
        );
        let res_group = self.kept[2].get(
            gpu,
            "sv.resolve",
            &self.p.resolve_layout,
            &[wgpu::BindingResource::TextureView(&f.gbuffer.depth_view), self.uniform.as_entire_binding()],
        );
        let (ds, lit) = (&t.depth, &t.lit);
        let verts = f.scene.triangle_count * 3;
        rec.stage("sv.stencil", |enc| {
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("sv.stencil"),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: ds,
                    depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Store }),
                    stencil_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(0), store: wgpu::StoreOp::Store }),
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.p.copy_depth);
            pass.set_bind_group(0, &res_group, &[]);
            pass.draw(0..3, 0..1);
            pass.set_bind_group(0, &vol_group, &[]);
            pass.set_bind_group(1, &f.scene.group, &[]);
            pass.set_pipeline(&self.p.sides);
            pass.draw_indirect(&self.draw, 0);
            pass.set_pipeline(&self.p.caps_ccw);
            pass.draw(0..verts, 0..1);
            pass.set_pipeline(&self.p.caps_cw);
            pass.draw(0..verts, 0..1);
        });
        self.last = Some((vol_group, f.scene.group.clone(), verts));
        let eval_group = f.view_group(gpu, &self.groups, "sv.eval", &self.p.eval_layout, &[wgpu::BindingResource::TextureView(lit)]);
        rec.stage("sv.resolve", |enc| {
            {
                let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("sv.lit"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: lit,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT), store: wgpu::StoreOp::Store },
                    })],
                    depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment { view: ds, depth_ops: None, stencil_ops: None }),
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                pass.set_pipeline(&self.p.lit);
                pass.set_bind_group(0, &res_group, &[]);
                pass.set_stencil_reference(0);
                pass.draw(0..3, 0..1);
            }
            gpu.dispatch_2d(enc, "sv.eval", &self.p.eval, &[&eval_group], w, h);
        });
        Ok(())
    }

    fn report(&mut self, gpu: &Gpu) -> TechniqueReport {
        let stats: Vec<u32> = gpu.read_buffer_as(&self.stats, 4);
        let draw: Vec<u32> = gpu.read_buffer_as(&self.draw, 4);
        let vps = self.params.side_vertices;
        let (open, manifold, more) = self.list.valence_counts();
        let casting = stats[1] as f64;
        let pixels = self.targets.as_ref().map_or(0, |t| t.width as u64 * t.height as u64);
        // depth-stencil: 4 + 1 bytes per pixel (D32F + S8; D24S8: 4), lit flag 1 byte
        let ds_bytes = if self.depth_format == wgpu::TextureFormat::Depth32FloatStencil8 { 5 } else { 4 };
        let mut r = TechniqueReport {
            shadow_data_bytes: self.list.bytes() + self.facing.size() + self.sides.size() + self.draw.size() + pixels * (ds_bytes + 1),
            ..Default::default()
        };
        let mut c = |k: &str, v: f64| r.counters.insert(k.into(), v);
        c("edges", self.list.edges.len() as f64);
        c("edges_open", open as f64);
        c("edges_manifold", manifold as f64);
        c("edges_nonmanifold", more as f64);
        c("welded_vertices", self.list.welded_vertices as f64);
        c("silhouette_edges", stats[2] as f64);
        c("side_records", stats[3] as f64);
        c("side_triangles", (draw[0] / 3) as f64);
        c("cap_triangles", if vps == 6 { 2.0 * casting } else { casting });
        c("cutout_triangles", stats[0] as f64);
        c("extrusion_infinite", self.infinite as u32 as f64);
        c("depth_offset_ulps", self.params.depth_offset as f64);
        if let Some(fill) = self.fill_fragments(gpu) {
            c("volume_fragments_per_pixel", fill as f64 / pixels.max(1) as f64);
        }
        r
    }
}
