//! `sm`: baseline shadow mapping (Williams 1978) for directional (orthographic, fitted to the
//! scene bounds) and spot (perspective) lights, with constant, slope-scaled and normal-offset
//! bias in units of one shadow texel, and NxN PCF through hardware comparison sampling.
//! Stored depth: post-projective, 0 = near the light (orthographic: linear).

use bytemuck::{Pod, Zeroable};
use shadowlab_core::light::Light;
use shadowlab_core::lightspace;
use shadowlab_core::metrics::sampling_stats;
use shadowlab_core::params::{ParamDef, ParamValues};

use crate::scene_gpu::GpuScene;
use crate::shaders::compose_depth;
use crate::techniques::{compose_view, view_layout, FrameInputs, NamedImage, Technique, TechniqueInfo, TechniqueReport};
use crate::timing::StageTimer;
use crate::{binding, raster, Gpu, GpuError};

const DEPTH_WGSL: &str = include_str!("depth.wgsl");
const EVAL_WGSL: &str = include_str!("eval.wgsl");

pub fn shaders() -> Vec<(&'static str, String)> {
    vec![("sm/depth.wgsl", depth_source()), ("sm/eval.wgsl", eval_source())]
}

/// The composed depth pass (uniform `SmParams` at group 0; mdsm and min-sm render with it too).
pub fn depth_source() -> String {
    compose_depth(DEPTH_WGSL)
}

/// The composed evaluation (view bindings, then `SmParams`, depth map, comparison sampler, counts).
pub fn eval_source() -> String {
    compose_view(EVAL_WGSL, false)
}

/// Shadow-map side in texels. The seeds evaluate 512 against 1024x1024 output.
pub const DEFAULT_RES: f64 = 512.0;
// Bias defaults come from a sweep (bias 0/0.25/0.5 x slope 0/0.5/1 x normal offset 0/0.5/1,
// res 512, 512x512 output) on courtyard, room, foliage and sponza, 2026-11-22: (0.5, 0, 0.5) was
// within 0.1 point of the best wrong-pixel rate on every scene; any slope bias added light leaks
// under ledges (sponza 1.62 % -> 2.58 % with slope 1) because the normal offset already grows
// with the slope. See BENCHMARKS.md.
/// Constant bias (texels along the light). Too low: acne on lit surfaces; too high: peter-panning.
pub const DEFAULT_BIAS: f64 = 0.5;
/// Slope-scaled bias (texels x tan of the light angle, clamped at `max_slope`). Off by default:
/// with the normal offset it only detaches contact shadows (light leaks under ledges).
pub const DEFAULT_SLOPE_BIAS: f64 = 0.0;
/// Normal offset (texels along the surface normal). Without it grazing surfaces show acne
/// (room: 22 % wrong at 0); too high shifts shadows sideways and makes thin occluders miss.
pub const DEFAULT_NORMAL_OFFSET: f64 = 0.5;

/// `sm`'s parameters, one constant each so that techniques with the same definition (same
/// default, range, doc and source) list them without copying.
pub const RES: ParamDef = ParamDef {
    key: "res",
    default: DEFAULT_RES,
    min: 16.0,
    max: 16384.0,
    integer: true,
    doc: "shadow map side (texels)",
    source: "seeds 000/002 evaluation: 512 with 1024x1024 output",
    choices: &[],
};
pub const PCF: ParamDef = ParamDef {
    key: "pcf",
    default: 1.0,
    min: 1.0,
    max: 7.0,
    integer: true,
    doc: "PCF kernel width N (NxN single-texel comparisons; (N-1)/2 x tan texels of bias added for the kernel); 1 = hard test",
    source: "Reeves et al. 1987; kernel bias: Isidoro 2006",
    choices: &[],
};
pub const BIAS: ParamDef = ParamDef {
    key: "bias",
    default: DEFAULT_BIAS,
    min: 0.0,
    max: 100.0,
    integer: false,
    doc: "constant depth bias, texels; low: acne, high: peter-panning",
    source: "shadowlab sweep 2026-11-22 (BENCHMARKS.md)",
    choices: &[],
};
pub const SLOPE_BIAS: ParamDef = ParamDef {
    key: "slope_bias",
    default: DEFAULT_SLOPE_BIAS,
    min: 0.0,
    max: 100.0,
    integer: false,
    doc: "slope-scaled bias, texels x tan(angle to light), tan clamped at max_slope",
    source: "shadowlab sweep 2026-11-22: 0 (normal offset covers slopes)",
    choices: &[],
};
pub const MAX_SLOPE: ParamDef = ParamDef {
    key: "max_slope",
    default: 4.0,
    min: 0.0,
    max: 1000.0,
    integer: false,
    doc: "clamp on tan(angle to light) for the slope bias and the PCF kernel bias; high: leaks under ledges at grazing light",
    source: "shadowlab sweep 2026-11-22 (2, 4, 10 with pcf=3)",
    choices: &[],
};
pub const NORMAL_OFFSET: ParamDef = ParamDef {
    key: "normal_offset",
    default: DEFAULT_NORMAL_OFFSET,
    min: 0.0,
    max: 100.0,
    integer: false,
    doc: "offset along the normal, texels; low: grazing acne, high: shifted shadows",
    source: "Holbert 2011 (normal offset shadows); value from the shadowlab sweep",
    choices: &[],
};

