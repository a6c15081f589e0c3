//! GPU side of `iasm`: resources, the per-frame plan (from the analysis read back) and the
//! passes. Stage names (timing keys): `iasm.importance` (analysis
//! pass), `iasm.readback` (waiting for and mapping the 16 tiles' stats: the sync cost),
//! `iasm.shadows.clear`, `iasm.shadows.tNN` (tile NN), `iasm.evaluate`.

use glam::Vec3;
use shadowlab_core::light::Light;
use shadowlab_core::techniques::iasm::{self as core, Anchor, Placement, THESIS_RESOLUTIONS, TILE_COUNT};

use super::atlas::{make_atlas, Atlas};
use super::chunks::chunk_bounds;
use super::fit::ViewFit;
use super::plan::{Plan, TileStats};
use super::{analysis_src, eval_src, probe_src, IasmFit, IasmParams, IasmSettings, IasmStore, TileParams, RENDER_WGSL};
use crate::record::{DelayedRead, Recorder};
use crate::scene_gpu::GpuScene;
use crate::shaders::compose_depth;
use crate::technique::{view_layout, FrameInputs, Technique, TechniqueReport};
use crate::{binding, Gpu, GpuError};

const TILE_STRIDE: u64 = 256;
const DUMMY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R8Unorm;

pub struct Iasm {
    pub(super) m: f32,
    pub(super) k: f32,
    size: f32,
    bias: f32,
    normal_offset: f32,
    delayed: bool,
    snap: bool,
    anchor: Anchor,
    pub(super) chunk: u32,
    pub(super) triangles: u32,
    light_dir: Vec3,
    /// Light-space (x, y, depth) boxes of the chunks (None: empty chunk).
    pub(super) boxes: Vec<(Vec3, Vec3)>,
    pub placement: Placement,
    pub plan: Plan,
    pub atlas: Option<Atlas>,
    /// `fit=view`: the square from the view samples' bounds (None: the thesis's fixed rule).
    pub(super) fit: Option<ViewFit>,
    /// Delayed: the analysis of the previous frame is in `stats_buf`, made over `analysed`.
    pending: bool,
    analysed: Placement,
    /// Delayed: this frame's own placement, analysed after the shadows for the next frame.
    current: Placement,
    pub(super) params_buf: wgpu::Buffer,
    stats_buf: wgpu::Buffer,
    pub(super) shadow: wgpu::Buffer,
    pub(super) counts: wgpu::Buffer,
    tile_buf: wgpu::Buffer,
    pub(super) tile_groups: Vec<wgpu::BindGroup>,
    dummy: wgpu::TextureView,
    analysis_layout: wgpu::BindGroupLayout,
    analysis: wgpu::ComputePipeline,
    render: wgpu::RenderPipeline,
    eval_layout: wgpu::BindGroupLayout,
    eval: wgpu::ComputePipeline,
    eval_count: wgpu::ComputePipeline,
    /// Delayed mode: the previous frame's statistics, read back without a stall.
    delayed_read: DelayedRead,
    /// The parameters this frame was evaluated with (the analysis pass evaluates with them
    /// again; delayed mode has overwritten the buffer for the next frame by then).
    evaluated: Option<IasmParams>,
}

