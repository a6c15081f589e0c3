//! The passes of the filterable maps: moments raster, blur, evaluation, report.

use shadowlab_core::light::Light;
use shadowlab_core::lightspace;
use shadowlab_core::metrics::sampling_stats;
use shadowlab_core::techniques::filtered as cpu;

use super::mips::{self, MipChain};
use super::{eval_source, render_source, FilteredMap, FilteredParams, Kind};
use crate::blur::{mip0, Blur};
use crate::record::Recorder;
use crate::scene_gpu::GpuScene;
use crate::technique::{view_layout, FrameInputs, Technique, TechniqueReport};
use crate::techniques::pictures::{count_image, depth_image};
use crate::{binding, raster, Gpu, GpuError};

/// The representation with the shape parameters its technique declares (mod.rs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Representation {
    Vsm { min_variance: f64 },
    Esm { c: f64 },
    Evsm { min_variance: f64, c_pos: f64, c_neg: f64 },
    Msm { moment_bias: f64 },
}

impl Representation {
    pub fn kind(self) -> Kind {
        match self {
            Representation::Vsm { .. } => Kind::Vsm,
            Representation::Esm { .. } => Kind::Esm,
            Representation::Evsm { .. } => Kind::Evsm,
            Representation::Msm { .. } => Kind::Msm,
        }
    }
}

pub struct Filtered {
    kind: Kind,
    sd: bool,
    res: u32,
    params: FilteredParams,
    map: wgpu::Texture,
    depth: wgpu::Texture,
    clear: wgpu::Color,
    blur: Option<Blur>,
    /// Effective kernel width (1 with sd).
    blur_width: u32,
    mips: Option<MipChain>,
    counts: wgpu::Buffer,
    uniform: wgpu::Buffer,
    render_pipeline: wgpu::RenderPipeline,
    render_group: wgpu::BindGroup,
    /// The evaluation and its analysis variant.
    eval: crate::technique::EvalPipelines,
    eval_layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
}