pub const PARAMS: &[ParamDef] = &[RES, PCF, BIAS, SLOPE_BIAS, MAX_SLOPE, NORMAL_OFFSET];

pub const INFO: TechniqueInfo = TechniqueInfo {
    name: "sm",
    summary: "shadow mapping: one depth map from the light (orthographic or perspective), biased hard test or NxN PCF",
    cost: "one depth pass over the scene + N^2 comparison fetches per pixel",
    quality: "aliasing where texels project large on screen (perspective aliasing); acne vs peter-panning trade-off",
    source: "Williams 1978; seed 002 chapter 2; PCF: Reeves, Salesin, Cook 1987",
    lights: &["directional", "spot"],
    params: PARAMS,
    create: |gpu, scene, p, light| Ok(Box::new(ShadowMap::new(gpu, scene, p, light)?)),
};

/// WGSL `SmParams` (in depth.wgsl and eval.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct SmParams {
    pub light_view_proj: [[f32; 4]; 4],
    pub texel: [f32; 4],
    pub bias: [f32; 4],
}

pub struct ShadowMap {
    res: u32,
    pcf: u32,
    params: SmParams,
    map: wgpu::Texture,
    counts: wgpu::Buffer,
    uniform: wgpu::Buffer,
    depth_pipeline: wgpu::RenderPipeline,
    depth_group: wgpu::BindGroup,
    eval_pipeline: wgpu::ComputePipeline,
    eval_layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
}

impl ShadowMap {
    pub fn new(gpu: &Gpu, scene: &GpuScene, p: &ParamValues, light: &Light) -> Result<ShadowMap, GpuError> {
        let res = p.get_u32("res");
        gpu.check_size(res, res, "shadow map")?;
        let lp = lightspace::fit(light, &scene.bounds, res).ok_or_else(|| GpuError::Invalid("sm does not support point lights".into()))?;
        let params = SmParams {
            light_view_proj: lp.view_proj.to_cols_array_2d(),
            texel: [lp.texel, lp.perspective as u32 as f32, res as f32, p.get("pcf") as f32],
            bias: [p.get("bias") as f32, p.get("slope_bias") as f32, p.get("normal_offset") as f32, p.get("max_slope") as f32],
        };
        let d = &gpu.device;
        let map = raster::depth_target(gpu, "sm.map", res, res, 1, wgpu::TextureUsages::empty());
        let uniform = gpu.uniform("sm.params", &params);
        let depth_layout = binding::layout(d, "sm.depth", wgpu::ShaderStages::VERTEX, &[binding::uniform()]);
        let depth_group = binding::group(d, "sm.depth", &depth_layout, &[uniform.as_entire_binding()]);
        let depth_pipeline = raster::scene_pipeline(gpu, "sm.depth", &depth_source(), &[&depth_layout, &scene.layout], &[]);
        let eval_layout = view_layout(
            gpu,
            "sm.eval",
            &[binding::uniform(), binding::texture_depth(), binding::comparison_sampler(), binding::storage(false)],
        );
        let eval_pipeline = gpu.compute_pipeline("sm.eval", &eval_source(), "main", &[&eval_layout]);
        let sampler = raster::comparison_sampler(gpu, "sm.cmp");
        let counts = gpu.storage("sm.counts", res as u64 * res as u64 * 4);
        Ok(ShadowMap {
            res,
            pcf: p.get_u32("pcf"),
            params,
            map,
            counts,
            uniform,
            depth_pipeline,
            depth_group,
            eval_pipeline,
            eval_layout,
            sampler,
        })
    }
}