impl Iasm {
    pub fn new(gpu: &Gpu, scene: &GpuScene, p: &IasmSettings, light: &Light) -> Result<Iasm, GpuError> {
        let Light::Directional { direction } = *light else {
            return Err(GpuError::Invalid(format!("iasm supports directional lights only, not {}", light.kind())));
        };
        let d = &gpu.device;
        let texels = core::texels(&THESIS_RESOLUTIONS);
        if texels * 4 > gpu.limits.max_storage_buffer_binding_size {
            return Err(GpuError::Invalid("iasm shadow buffer exceeds this device's storage binding limit".into()));
        }
        let chunk = p.chunk.max(1);
        let triangles = scene.triangle_count;
        let (right, up, dir) = core::light_basis(direction);
        let basis = Placement { right, up, dir, origin: glam::Vec2::ZERO, size: 1.0 };
        let boxes = chunk_bounds(gpu, scene, chunk)?.into_iter().map(|(a, b)| core::light_box(&basis, a, b)).collect();
        let sb = core::light_box(&basis, scene.bounds.min, scene.bounds.max);
        let size = match p.size as f32 {
            s if s > 0.0 => s,
            _ => (sb.1.x - sb.0.x).max(sb.1.y - sb.0.y).max(1e-3),
        };

        let params_buf = gpu.uniform("iasm.params", &<IasmParams as bytemuck::Zeroable>::zeroed());
        let stats_buf = gpu.storage("iasm.stats", TILE_COUNT as u64 * 32 + 4);
        let shadow = gpu.storage("iasm.shadow", texels * core::TEXEL_BYTES);
        let counts = gpu.storage("iasm.counts", texels * 4);
        let tile_buf = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("iasm.tiles"),
            size: TILE_STRIDE * TILE_COUNT as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        // the tile uniform for both stages, the buffer for the fragment stage only (writable
        // storage in vertex shaders needs a feature)
        let entry = |i: u32, visibility, ty| wgpu::BindGroupLayoutEntry { binding: i, visibility, ty, count: None };
        let render_layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("iasm.render"),
            entries: &[
                entry(0, wgpu::ShaderStages::VERTEX_FRAGMENT, binding::uniform()),
                entry(1, wgpu::ShaderStages::FRAGMENT, binding::storage(false)),
            ],
        });
        let tile_groups = (0..TILE_COUNT as u64)
            .map(|t| {
                let tb = wgpu::BufferBinding { buffer: &tile_buf, offset: t * TILE_STRIDE, size: wgpu::BufferSize::new(80) };
                binding::group(d, "iasm.render", &render_layout, &[wgpu::BindingResource::Buffer(tb), shadow.as_entire_binding()])
            })
            .collect();
        let max_res = THESIS_RESOLUTIONS[0];
        let dummy = d
            .create_texture(&wgpu::TextureDescriptor {
                label: Some("iasm.dummy"),
                size: wgpu::Extent3d { width: max_res, height: max_res, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: DUMMY_FORMAT,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
                view_formats: &[],
            })
            .create_view(&Default::default());
        let analysis_layout = view_layout(gpu, "iasm.analysis", &[binding::uniform(), binding::storage(false)]);
        let analysis = gpu.compute_pipeline("iasm.analysis", &analysis_src(), "main", &[&analysis_layout]);
        let eval_layout = view_layout(gpu, "iasm.eval", &[binding::uniform(), binding::storage(true), binding::storage(false)]);
        let eval = gpu.compute_pipeline("iasm.evaluate", &eval_src(), "main", &[&eval_layout]);
        let eval_count = gpu.compute_pipeline_with("iasm.evaluate", &eval_src(), "main", &[&eval_layout], crate::context::COUNTING);
        let render = render_pipeline(gpu, &[&render_layout, &scene.layout]);
        let atlas =
            (p.store == IasmStore::Atlas).then(|| make_atlas(gpu, &[&render_layout, &scene.layout], scene.has_cutouts)).transpose()?;
        Ok(Iasm {
            m: p.m as f32,
            k: p.k as f32,
            size,
            bias: p.bias as f32,
            normal_offset: p.normal_offset as f32,
            delayed: p.delayed,
            snap: p.snap,
            anchor: p.anchor.into(),
            chunk,
            triangles,
            light_dir: direction,
            boxes,
            placement: basis,
            plan: Plan::default(),
            atlas,
            fit: (p.fit == IasmFit::View).then(|| ViewFit::new(gpu, direction, p.margin as f32, 1e-3 * size, p.snap, p.delayed)),
            pending: false,
            analysed: basis,
            current: basis,
            params_buf,
            stats_buf,
            shadow,
            counts,
            tile_buf,
            tile_groups,
            dummy,
            analysis_layout,
            analysis,
            render,
            eval_layout,
            eval,
            eval_count,
            delayed_read: DelayedRead::new(gpu, "iasm.delayed", (TILE_COUNT * 8 + 1) as u64 * 4),
            evaluated: None,
        })
    }

    pub fn size(&self) -> f32 {
        self.size
    }

    /// The uniform of this frame (placement and plan).
    pub fn params(&self) -> IasmParams {
        let p = &self.placement;
        let k = if self.k > 0.0 { self.k } else { 0.5 * p.size };
        let res = std::array::from_fn(|t| if self.plan.empty[t] { 0 } else { self.plan.res[t] });
        let mut slot = [0; TILE_COUNT];
        if let Some(a) = &self.atlas {
            for (rank, &t) in self.plan.order.iter().enumerate() {
                slot[t] = a.slots[rank][0] | a.slots[rank][1] << 16;
            }
        }
        IasmParams {
            right: p.right.extend(p.origin.x).into(),
            up: p.up.extend(p.origin.y).into(),
            dir: p.dir.extend(p.size).into(),
            imp: [self.m, k, self.bias, self.normal_offset],
            res,
            off: self.plan.off,
            near: self.plan.near,
            far: self.plan.far,
            slot,
        }
    }

    /// Places the square for the camera of `f`: fitted to the view samples (`fit=view`, when
    /// any was evaluated) or by the thesis's rule.
    fn place(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) {
        if let Some(p) = self.fit.as_mut().and_then(|v| v.place(gpu, f, rec)) {
            self.placement = p;
            return;
        }
        let cam = &f.camera;
        let forward = (cam.target - cam.position).normalize_or_zero();
        let min_res = *THESIS_RESOLUTIONS.iter().min().unwrap_or(&16) as f32;
        let step = self.snap.then_some(self.size / core::TILES_PER_SIDE as f32 / min_res);
        self.placement = core::place(self.light_dir, cam.position, forward, self.size, step, self.anchor);
    }

    fn analysis_extra(&self) -> [wgpu::BindingResource<'_>; 2] {
        [self.params_buf.as_entire_binding(), self.stats_buf.as_entire_binding()]
    }

    /// Dispatches the analysis of `f` with the current placement into `stats_buf`.
    fn analyse(&self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) {
        rec.write_buffer(&self.params_buf, 0, bytemuck::bytes_of(&self.params()));
        let mut init: Vec<u32> = (0..TILE_COUNT).flat_map(|_| [0, 0, 0, u32::MAX, 0, 0, 0, 0]).collect();
        init.push(0);
        rec.write_buffer(&self.stats_buf, 0, bytemuck::cast_slice(&init));
        let group = f.view_group(gpu, "iasm.analysis", &self.analysis_layout, &self.analysis_extra());
        rec.stage("iasm.importance", |enc| {
            gpu.dispatch_2d(enc, "iasm.importance", &self.analysis, &[&group], f.gbuffer.width, f.gbuffer.height)
        });
    }

    fn read_stats(&self, rec: &mut Recorder) -> TileStats {
        let t0 = std::time::Instant::now();
        let words: Vec<u32> = rec.read_buffer_as(&self.stats_buf, TILE_COUNT * 8 + 1, "iasm.readback");
        rec.cpu("iasm.readback", t0.elapsed().as_secs_f64() * 1e3);
        TileStats::parse(&words)
    }

    fn write_tiles(&self, rec: &mut Recorder) {
        for t in 0..TILE_COUNT {
            let tp = TileParams {
                view_proj: self.placement.tile_matrix(t, self.plan.near[t], self.plan.far[t]).to_cols_array_2d(),
                tile: [self.plan.res[t], self.plan.off[t], 0, 0],
            };
            rec.write_buffer(&self.tile_buf, t as u64 * TILE_STRIDE, bytemuck::bytes_of(&tp));
        }
        rec.write_buffer(&self.params_buf, 0, bytemuck::bytes_of(&self.params()));
    }

    /// The GPU's texel index and tile (equations 3.2-3.5 in eval.wgsl) of buffer coordinates
    /// `uvs` for resolutions `res` (offsets accumulated from them). For tests.
    pub fn probe_indices(&self, gpu: &Gpu, res: &[u32; TILE_COUNT], uvs: &[glam::Vec2]) -> Vec<(u32, u32)> {
        let mut params = self.params();
        params.res = *res;
        params.off = core::offsets(res);
        let ub = gpu.uniform("iasm.probe_params", &params);
        let data: Vec<[f32; 4]> = uvs.iter().map(|u| [u.x, u.y, 0.0, 0.0]).collect();
        let probe = gpu.buffer_init(
            "iasm.probe",
            bytemuck::cast_slice(&data),
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
        );
        let layout =
            binding::layout(&gpu.device, "iasm.probe", wgpu::ShaderStages::COMPUTE, &[binding::uniform(), binding::storage(false)]);
        let group = binding::group(&gpu.device, "iasm.probe", &layout, &[ub.as_entire_binding(), probe.as_entire_binding()]);
        let pipeline = gpu.compute_pipeline("iasm.probe", &probe_src(), "probe_index", &[&layout]);
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(0, &group, &[]);
            pass.dispatch_workgroups((uvs.len() as u32).div_ceil(64), 1, 1);
        }
        gpu.submit(enc.finish());
        let out: Vec<[f32; 4]> = gpu.read_buffer_as(&probe, uvs.len());
        out.iter().map(|v| (v[2].to_bits(), v[3].to_bits())).collect()
    }

    pub(super) fn eval_group(&self, gpu: &Gpu, f: &FrameInputs) -> wgpu::BindGroup {
        if let Some(a) = &self.atlas {
            let extra = [self.params_buf.as_entire_binding(), wgpu::BindingResource::TextureView(&a.view), self.counts.as_entire_binding()];
            return f.view_group(gpu, "iasm.eval", &a.eval_layout, &extra);
        }
        let extra = [self.params_buf.as_entire_binding(), self.shadow.as_entire_binding(), self.counts.as_entire_binding()];
        f.view_group(gpu, "iasm.eval", &self.eval_layout, &extra)
    }
}

