//! `min-sm`: shadow mapping with the minimal shadow frustum (MSF; seed 000 section 3.2, seed 002
//! section 4.1.5). Per frame: the view samples are projected into the light's fixed frame and
//! reduced on the GPU (bounding box, then per band of `grid` rows the least and greatest x;
//! reduce.wgsl; in steady state one pass, banding over the previous frame's range with overflow
//! slots), the few band corners are read back, the CPU takes their convex hull and the
//! minimum-area rectangle by rotating calipers (`shadowlab_core::techniques::min_sm`), and the map is
//! rendered over that rectangle (rotated, padded by the bias reach) with near/far fitted to the
//! scene towards the light and the farthest sample. Depth map and evaluation are `sm`'s shaders
//! and bias model; the texel is the rectangle's larger texel side.
//! Stored depth: post-projective, 0 = near the light (orthographic: linear).

use bytemuck::Zeroable;
use shadowlab_core::light::Light;
use shadowlab_core::lightspace::{self, LightProjection};
use shadowlab_core::params::family::{self, Bias};
use shadowlab_core::params::{Block, ParamDef, ParamSet, ParamTable};
use shadowlab_core::scene::Bounds;
use shadowlab_core::techniques::min_sm::frustum::{self, LightFrame, MinFrustum, RectFit, Reduction};

use crate::record::Recorder;
use crate::scene_gpu::GpuScene;
use crate::technique::{compose_view, view_layout, FrameInputs, Technique, TechniqueInfo, TechniqueReport};
use crate::techniques::sm::{MapPass, MapSettings};
use crate::{binding, Gpu, GpuError};

const REDUCE_WGSL: &str = include_str!("reduce.wgsl");

/// min-sm's own shader (the depth and evaluation shaders are `sm`'s files, validated there).
pub fn shaders() -> Vec<(&'static str, String)> {
    vec![("min_sm/reduce.wgsl", compose_view(REDUCE_WGSL, false))]
}

/// Bands of the light-space reduction. The hull of the band corners exceeds the exact hull by at
/// most one band height (1/grid of the samples' extent). Too low: a looser rectangle (16 bands:
/// up to 6 % per side); too high: more atomics targets and a longer read-back (8 bytes per band).
/// 1024 keeps the overshoot at a quarter texel of a 512 map on the box's y side.
pub const DEFAULT_GRID: f64 = 1024.0;
/// Pixels of a screen row one reduction thread walks, keeping its extremes in registers:
/// neighbouring pixels mostly fall in the same band, so atomics drop by about this factor.
pub const RUN: u32 = 16;
/// Texels of padding beyond the bias reach (normal offset + PCF half width): f32 rounding of the
/// projected samples and of the band bounds. Too low: samples at the rim read outside the map
/// (lit); too high: wasted texels.
pub const PAD_MARGIN_TEXELS: f64 = 1.0;

shadowlab_core::param_set! {
    /// `min-sm`'s parameters: `sm`'s (same keys, defaults, docs and sources), then the
    /// reduction grid and the rectangle's fit.
    pub struct MinSmSettings {
        pub res: u32 = family::RES,
        pub pcf: u32 = family::PCF,
        pub bias: Bias = Block::as_declared(),
        pub grid: u32 = ParamDef::integer("grid", DEFAULT_GRID, 1.0, 16384.0, "bands of the GPU reduction before the hull (hull overshoot <= 1/grid of the samples' extent)", "shadowlab: exact hull up to one band; 1024 = 8 KB read back"),
        pub fit: RectFit = ParamDef::choice("fit", RectFit::NAMES, 0, "rectangle around the hull: area = minimum area (the seeds' MSF; texels may be stretched up to the rectangle's aspect), side = shortest longer side (smallest square texel)", "seed 000 section 3.2 (area); side: shadowlab, see docs/bench/min_sm.md"),
        pub one_pass: bool = ParamDef::flag("one_pass", true, "true: one pass over the G-buffer, bands over the previous frame's y range (samples outside it go to two overflow slots: always conservative, tight again next frame); false or first frame: two passes (bounds, then bands)", "shadowlab: halves the G-buffer reads in steady state (docs/bench/min_sm.md)"),
    }
    rules {
        fn ineffective(&self) -> Vec<(&'static str, String)> {
            self.bias.ineffective(self.pcf)
        }
    }
}

impl MinSmSettings {
    /// The map `sm`'s passes draw and evaluate.
    fn map(&self) -> MapSettings {
        MapSettings { res: self.res, pcf: self.pcf, bias: self.bias.clone() }
    }
}

