//! The passes of leak tracing: static/dynamic map raster, classification with ray-list
//! compaction, indirect list tracing; the screen-sized state (temporal mask and history, ping-pong).

use bytemuck::Zeroable;
use shadowlab_core::light::Light;
use shadowlab_core::lightspace;
use shadowlab_core::techniques::lt as leak;

use super::cascade::{single_level, Cascades};
use super::screen::Screen;
use super::{classify_source, trace_source, LevelU, LtParams, Mode, TraceParams, Variant, ARGS_WGSL, MAX_MAPS};
use super::{FLAG_DYNAMIC, FLAG_FORCE_ALL, FLAG_FULL, FLAG_HAS_HISTORY, FLAG_HISTORY_TEST, FLAG_POINT, FLAG_RR};
use crate::record::Recorder;
use crate::scene_gpu::GpuScene;
use crate::technique::{view_layout, FrameInputs, Technique, TechniqueReport};
use crate::techniques::filtered::{render_source, FilteredParams};
use crate::{binding, raster, Gpu, GpuError};

/// Lights per technique instance (the lab runs one instance per light).
const LIGHTS: usize = 1;

pub struct LeakTracing {
    pub(super) mode: Mode,
    pub(super) res: u32,
    reuse: bool,
    pub(super) params: LtParams,
    pub(super) mask_bits: u32,
    /// One layer per hybrid level.
    pub(super) static_map: wgpu::Texture,
    pub(super) dynamic_map: Option<wgpu::Texture>,
    depth: wgpu::Texture,
    pub(super) levels: usize,
    pub(super) cascades: Option<Cascades>,
    /// Layer renders of the static map, of the dynamic map.
    pub(super) static_renders: u32,
    pub(super) dynamic_renders: u32,
    static_dirty: Vec<bool>,
    map_params: FilteredParams,
    /// Per level: the raster's `FilteredParams` and its bind group.
    map_uniforms: Vec<(wgpu::Buffer, wgpu::BindGroup)>,
    render_pipeline: wgpu::RenderPipeline,
    classify_pipeline: wgpu::ComputePipeline,
    classify_layout: wgpu::BindGroupLayout,
    trace_pipeline: wgpu::ComputePipeline,
    trace_layout: wgpu::BindGroupLayout,
    args_pipeline: wgpu::ComputePipeline,
    args_layout: wgpu::BindGroupLayout,
    uniform: wgpu::Buffer,
    sampler: wgpu::Sampler,
    pub(super) screen: Option<Screen>,
}

