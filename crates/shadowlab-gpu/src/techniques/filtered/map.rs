//! Making a [`Filtered`], in stages: the settings and the light checked into a [`Plan`] (plain
//! data: sizes, the uniform, the clear value, the format; errors are returned here), the
//! [`Targets`] it sizes (textures, the pre-filter and mip chain, buffers), then the pipelines of
//! render.rs and eval.rs.

use shadowlab_core::light::Light;
use shadowlab_core::lightspace;
use shadowlab_core::techniques::filtered as cpu;

use super::mips::{self, MipChain};
use super::{eval, render, Filtered, FilteredMap, FilteredParams, Kind, Representation};
use crate::blur::Blur;
use crate::scene_gpu::GpuScene;
use crate::{raster, Gpu, GpuError};

impl Filtered {
    pub fn new(gpu: &Gpu, scene: &GpuScene, settings: &FilteredMap, rep: Representation, light: &Light) -> Result<Filtered, GpuError> {
        let plan = Plan::new(gpu, scene, settings, rep, light)?;
        let t = Targets::new(gpu, &plan)?;
        let (render_pipeline, render_group) = render::pipeline(gpu, scene, plan.kind.name(), plan.format, &t.uniform);
        let (eval_layout, eval, sampler) = eval::pipelines(gpu, plan.kind.name(), &plan.params);
        Ok(Filtered {
            groups: Default::default(),
            kind: plan.kind,
            sd: plan.sd,
            res: plan.res,
            params: plan.params,
            map_view: t.map.create_view(&Default::default()),
            map: t.map,
            depth: t.depth,
            clear: plan.clear,
            blur_width: if t.blur.is_some() { plan.blur_width } else { 1 },
            blur: t.blur,
            mips: t.mips,
            counts: t.counts,
            uniform: t.uniform,
            render_pipeline,
            render_group,
            eval,
            eval_layout,
            sampler,
        })
    }
}

/// What one filterable map needs, checked: no GPU object yet.
struct Plan {
    kind: Kind,
    sd: bool,
    res: u32,
    /// Mip levels of the map (1: no chain).
    levels: u32,
    /// The kernel width asked for (odd; 1 = none).
    blur_width: u32,
    params: FilteredParams,
    /// The map's clear value: b(1), the farthest depth.
    clear: wgpu::Color,
    format: wgpu::TextureFormat,
}

impl Plan {
    /// Errors: a map over the device's texture size, an even kernel width, a point light.
    fn new(gpu: &Gpu, scene: &GpuScene, settings: &FilteredMap, rep: Representation, light: &Light) -> Result<Plan, GpuError> {
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
        let shape = Shape::of(rep);
        let params = uniform(&lp, settings, &shape, kind, levels, inv_far);
        let format = match if sd { 1 } else { kind.channels() } {
            1 => wgpu::TextureFormat::R32Float,
            2 => wgpu::TextureFormat::Rg32Float,
            _ => wgpu::TextureFormat::Rgba32Float,
        };
        Ok(Plan { kind, sd, res, levels, blur_width, params, clear: clear_value(sd, kind, &shape), format })
    }
}

/// Every representation's shape parameters, 0 where the kind has none (the shaders read no
/// slot left at 0).
struct Shape {
    min_variance: f64,
    c: f64,
    c_pos: f64,
    c_neg: f64,
    moment_bias: f64,
}

impl Shape {
    fn of(rep: Representation) -> Shape {
        let (min_variance, c, c_pos, c_neg, moment_bias) = match rep {
            Representation::Vsm { min_variance } => (min_variance, 0.0, 0.0, 0.0, 0.0),
            Representation::Esm { c } => (0.0, c, 0.0, 0.0, 0.0),
            Representation::Evsm { min_variance, c_pos, c_neg } => (min_variance, 0.0, c_pos, c_neg, 0.0),
            Representation::Msm { moment_bias } => (0.0, 0.0, 0.0, 0.0, moment_bias),
        };
        Shape { min_variance, c, c_pos, c_neg, moment_bias }
    }
}

fn uniform(lp: &lightspace::LightProjection, settings: &FilteredMap, s: &Shape, kind: Kind, levels: u32, inv_far: f32) -> FilteredParams {
    FilteredParams {
        light_view_proj: lp.view_proj.to_cols_array_2d(),
        texel_world: lp.texel,
        perspective: lp.perspective as u32 as f32,
        res: settings.res as f32,
        inv_far,
        kind: kind as u32,
        single_depth: settings.sd as u32,
        mip_levels: levels,
        pad0: 0,
        min_variance: s.min_variance as f32,
        esm_c: s.c as f32,
        evsm_c_pos: s.c_pos as f32,
        evsm_c_neg: s.c_neg as f32,
        moment_bias: s.moment_bias as f32,
        depth_bias: settings.bias as f32,
        normal_offset: settings.normal_offset as f32,
        pad1: 0.0,
    }
}

/// b(1), the representation of the farthest depth (sd: the depth itself).
fn clear_value(sd: bool, kind: Kind, s: &Shape) -> wgpu::Color {
    let far: [f64; 4] = match (sd, kind) {
        (true, _) => [1.0, 0.0, 0.0, 0.0],
        (_, Kind::Vsm) => [1.0, 1.0, 0.0, 0.0],
        (_, Kind::Esm) => [cpu::esm_moment(1.0, s.c), 0.0, 0.0, 0.0],
        (_, Kind::Evsm) => cpu::evsm_moments(1.0, s.c_pos, s.c_neg),
        (_, Kind::Msm) => cpu::msm_moments(1.0),
    };
    wgpu::Color { r: far[0], g: far[1], b: far[2], a: far[3] }
}

/// The map and its raster depth, the pre-filter and mip chain over it, the uniform and the
/// sample counts.
struct Targets {
    map: wgpu::Texture,
    depth: wgpu::Texture,
    blur: Option<Blur>,
    mips: Option<MipChain>,
    uniform: wgpu::Buffer,
    counts: wgpu::Buffer,
}

impl Targets {
    fn new(gpu: &Gpu, plan: &Plan) -> Result<Targets, GpuError> {
        let (name, res) = (plan.kind.name(), plan.res);
        let texture = |label: &str, format, usage, mip_level_count| {
            gpu.device.create_texture(&wgpu::TextureDescriptor {
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
        let map_usage = U::RENDER_ATTACHMENT | U::TEXTURE_BINDING | U::STORAGE_BINDING | U::COPY_SRC;
        let map = texture(&format!("{name}.map"), plan.format, map_usage, plan.levels);
        let depth = texture(&format!("{name}.depth"), raster::DEPTH_FORMAT, U::RENDER_ATTACHMENT, 1);
        let blur_width = plan.blur_width;
        let blur = if blur_width > 1 && !plan.sd { Some(Blur::new(gpu, &format!("{name}.blur"), &map, blur_width)?) } else { None };
        let mips = if plan.levels > 1 { Some(MipChain::new(gpu, &format!("{name}.mips"), &map)?) } else { None };
        let uniform = gpu.uniform(&format!("{name}.params"), &plan.params);
        let counts = gpu.storage(&format!("{name}.counts"), res as u64 * res as u64 * 4);
        Ok(Targets { map, depth, blur, mips, uniform, counts })
    }
}