pub const INFO: TechniqueInfo = TechniqueInfo {
    name: "min-sm",
    summary: "shadow map over the minimal shadow frustum: min-area rectangle (rotating calipers) around the view samples in light space",
    cost: "one reduction pass over the view samples (two on the first frame) + an 8 KB read-back and a CPU hull/calipers fit (~0.25 ms) + one depth pass",
    quality: "sm with the map focused on what the view sees: wins on close-ups, near sm on full-scene views; perspective aliasing remains",
    source: "seed 000 section 3.2 and seed 002 section 4.1.5 (MSF after Stamminger & Drettakis 2002, Perspective Shadow Maps); calipers: Toussaint 1983",
    lights: &["directional", "spot"],
    params: ParamTable::of::<MinSmSettings>(),
    stalls: "min-sm.readback: the band reduction of the view samples is read back for the CPU hull and calipers",
    needs: "",
    storage_buffers: 8,
    compare: &[""],
    shaders,
    create: |gpu, scene, p, light| Ok(Box::new(MinShadowMap::new(gpu, scene, &MinSmSettings::from_values(p), light)?)),
};

/// WGSL `MsfReduce` (reduce.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, Zeroable)]
pub struct MsfReduce {
    pub frame_view: [[f32; 4]; 4],
    pub mode: [u32; 4],
    pub prev: [f32; 4],
}

pub struct MinShadowMap {
    pub(crate) groups: crate::binding::GroupCache,
    /// `sm`'s depth pass and evaluation, pointed at the fitted rectangle every frame.
    pass: MapPass,
    res: u32,
    grid: u32,
    shape: RectFit,
    one_pass: bool,
    /// y range of the last frame's samples in the light frame (the next one-pass band range).
    prior: Option<(f32, f32)>,
    last_passes: u32,
    light: Light,
    bounds: Bounds,
    frame: LightFrame,
    /// `sm`'s scene-fitted projection: used when no sample is evaluated, and for comparisons.
    scene_fit: LightProjection,
    pad_texels: f64,
    last: Option<MinFrustum>,
    /// CPU fit time of every frame so far (ms).
    fit_ms: Vec<f64>,
    last_count: u64,
    reduce_uniform: wgpu::Buffer,
    reduce_layout: wgpu::BindGroupLayout,
    bounds_pipeline: wgpu::ComputePipeline,
    rows_pipeline: wgpu::ComputePipeline,
    red: wgpu::Buffer,
    staging: wgpu::Buffer,
}