impl LeakTracing {
    pub fn new(gpu: &Gpu, scene: &GpuScene, variant: &Variant, light: &Light) -> Result<LeakTracing, GpuError> {
        let mode = variant.mode();
        let name = mode.name();
        // what each mode declares (mod.rs): lt all; ltt no temporal mask (rr, full,
        // history_test, depth_tol, normal_cos); hybrid-pcf no filterable base (base, eps, the
        // moment shape) but the PCF bias. The shader reads no slot a mode leaves at 0.
        let (map_levels, reuse, force_all) = match variant {
            Variant::Lt(s) => (&s.map, s.reuse, s.force_all),
            Variant::Ltt(s) => (&s.map, s.reuse, s.force_all),
            Variant::HybridPcf(s) => (&s.map, s.reuse, s.force_all),
        };
        let filterable = match variant {
            Variant::Lt(s) => Some((s.base, s.eps, &s.moments)),
            Variant::Ltt(s) => Some((s.base, s.eps, &s.moments)),
            Variant::HybridPcf(_) => None,
        };
        let temporal = match variant {
            Variant::Lt(s) => Some(s),
            _ => None,
        };
        let res = map_levels.res;
        gpu.check_size(res, res, "shadow map")?;
        // point: six cube faces, one layer each (level 0 = the +x face stands for all below)
        let faces = match *light {
            Light::Point { position } => Some(leak::cube_faces(position, &scene.bounds, res)),
            _ => None,
        };
        let lp = match &faces {
            Some(f) => f[0],
            None => lightspace::fit(light, &scene.bounds, res)
                .ok_or_else(|| GpuError::Invalid(format!("{name}: unsupported light ({})", light.kind())))?,
        };
        let inv_far = match *light {
            Light::Spot { position, .. } | Light::Point { position } => {
                let far = scene.bounds.corners().iter().map(|c| (*c - position).length()).fold(0.0f32, f32::max);
                1.0 / far.max(1e-6)
            }
            _ => 0.0,
        };
        let mask_bits = leak::mask_texel_bits(LIGHTS).map_err(GpuError::Invalid)?;
        let flag = |on: bool, bit: u32| if on { bit } else { 0 };
        let flags = temporal.map_or(0, |t| flag(t.rr, FLAG_RR) | flag(t.full, FLAG_FULL) | flag(t.history_test, FLAG_HISTORY_TEST))
            | flag(force_all, FLAG_FORCE_ALL)
            | flag(faces.is_some(), FLAG_POINT);
        let (bias, normal_offset) = match variant {
            Variant::HybridPcf(s) => (s.bias, s.normal_offset),
            _ => (0.0, 0.0),
        };
        let (min_variance, esm_c, evsm_c_pos, evsm_c_neg, moment_bias) = filterable.map_or((0.0, 0.0, 0.0, 0.0, 0.0), |(_, _, m)| {
            (m.min_variance as f32, m.c as f32, m.c_pos as f32, m.c_neg as f32, m.moment_bias as f32)
        });
        let base = filterable.map_or(0, |(base, _, _)| base.index() as u32);
        let eps = filterable.map_or(0.0, |(_, eps, _)| eps as f32);
        let (depth_tol, normal_cos) = temporal.map_or((0.0, 0.0), |t| (t.depth_tol as f32, t.normal_cos as f32));
        let cascades = match *light {
            Light::Directional { direction } if map_levels.cascades > 1 => Some(Cascades {
                count: map_levels.cascades as usize,
                lambda: map_levels.lambda as f32,
                enlarge: map_levels.enlarge as f32,
                dir: direction,
                kept: vec![None; map_levels.cascades as usize - 1],
            }),
            _ => None,
        };
        let levels = if faces.is_some() { 6 } else { cascades.as_ref().map_or(1, |c| c.levels()) };
        let mut level_u = [LevelU::zeroed(); MAX_MAPS];
        level_u[0] = single_level(lp.view_proj, lp.texel);
        for (l, f) in faces.iter().flatten().enumerate() {
            level_u[l] = single_level(f.view_proj, f.texel);
        }
        let params = LtParams {
            levels: level_u,
            layers: levels as f32,
            perspective: lp.perspective as u32 as f32,
            res: res as f32,
            inv_far,
            technique: mode as u32,
            base,
            frame: 0,
            flags,
            min_variance,
            esm_c,
            evsm_c_pos,
            evsm_c_neg,
            moment_bias,
            depth_bias: bias as f32,
            normal_offset: normal_offset as f32,
            eps,
            depth_tol,
            normal_cos,
            mask_bits: mask_bits as f32,
            pad0: 0.0,
        };
        // the raster of filtered/ in single-depth mode: linear depth into an R32Float target
        let map_params = FilteredParams {
            light_view_proj: lp.view_proj.to_cols_array_2d(),
            texel_world: lp.texel,
            perspective: lp.perspective as u32 as f32,
            res: res as f32,
            inv_far,
            kind: 0,
            single_depth: 1,
            mip_levels: 1,
            min_variance,
            esm_c,
            evsm_c_pos,
            evsm_c_neg,
            ..FilteredParams::zeroed()
        };
        let d = &gpu.device;
        use wgpu::TextureUsages as U;
        let map = |label: &str| {
            d.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d { width: res, height: res, depth_or_array_layers: levels as u32 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::R32Float,
                usage: U::RENDER_ATTACHMENT | U::TEXTURE_BINDING | U::COPY_SRC,
                view_formats: &[],
            })
        };
        let static_map = map(&format!("{name}.static_map"));
        let dynamic_map = (scene.dynamic_first < scene.triangle_count).then(|| map(&format!("{name}.dynamic_map")));
        let depth = raster::render_target(gpu, &format!("{name}.raster_depth"), res, res, raster::DEPTH_FORMAT, U::empty());
        let render_layout = binding::layout(d, name, wgpu::ShaderStages::VERTEX_FRAGMENT, &[binding::uniform()]);
        let map_uniforms = (0..levels)
            .map(|l| {
                let mut mp = map_params;
                mp.light_view_proj = level_u[l].view_proj;
                let u = gpu.uniform(&format!("{name}.map_params"), &mp);
                let g = binding::group(d, name, &render_layout, &[u.as_entire_binding()]);
                (u, g)
            })
            .collect();
        let target = wgpu::ColorTargetState { format: wgpu::TextureFormat::R32Float, blend: None, write_mask: wgpu::ColorWrites::ALL };
        let render_pipeline =
            raster::scene_pipeline(gpu, &format!("{name}.render"), &render_source(), &[&render_layout, &scene.layout], &[Some(target)]);
        let nf = wgpu::BindingType::Sampler(wgpu::SamplerBindingType::NonFiltering);
        let (ro, rw, tex) = (binding::storage(true), binding::storage(false), binding::texture_float());
        let arr = wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: false },
            view_dimension: wgpu::TextureViewDimension::D2Array,
            multisampled: false,
        };
        let classify_layout = view_layout(gpu, &format!("{name}.classify"), &[binding::uniform(), arr, arr, nf, tex, ro, rw, ro, rw, rw]);
        let classify_pipeline = gpu.compute_pipeline(&format!("{name}.classify"), &classify_source(), "main", &[&classify_layout]);
        let trace_layout = view_layout(gpu, &format!("{name}.trace"), &[binding::uniform(), ro, rw]);
        let trace_pipeline = gpu.compute_pipeline(&format!("{name}.trace"), &trace_source(), "main", &[&trace_layout, &scene.layout]);
        let args_layout = binding::layout(d, &format!("{name}.args"), wgpu::ShaderStages::COMPUTE, &[binding::uniform(), ro, rw]);
        let args_pipeline = gpu.compute_pipeline(&format!("{name}.args"), ARGS_WGSL, "main", &[&args_layout]);
        let sampler = d.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("lt.gather"),
            address_mode_u: wgpu::AddressMode::ClampToEdge,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            ..Default::default()
        });
        let uniform = gpu.uniform(&format!("{name}.params"), &params);
        Ok(LeakTracing {
            mode,
            res,
            reuse,
            params,
            mask_bits,
            static_map,
            dynamic_map,
            depth,
            levels,
            cascades,
            static_renders: 0,
            dynamic_renders: 0,
            static_dirty: vec![true; levels],
            map_params,
            map_uniforms,
            render_pipeline,
            classify_pipeline,
            classify_layout,
            trace_pipeline,
            trace_layout,
            args_pipeline,
            args_layout,
            uniform,
            sampler,
            screen: None,
        })
    }

    #[allow(clippy::too_many_arguments)]
    fn draw(
        &self,
        enc: &mut wgpu::CommandEncoder,
        label: &str,
        f: &FrameInputs,
        target: &wgpu::Texture,
        layer: usize,
        tris: std::ops::Range<u32>,
    ) {
        let view = target.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2),
            base_array_layer: layer as u32,
            array_layer_count: Some(1),
            ..Default::default()
        });
        let depth_view = self.depth.create_view(&Default::default());
        // cleared to the farthest depth where nothing is drawn
        let mut pass = raster::begin_pass_with(enc, label, &[&view], wgpu::Color::WHITE, &depth_view, wgpu::StoreOp::Discard);
        pass.set_pipeline(&self.render_pipeline);
        pass.set_bind_group(0, &self.map_uniforms[layer].1, &[]);
        pass.set_bind_group(1, &f.scene.group, &[]);
        pass.draw(tris.start * 3..tris.end * 3, 0..1);
    }

    fn screen(&mut self, gpu: &Gpu, w: u32, h: u32) -> &mut Screen {
        if !matches!(&self.screen, Some(s) if s.width == w && s.height == h) {
            self.screen = Some(Screen::new(gpu, self.mode.name(), w, h, self.mask_bits));
        }
        self.screen.as_mut().expect("allocated above")
    }

    /// The pixels listed for rays in the last frame (in list order).
    pub fn ray_list(&self, gpu: &Gpu) -> Vec<u32> {
        let Some(s) = &self.screen else { return Vec::new() };
        let words: Vec<u32> = gpu.read_buffer_as(&s.list, (s.width * s.height + 1) as usize);
        words[1..1 + words[0] as usize].to_vec()
    }

    /// Layer 0 of the static map and of the dynamic map (linear light depth, `res`^2 texels),
    /// as last rendered.
    pub fn maps(&self, gpu: &Gpu) -> (Vec<f32>, Option<Vec<f32>>) {
        let read = |t: &wgpu::Texture| bytemuck::pod_collect_to_vec(&gpu.read_texture(t, 4));
        (read(&self.static_map), self.dynamic_map.as_ref().map(read))
    }

    /// The temporal mask written in the last frame: 3 bits per pixel (`shadowlab_core::techniques::lt`).
    pub fn mask(&self, gpu: &Gpu) -> Vec<u32> {
        let Some(s) = &self.screen else { return Vec::new() };
        let n = (s.width * s.height) as usize;
        let per = (32 / self.mask_bits) as usize;
        let words: Vec<u32> = gpu.read_buffer_as(&s.masks[((s.frames + 1) % 2) as usize], n.div_ceil(per));
        (0..n).map(|i| (words[i / per] >> ((i % per) as u32 * self.mask_bits)) & 7).collect()
    }
}