impl Technique for Iasm {
    fn prepare(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        self.place(gpu, f, rec);
        self.current = self.placement;
        if self.delayed && self.pending {
            // the previous frame's analysis belongs to the previous frame's square: keep both
            // together, so every tile's planes and resolution describe that tile's region
            self.placement = self.analysed;
        } else {
            self.analyse(gpu, f, rec);
        }
        let stats = match self.delayed_read.take::<u32>(gpu, TILE_COUNT * 8 + 1).filter(|_| self.delayed && self.pending) {
            Some(words) => TileStats::parse(&words),
            // this frame's analysis (or, delayed, one whose frame has not finished): a sync
            None => self.read_stats(rec),
        };
        self.make_plan(stats);
        self.write_tiles(rec);
        self.evaluated = Some(self.params());
        Ok(())
    }

    fn render(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        if let Some(a) = &self.atlas {
            self.render_atlas(gpu, f, rec, a);
            return Ok(());
        }
        rec.stage("iasm.shadows.clear", |enc| enc.clear_buffer(&self.shadow, 0, None));
        for t in 0..TILE_COUNT {
            if self.plan.empty[t] {
                continue;
            }
            let r = self.plan.res[t];
            rec.stage(&format!("iasm.shadows.t{t:02}"), |enc| {
                let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("iasm.shadows"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: &self.dummy,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Discard },
                    })],
                    depth_stencil_attachment: None,
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                pass.set_pipeline(&self.render);
                pass.set_bind_group(0, &self.tile_groups[t], &[]);
                pass.set_bind_group(1, &f.scene.group, &[]);
                pass.set_viewport(0.0, 0.0, r as f32, r as f32, 0.0, 1.0);
                for &(a, b) in &self.plan.draws[t] {
                    pass.draw(a..b, 0..1);
                }
            });
        }
        Ok(())
    }

    fn evaluate(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        let group = self.eval_group(gpu, f);
        rec.stage("iasm.evaluate", |enc| {
            let pipeline = self.atlas.as_ref().map_or(&self.eval, |a| &a.eval);
            gpu.dispatch_2d(enc, "iasm.evaluate", pipeline, &[&group], f.gbuffer.width, f.gbuffer.height)
        });
        if self.delayed {
            // this frame's analysis, over this frame's square, feeds the next frame (thesis 4.3:
            // copied after the shadows)
            self.placement = self.current;
            self.analyse(gpu, f, rec);
            self.delayed_read.record(rec, &self.stats_buf);
            self.analysed = self.current;
            self.pending = true;
            if let Some(v) = self.fit.as_mut() {
                v.record_for_next(gpu, f, rec);
            }
        }
        Ok(())
    }

    /// The evaluation again with the view samples counted per texel. In delayed mode the tile
    /// planes the frame was evaluated with are the previous analysis's: they are still set
    /// (the next frame's are written in its `prepare`).
    fn analyze(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        if let Some(p) = self.evaluated {
            rec.write_buffer(&self.params_buf, 0, bytemuck::bytes_of(&p));
        }
        let group = self.eval_group(gpu, f);
        rec.stage("iasm.analysis", |enc| {
            enc.clear_buffer(&self.counts, 0, None);
            let pipeline = self.atlas.as_ref().map_or(&self.eval_count, |a| &a.eval_count);
            gpu.dispatch_2d(enc, "iasm.analysis", pipeline, &[&group], f.gbuffer.width, f.gbuffer.height)
        });
        Ok(())
    }

    fn report(&mut self, gpu: &Gpu) -> TechniqueReport {
        super::images::report(self, gpu)
    }
}

fn render_pipeline(gpu: &Gpu, layouts: &[&wgpu::BindGroupLayout]) -> wgpu::RenderPipeline {
    let module = gpu.shader("iasm.render", &compose_depth(RENDER_WGSL));
    let layout = gpu.pipeline_layout("iasm.render", layouts);
    gpu.device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("iasm.render"),
        layout: Some(&layout),
        vertex: wgpu::VertexState { module: &module, entry_point: Some("vs_main"), compilation_options: Default::default(), buffers: &[] },
        primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
        depth_stencil: None,
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs_main"),
            compilation_options: Default::default(),
            targets: &[Some(wgpu::ColorTargetState { format: DUMMY_FORMAT, blend: None, write_mask: wgpu::ColorWrites::empty() })],
        }),
        multiview_mask: None,
        cache: None,
    })
}