impl Technique for ShadowMap {
    fn render(&mut self, gpu: &Gpu, f: &FrameInputs, timer: &mut StageTimer) -> Result<(), GpuError> {
        let map_view = self.map.create_view(&Default::default());
        timer.stage(gpu, "sm.render", |enc| {
            let mut pass = raster::begin_pass(enc, "sm.render", &[], &map_view);
            pass.set_pipeline(&self.depth_pipeline);
            pass.set_bind_group(0, &self.depth_group, &[]);
            pass.set_bind_group(1, &f.scene.group, &[]);
            pass.draw(0..f.scene.triangle_count * 3, 0..1);
        });
        Ok(())
    }

    fn evaluate(&mut self, gpu: &Gpu, f: &FrameInputs, timer: &mut StageTimer) -> Result<(), GpuError> {
        let map_view = self.map.create_view(&Default::default());
        let group = f.view_group(
            gpu,
            "sm.eval",
            &self.eval_layout,
            &[
                self.uniform.as_entire_binding(),
                wgpu::BindingResource::TextureView(&map_view),
                wgpu::BindingResource::Sampler(&self.sampler),
                self.counts.as_entire_binding(),
            ],
        );
        timer.stage(gpu, "sm.evaluate", |enc| {
            enc.clear_buffer(&self.counts, 0, None);
            gpu.dispatch_2d(enc, "sm.evaluate", &self.eval_pipeline, &[&group], f.gbuffer.width, f.gbuffer.height)
        });
        Ok(())
    }

    fn report(&mut self, gpu: &Gpu) -> TechniqueReport {
        let n = (self.res * self.res) as usize;
        let counts: Vec<u32> = gpu.read_buffer_as(&self.counts, n);
        let depth: Vec<f32> = bytemuck::pod_collect_to_vec(&gpu.read_texture(&self.map, 4));
        let mut r = TechniqueReport { shadow_data_bytes: n as u64 * 4, sampling: Some(sampling_stats(&counts)), ..Default::default() };
        r.counters.insert("fetches_per_pixel".into(), (self.pcf * self.pcf) as f64);
        r.counters.insert("shadow_map_texels".into(), n as f64);
        r.images.push(depth_image("shadow map (depth)", self.res, &depth));
        r.images.push(count_image("view samples per texel", self.res, &counts));
        let _ = self.params;
        r
    }
}

/// Grey depth picture, stretched to the range of covered texels (1.0 = empty shows black).
pub fn depth_image(name: &str, res: u32, depth: &[f32]) -> NamedImage {
    let (lo, hi) = depth.iter().filter(|d| **d < 1.0).fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &d| (a.min(d), b.max(d)));
    let rgba = depth
        .iter()
        .flat_map(|&d| {
            let g = if d >= 1.0 || hi <= lo { 0 } else { (255.0 * (1.0 - (d - lo) / (hi - lo)) * 0.85 + 30.0) as u8 };
            [g, g, g, 255]
        })
        .collect();
    NamedImage { name: name.into(), width: res, height: res, rgba }
}

/// Heat picture of the sample count per texel (log scale; black = unused).
pub fn count_image(name: &str, res: u32, counts: &[u32]) -> NamedImage {
    let max = counts.iter().copied().max().unwrap_or(1).max(1) as f32;
    let rgba = counts
        .iter()
        .flat_map(|&c| {
            if c == 0 {
                return [0, 0, 0, 255];
            }
            let t = (c as f32).ln_1p() / max.ln_1p();
            [(255.0 * t.sqrt()) as u8, (255.0 * t * t) as u8, (255.0 * (1.0 - t) * 0.6) as u8, 255]
        })
        .collect();
    NamedImage { name: name.into(), width: res, height: res, rgba }
}