impl Technique for LeakTracing {
    /// Cascades: fit this frame's slices, keep or replace each level's box (section 3.3).
    fn prepare(&mut self, _gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        let t0 = std::time::Instant::now();
        if let Some(c) = self.cascades.as_mut() {
            let dirty = c.update(f, self.res, self.reuse, &mut self.params)?;
            for (l, d) in dirty.into_iter().enumerate() {
                if d {
                    self.map_params.light_view_proj = self.params.levels[l].view_proj;
                    self.map_params.texel_world = self.params.levels[l].info[0];
                    rec.write_buffer(&self.map_uniforms[l].0, 0, bytemuck::bytes_of(&self.map_params));
                    self.static_dirty[l] = true;
                }
            }
            rec.cpu(&format!("{}.fit", self.mode.name()), t0.elapsed().as_secs_f64() * 1e3);
        } else if !self.reuse {
            self.static_dirty.iter_mut().for_each(|d| *d = true);
        }
        Ok(())
    }

    fn render(&mut self, _gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        let name = self.mode.name();
        let label = format!("{name}.render");
        let dynamic = (f.scene.dynamic_first < f.scene.triangle_count).then_some(f.scene.dynamic_first..f.scene.triangle_count);
        if dynamic.is_some() && self.dynamic_map.is_none() {
            return Err(GpuError::Invalid(format!("{name}: the scene gained dynamic triangles after creation")));
        }
        let redraw: Vec<usize> = (0..self.levels).filter(|l| self.static_dirty[*l]).collect();
        if redraw.is_empty() && dynamic.is_none() {
            return Ok(());
        }
        rec.stage(&label, |enc| {
            for &l in &redraw {
                self.draw(enc, &label, f, &self.static_map, l, 0..f.scene.dynamic_first);
            }
            if let (Some(range), Some(map)) = (&dynamic, &self.dynamic_map) {
                for l in 0..self.levels {
                    self.draw(enc, &label, f, map, l, range.clone());
                }
            }
        });
        self.static_renders += redraw.len() as u32;
        self.dynamic_renders += if dynamic.is_some() { self.levels as u32 } else { 0 };
        self.static_dirty.iter_mut().for_each(|d| *d = false);
        Ok(())
    }