impl Filtered {
    pub fn new(gpu: &Gpu, scene: &GpuScene, settings: &FilteredMap, rep: Representation, light: &Light) -> Result<Filtered, GpuError> {
        let kind = rep.kind();
        let name = kind.name();
        let res = settings.res;
        gpu.check_size(res, res, "shadow map")?;
        let sd = settings.sd;
        let levels = if settings.mips && !sd { mips::levels(res) } else { 1 };
        let blur_width = settings.blur;
        if blur_width.is_multiple_of(2) {
            return Err(GpuError::Invalid(format!("{name}: blur={blur_width} must be odd (1 = no blur)")));
        }
        let lp = lightspace::fit(light, &scene.bounds, res)
            .ok_or_else(|| GpuError::Invalid(format!("{name} does not support point lights (no cube maps)")))?;
        let inv_far = match *light {
            Light::Spot { position, .. } => {
                let far = scene.bounds.corners().iter().map(|c| (*c - position).length()).fold(0.0f32, f32::max);
                1.0 / far.max(1e-6)
            }
            _ => 0.0,
        };
        // each kind has what it declares (mod.rs); the shaders read no slot left at 0
        let (min_variance, c, c_pos, c_neg, moment_bias) = match rep {
            Representation::Vsm { min_variance } => (min_variance, 0.0, 0.0, 0.0, 0.0),
            Representation::Esm { c } => (0.0, c, 0.0, 0.0, 0.0),
            Representation::Evsm { min_variance, c_pos, c_neg } => (min_variance, 0.0, c_pos, c_neg, 0.0),
            Representation::Msm { moment_bias } => (0.0, 0.0, 0.0, 0.0, moment_bias),
        };
        let params = FilteredParams {
            light_view_proj: lp.view_proj.to_cols_array_2d(),
            texel_world: lp.texel,
            perspective: lp.perspective as u32 as f32,
            res: res as f32,
            inv_far,
            kind: kind as u32,
            single_depth: sd as u32,
            mip_levels: levels,
            pad0: 0,
            min_variance: min_variance as f32,
            esm_c: c as f32,
            evsm_c_pos: c_pos as f32,
            evsm_c_neg: c_neg as f32,
            moment_bias: moment_bias as f32,
            depth_bias: settings.bias as f32,
            normal_offset: settings.normal_offset as f32,
            pad1: 0.0,
        };
        // the map's clear value: b(1), the farthest depth
        let far: [f64; 4] = match (sd, kind) {
            (true, _) => [1.0, 0.0, 0.0, 0.0],
            (_, Kind::Vsm) => [1.0, 1.0, 0.0, 0.0],
            (_, Kind::Esm) => [cpu::esm_moment(1.0, c), 0.0, 0.0, 0.0],
            (_, Kind::Evsm) => cpu::evsm_moments(1.0, c_pos, c_neg),
            (_, Kind::Msm) => cpu::msm_moments(1.0),
        };
        let clear = wgpu::Color { r: far[0], g: far[1], b: far[2], a: far[3] };
        let format = match if sd { 1 } else { kind.channels() } {
            1 => wgpu::TextureFormat::R32Float,
            2 => wgpu::TextureFormat::Rg32Float,
            _ => wgpu::TextureFormat::Rgba32Float,
        };
        let d = &gpu.device;
        let texture = |label: &str, format, usage, mip_level_count| {
            d.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d { width: res, height: res, depth_or_array_layers: 1 },
                mip_level_count,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        use wgpu::TextureUsages as U;
        let map =
            texture(&format!("{name}.map"), format, U::RENDER_ATTACHMENT | U::TEXTURE_BINDING | U::STORAGE_BINDING | U::COPY_SRC, levels);
        let depth = texture(&format!("{name}.depth"), raster::DEPTH_FORMAT, U::RENDER_ATTACHMENT, 1);
        let blur = if blur_width > 1 && !sd { Some(Blur::new(gpu, &format!("{name}.blur"), &map, blur_width)?) } else { None };
        let mips = if levels > 1 { Some(MipChain::new(gpu, &format!("{name}.mips"), &map)?) } else { None };
        let uniform = gpu.uniform(&format!("{name}.params"), &params);
        let render_layout = binding::layout(d, name, wgpu::ShaderStages::VERTEX_FRAGMENT, &[binding::uniform()]);
        let render_group = binding::group(d, name, &render_layout, &[uniform.as_entire_binding()]);
        let target = wgpu::ColorTargetState { format, blend: None, write_mask: wgpu::ColorWrites::ALL };
        let render_pipeline =
            raster::scene_pipeline(gpu, &format!("{name}.render"), &render_source(), &[&render_layout, &scene.layout], &[Some(target)]);
        let sampler_type = wgpu::BindingType::Sampler(wgpu::SamplerBindingType::NonFiltering);
        let eval_layout = view_layout(
            gpu,
            &format!("{name}.eval"),
            &[binding::uniform(), binding::texture_float(), sampler_type, binding::storage(false)],
        );
        let eval = crate::technique::EvalPipelines::new(gpu, &format!("{name}.evaluate"), &eval_source(), &eval_layout, &[]);
        let sampler = d.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("filtered.gather"),
            address_mode_u: wgpu::AddressMode::ClampToEdge,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            ..Default::default()
        });
        let counts = gpu.storage(&format!("{name}.counts"), res as u64 * res as u64 * 4);
        Ok(Filtered {
            kind,
            sd,
            res,
            params,
            map,
            depth,
            clear,
            blur_width: if blur.is_some() { blur_width } else { 1 },
            blur,
            mips,
            counts,
            uniform,
            render_pipeline,
            render_group,
            eval,
            eval_layout,
            sampler,
        })
    }

    fn bytes_per_texel(&self) -> u64 {
        self.map.format().block_copy_size(None).unwrap_or(16) as u64
    }

    /// Linear depth per texel recovered from the first channel (for the report picture).
    fn first_moment_as_depth(&self, texels: &[f32]) -> Vec<f32> {
        let ch = (self.bytes_per_texel() / 4) as usize;
        let (c, cp) = (self.params.esm_c, self.params.evsm_c_pos);
        texels
            .chunks(ch)
            .map(|t| match (self.sd, self.kind) {
                (false, Kind::Esm) => t[0].ln() / c,
                (false, Kind::Evsm) => (t[0].ln() / cp + 1.0) * 0.5,
                _ => t[0],
            })
            .collect()
    }
}