impl MinShadowMap {
    pub fn new(gpu: &Gpu, scene: &GpuScene, p: &MinSmSettings, light: &Light) -> Result<MinShadowMap, GpuError> {
        let res = p.res;
        gpu.check_size(res, res, "shadow map")?;
        let no_point = || GpuError::Invalid("min-sm does not support point lights".into());
        let scene_fit = lightspace::fit(light, &scene.bounds, res).ok_or_else(no_point)?;
        let frame = frustum::light_frame(light, &scene.bounds).ok_or_else(no_point)?;
        let (pcf, grid) = (p.pcf, p.grid);
        let pass = MapPass::new(gpu, scene, "min-sm", &p.map(), &scene_fit);
        let reduce = MsfReduce {
            frame_view: frame.view.as_mat4().to_cols_array_2d(),
            mode: [frame.perspective as u32, grid, RUN, 0],
            prev: [0.0; 4],
        };
        let reduce_uniform = gpu.uniform("min-sm.reduce", &reduce);
        let reduce_layout = view_layout(gpu, "min-sm.reduce", &[binding::uniform(), binding::storage(false)]);
        let src = compose_view(REDUCE_WGSL, false);
        let bounds_pipeline = gpu.compute_pipeline("min-sm.reduce.bounds", &src, "bounds", &[&reduce_layout]);
        let rows_pipeline = gpu.compute_pipeline("min-sm.reduce.rows", &src, "rows", &[&reduce_layout]);
        let words = frustum::buffer_words(grid as usize) as u64 * 4;
        let red = gpu.storage("min-sm.reduction", words);
        let staging = gpu.buffer(&wgpu::BufferDescriptor {
            label: Some("min-sm.reduction.readback"),
            size: words,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let pad_texels = p.bias.normal_offset + (pcf as f64 - 1.0) * 0.5 + PAD_MARGIN_TEXELS;
        Ok(MinShadowMap {
            groups: Default::default(),
            pass,
            res,
            grid,
            shape: p.fit,
            one_pass: p.one_pass,
            prior: None,
            last_passes: 0,
            light: *light,
            bounds: scene.bounds,
            frame,
            scene_fit,
            pad_texels,
            last: None,
            fit_ms: Vec::new(),
            last_count: 0,
            reduce_uniform,
            reduce_layout,
            bounds_pipeline,
            rows_pipeline,
            red,
            staging,
        })
    }

    fn read_reduction(&self, gpu: &Gpu) -> Result<Vec<u32>, GpuError> {
        let slice = self.staging.slice(..);
        let (tx, rx) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        gpu.wait();
        let failed = |e: String| GpuError::Validation(format!("min-sm: reading back the reduction: {e}"));
        rx.recv().map_err(|e| failed(e.to_string()))?.map_err(|e| failed(e.to_string()))?;
        let words = bytemuck::pod_collect_to_vec(&slice.get_mapped_range().map_err(|e| failed(e.to_string()))?);
        self.staging.unmap();
        Ok(words)
    }
}

impl Technique for MinShadowMap {
    fn prepare(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        let group = f.view_group(
            gpu,
            &self.groups,
            "min-sm.reduce",
            &self.reduce_layout,
            &[self.reduce_uniform.as_entire_binding(), self.red.as_entire_binding()],
        );
        let (w, h) = (f.gbuffer.width, f.gbuffer.height);
        let prior = if self.one_pass { self.prior } else { None };
        let (lo, hi) = prior.unwrap_or((0.0, 0.0));
        // mode.w and prev of MsfReduce
        let w_at = std::mem::offset_of!(MsfReduce, mode) as u64 + 12;
        rec.write_buffer(&self.reduce_uniform, w_at, bytemuck::bytes_of(&(prior.is_some() as u32)));
        rec.write_buffer(&self.reduce_uniform, std::mem::offset_of!(MsfReduce, prev) as u64, bytemuck::bytes_of(&[lo, hi, 0.0, 0.0]));
        self.last_passes = if prior.is_some() { 1 } else { 2 };
        rec.stage("min-sm.reduce", |enc| {
            enc.clear_buffer(&self.red, 0, None);
            gpu.dispatch_2d(enc, "min-sm.reduce.bounds", &self.bounds_pipeline, &[&group], w.div_ceil(RUN), h);
            if prior.is_none() {
                gpu.dispatch_2d(enc, "min-sm.reduce.rows", &self.rows_pipeline, &[&group], w.div_ceil(RUN), h);
            }
            enc.copy_buffer_to_buffer(&self.red, 0, &self.staging, 0, self.red.size());
        });
        let t0 = web_time::Instant::now();
        rec.sync("min-sm.readback");
        let words = self.read_reduction(gpu)?;
        rec.cpu("min-sm.readback", t0.elapsed().as_secs_f64() * 1e3);

        // CPU: hull, calipers, projection
        let t1 = web_time::Instant::now();
        let red = Reduction::from_words(&words, self.grid as usize, prior);
        self.last_count = red.as_ref().map_or(0, |r| r.count);
        self.prior = red.as_ref().map(|r| (r.lo.y as f32, r.hi.y as f32));
        self.last = red.and_then(|r| frustum::fit(&self.light, &self.bounds, &self.frame, &r, self.res, self.pad_texels, self.shape));
        let (vp, texel, persp) = match &self.last {
            Some(m) => (m.view_proj_f32(), m.texel as f32, m.perspective),
            None => (self.scene_fit.view_proj, self.scene_fit.texel, self.scene_fit.perspective),
        };
        let fit_ms = t1.elapsed().as_secs_f64() * 1e3;
        self.fit_ms.push(fit_ms);
        rec.cpu("min-sm.fit", fit_ms);
        self.pass.set_projection(rec, vp, texel, persp);
        Ok(())
    }

    fn render(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        self.pass.render(gpu, f, rec);
        Ok(())
    }

    fn evaluate(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        self.pass.evaluate(gpu, f, rec);
        Ok(())
    }

    fn analyze(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        self.pass.analyze(gpu, f, rec);
        Ok(())
    }

    fn report(&mut self, gpu: &Gpu) -> TechniqueReport {
        let (mut r, counts) = self.pass.report(gpu);
        let in_map: u64 = counts.iter().map(|&c| c as u64).sum();
        let c = &mut r.counters;
        c.insert("view_samples".into(), self.last_count as f64);
        c.insert("samples_in_map".into(), in_map as f64);
        c.insert("samples_outside_map".into(), self.last_count.saturating_sub(in_map) as f64);
        // median and max over the frames run so far (a single frame can be preempted)
        c.insert("cpu_fit_ms".into(), crate::timing::median(&self.fit_ms));
        c.insert("cpu_fit_max_ms".into(), self.fit_ms.iter().copied().fold(0.0, f64::max));
        c.insert("readback_bytes".into(), self.red.size() as f64);
        c.insert("fallback_scene_fit".into(), self.last.is_none() as u32 as f64);
        c.insert("reduce_passes".into(), self.last_passes as f64);
        if let Some(m) = &self.last {
            c.insert("reduced_points".into(), m.input_points as f64);
            c.insert("hull_points".into(), m.hull_points as f64);
            c.insert("rect_area_vs_scene_map".into(), m.area_ratio);
            c.insert("texel_vs_sm".into(), m.texel / self.scene_fit.texel as f64);
            c.insert("rect_aspect".into(), m.padded.half.max_element() / m.padded.half.min_element().max(1e-30));
        }
        r
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn shares_sm_parameters_by_key() {
        use shadowlab_core::params::ParamSet;
        let keys: Vec<_> = super::MinSmSettings::defs().iter().map(|p| p.key).collect();
        assert_eq!(keys, ["res", "pcf", "bias", "slope_bias", "max_slope", "normal_offset", "grid", "fit", "one_pass"]);
    }
}