    fn evaluate(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        let name = self.mode.name();
        let (w, h) = (f.gbuffer.width, f.gbuffer.height);
        let has_dynamic = self.dynamic_map.is_some() && f.scene.dynamic_first < f.scene.triangle_count;
        let frames = self.screen(gpu, w, h).frames;
        let mut params = self.params;
        params.frame = frames;
        params.flags |= if frames > 0 { FLAG_HAS_HISTORY } else { 0 } | if has_dynamic { FLAG_DYNAMIC } else { 0 };
        rec.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&params));
        let trace = gpu.uniform(&format!("{name}.trace_params"), &TraceParams { cfg: [self.mask_bits, w * h, 0, 0] });
        let s = self.screen.as_ref().expect("allocated above");
        let (cur, prev) = ((frames % 2) as usize, ((frames + 1) % 2) as usize);
        let array = wgpu::TextureViewDescriptor { dimension: Some(wgpu::TextureViewDimension::D2Array), ..Default::default() };
        let static_view = self.static_map.create_view(&array);
        let dynamic_view = self.dynamic_map.as_ref().unwrap_or(&self.static_map).create_view(&array);
        let motion_view = f.gbuffer.motion.create_view(&Default::default());
        use wgpu::BindingResource as R;
        let classify = f.view_group(
            gpu,
            &format!("{name}.classify"),
            &self.classify_layout,
            &[
                self.uniform.as_entire_binding(),
                R::TextureView(&static_view),
                R::TextureView(&dynamic_view),
                R::Sampler(&self.sampler),
                R::TextureView(&motion_view),
                s.masks[prev].as_entire_binding(),
                s.masks[cur].as_entire_binding(),
                s.history[prev].as_entire_binding(),
                s.history[cur].as_entire_binding(),
                s.list.as_entire_binding(),
            ],
        );
        let trace_group = f.view_group(
            gpu,
            &format!("{name}.trace"),
            &self.trace_layout,
            &[trace.as_entire_binding(), s.list.as_entire_binding(), s.masks[cur].as_entire_binding()],
        );
        let args_group = binding::group(
            &gpu.device,
            &format!("{name}.args"),
            &self.args_layout,
            &[trace.as_entire_binding(), s.list.as_entire_binding(), s.args.as_entire_binding()],
        );
        let label = format!("{name}.classify");
        rec.stage(&label, |enc| {
            enc.clear_buffer(&s.masks[cur], 0, None);
            enc.clear_buffer(&s.list, 0, Some(4));
            gpu.dispatch_2d(enc, &label, &self.classify_pipeline, &[&classify], w, h);
        });
        let label = format!("{name}.trace");
        rec.stage(&label, |enc| {
            {
                let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(&label), timestamp_writes: None });
                pass.set_pipeline(&self.args_pipeline);
                pass.set_bind_group(0, &args_group, &[]);
                pass.dispatch_workgroups(1, 1, 1);
            }
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(&label), timestamp_writes: None });
            pass.set_pipeline(&self.trace_pipeline);
            pass.set_bind_group(0, &trace_group, &[]);
            pass.set_bind_group(1, &f.scene.group, &[]);
            pass.dispatch_workgroups_indirect(&s.args, 0);
        });
        self.screen.as_mut().expect("allocated above").frames += 1;
        Ok(())
    }

    fn report(&mut self, gpu: &Gpu) -> TechniqueReport {
        super::report::report(self, gpu)
    }
}