impl Technique for Filtered {
    fn render(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        let name = self.kind.name();
        let map_view = mip0(&self.map);
        let depth_view = self.depth.create_view(&Default::default());
        rec.stage(&format!("{name}.render"), |enc| {
            let label = format!("{name}.render");
            let mut pass = raster::begin_pass_with(enc, &label, &[&map_view], self.clear, &depth_view, wgpu::StoreOp::Discard);
            pass.set_pipeline(&self.render_pipeline);
            pass.set_bind_group(0, &self.render_group, &[]);
            pass.set_bind_group(1, &f.scene.group, &[]);
            pass.draw(0..f.scene.triangle_count * 3, 0..1);
        });
        if let Some(blur) = &self.blur {
            let label = format!("{name}.blur");
            rec.stage(&label, |enc| blur.record(gpu, enc, &label));
        }
        if let Some(m) = &self.mips {
            let label = format!("{name}.mips");
            rec.stage(&label, |enc| m.record(gpu, enc, &label));
        }
        Ok(())
    }

    fn evaluate(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        self.eval_pass(gpu, f, rec, false)
    }

    fn analyze(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        self.eval_pass(gpu, f, rec, true)
    }

    fn report(&mut self, gpu: &Gpu) -> TechniqueReport {
        let n = (self.res * self.res) as usize;
        let bpt = self.bytes_per_texel();
        let counts: Vec<u32> = gpu.read_buffer_as(&self.counts, n);
        let texels: Vec<f32> = bytemuck::pod_collect_to_vec(&gpu.read_texture(&self.map, bpt as u32));
        let depth = self.first_moment_as_depth(&texels);
        let levels = self.map.mip_level_count();
        let bytes = if levels > 1 { mips::chain_bytes(self.res, bpt) } else { n as u64 * bpt };
        let mut r = TechniqueReport { shadow_data_bytes: bytes, sampling: Some(sampling_stats(&counts)), ..Default::default() };
        let c = &mut r.counters;
        // texels read per evaluated pixel: 2x2 (4 loads, or one gather of 4 depths); trilinear:
        // 2x2 on two levels (plus 4 G-buffer positions of the neighbours for the footprint)
        let texels = if levels > 1 { 8.0 } else { 4.0 };
        c.insert("fetches_per_pixel".into(), texels);
        c.insert("texture_instructions_per_pixel".into(), if self.sd { 1.0 } else { texels });
        c.insert("bytes_read_per_pixel".into(), texels * bpt as f64);
        c.insert("mip_levels".into(), levels as f64);
        c.insert("bytes_per_texel".into(), bpt as f64);
        c.insert("shadow_map_texels".into(), n as f64);
        c.insert("blur_width".into(), self.blur_width as f64);
        // transient targets kept allocated between frames (not read by the evaluation)
        c.insert("raster_depth_bytes".into(), n as f64 * 4.0);
        c.insert("blur_scratch_bytes".into(), self.blur.as_ref().map_or(0.0, |b| b.scratch_bytes() as f64));
        let what = if self.sd { "shadow map (linear depth)" } else { "moment map (first moment as depth)" };
        r.images.push(depth_image(what, self.res, &depth));
        r.images.push(count_image("view samples per texel", self.res, &counts));
        r
    }
}

impl Filtered {
    /// The evaluation; with `counting` the lab's analysis variant (view samples per texel).
    fn eval_pass(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder, counting: bool) -> Result<(), GpuError> {
        let name = self.kind.name();
        let map_view = self.map.create_view(&Default::default());
        let group = f.view_group(
            gpu,
            &format!("{name}.eval"),
            &self.eval_layout,
            &[
                self.uniform.as_entire_binding(),
                wgpu::BindingResource::TextureView(&map_view),
                wgpu::BindingResource::Sampler(&self.sampler),
                self.counts.as_entire_binding(),
            ],
        );
        let label = format!("{name}.evaluate");
        self.eval.record(gpu, rec, &label, &self.counts, &group, f.gbuffer.width, f.gbuffer.height, counting);
        Ok(())
    }
}
