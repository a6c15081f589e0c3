//! Leak tracing (seed 004, Kern, Brüll, Grosch): a filterable shadow map says where it is sure
//! (bound 0 or 1), rays answer the rest. Three registry entries, one implementation:
//! - `lt`: the single-depth filterable map (default EVSM; depth only, 2x2 gather, moments
//!   rebuilt in the shader, section 3.2), the leak-tracing test LTT (eq. 3), and the 3-bit
//!   temporal mask (section 3.1: expand rays eq. 6, optional remove rays eq. 8, reprojected
//!   with the G-buffer's motion vectors, a failed reprojection forces a ray);
//! - `ltt`: LTT alone, no temporal mask;
//! - `hybrid-pcf`: a ray where a 2x2 PCF of the plain (biased) depth map is not unanimous
//!   (AMD FidelityFX hybrid shadows, the paper's HySM comparator), no temporal mask.
//!
//! Passes: `<name>.render` draws the static triangles (`0..dynamic_first`) into the static map
//! (once, reused across frames with `reuse`, section 3.3-3.4; the map is fitted to the scene
//! bounds, so it stays valid for any camera while the light does not move) and the dynamic
//! triangles into the dynamic map every frame (skipped while there are none); `<name>.classify`
//! evaluates every pixel and appends the ones needing a ray to a list (atomic append);
//! `<name>.trace` sizes an indirect dispatch from the list's count and traces one ray per
//! listed pixel with `rt`'s BVH traversal (`reference::TRACE_WGSL`).
//! Temporal mask: 3 bits per light (ST, LTT = a ray was traced, RS) in two ping-pong buffers
//! of `leak::mask_texel_bits(lights)` bits per pixel (8 for the one light of an instance),
//! packed into u32 words (WebGPU cannot write R8Uint storage textures; the bytes are those of
//! an R8Uint texture), written with atomic OR. Reprojection: the pixel's motion vector leads to
//! last frame's pixel; it fails (forcing a ray) off-screen, and with `history_test` where last
//! frame's view depth there differs from this point's depth seen from the previous camera by
//! more than `depth_tol` (relative) or the normals differ by more than `normal_cos`; that needs
//! 8 bytes per pixel of history (view depth + packed normal, ping-pong).
//! Stored depth: linear light-space depth in [0, 1], 0 = near the light (filtered/'s `sd`
//! maps, rendered with its render.wgsl). CPU half: `shadowlab_core::techniques::lt`.
//! Directional lights (`cascades` > 1, default 4): the view frustum split with the practical
//! scheme, cascades 0..n-2 hybrid with maps fitted to their slices, enlarged by 15 % and
//! re-rendered only when this frame's slice leaves the kept box (section 3.3); the last
//! cascade is ray traced. `cascades=1`: one map fitted to the scene bounds. Spot: one map.
//! Point: one cube map of six layers (`shadowlab_core::techniques::lt::cube_faces`: 90 degree faces
//! widened by a texel, linear depth along the face axis), the face chosen per pixel by the
//! dominant axis, then the same 2x2 gather as a spot map (no gather across faces).
//!
//! Files: `params.rs` the three parameter tables and [`Variant`]; `uniforms.rs` the structs
//! shared with WGSL; construction in stages, `setup.rs` (the variant's settings, the checked
//! plan) then `resources.rs` (maps and buffers) then each pass's pipelines; the passes
//! `maps.rs` (`.render`), `classify.rs` (`.classify`), `trace.rs` (`.trace`); `cascade.rs` the
//! cascades' fitting and reuse; `screen.rs` the screen-sized state; `report.rs` the report.

mod cascade;
mod classify;
mod maps;
mod params;
mod report;
mod resources;
mod screen;
mod setup;
mod trace;
mod uniforms;

use shadowlab_core::light::Light;
use shadowlab_core::params::{ParamSet, ParamTable};

use cascade::Cascades;
use classify::ClassifyPass;
use maps::MapPass;
pub use params::*;
use resources::Resources;
use screen::Screen;
use trace::TracePass;
pub use uniforms::*;

use crate::record::Recorder;
use crate::scene_gpu::GpuScene;
use crate::technique::{FrameInputs, Technique, TechniqueInfo, TechniqueReport};
use crate::techniques::filtered::FilteredParams;
use crate::{Gpu, GpuError};

pub fn shaders() -> Vec<(&'static str, String)> {
    vec![("lt/classify.wgsl", classify::source()), ("lt/trace.wgsl", trace::source()), ("lt/args.wgsl", trace::ARGS_WGSL.to_string())]
}

const LIGHTS: &[&str] = &["directional", "spot", "point"];

pub const LT_INFO: TechniqueInfo = TechniqueInfo {
    name: "lt",
    summary: "leak tracing: single-depth EVSM + LTT + 3-bit temporal mask (expand/remove rays), rays only where unsure",
    cost: "static map once + 1 gather and 4 (9) mask reads per pixel + one BVH ray per listed pixel (indirect dispatch)",
    quality: "converges to rt within a few frames; thin lit gaps missing from the map can stay closed",
    source: "Kern, Brüll, Grosch 2024 (seed 004) sections 3-3.4",
    lights: LIGHTS,
    params: ParamTable::of::<LtSettings>(),
    stalls: "",
    needs: "9 storage buffers per shader stage (WebGPU default: 8)",
    storage_buffers: 9,
    compare: &[""],
    shaders,
    create: |gpu, scene, p, light| Ok(Box::new(LeakTracing::new(gpu, scene, &Variant::Lt(LtSettings::from_values(p)), light)?)),
};
pub const LTT_INFO: TechniqueInfo = TechniqueInfo {
    name: "ltt",
    summary: "leak-tracing test alone: a ray where the single-depth filterable bound is strictly between eps and 1-eps",
    cost: "static map once + 1 gather per pixel + one ray per listed pixel",
    quality: "misses LTT's failure cases (grazing receivers, edges near gaps: seed 004 figure 4)",
    source: "seed 004 eq. 3 ('LTT only' of table 3)",
    lights: LIGHTS,
    params: ParamTable::of::<LttSettings>(),
    stalls: "",
    needs: "9 storage buffers per shader stage (WebGPU default: 8)",
    storage_buffers: 9,
    compare: &[""],
    shaders,
    create: |gpu, scene, p, light| Ok(Box::new(LeakTracing::new(gpu, scene, &Variant::Ltt(LttSettings::from_values(p)), light)?)),
};
pub const HYBRID_INFO: TechniqueInfo = TechniqueInfo {
    name: "hybrid-pcf",
    summary: "hybrid shadows: a ray where the 2x2 PCF of a biased plain depth map is not unanimous",
    cost: "static map once + 1 gather per pixel + one ray per listed pixel",
    quality: "needs a tuned bias; misses edges the biased map does not see",
    source: "AMD FidelityFX Hybrid Shadows 2021 (seed 004's HySM)",
    lights: LIGHTS,
    params: ParamTable::of::<HybridSettings>(),
    stalls: "",
    needs: "9 storage buffers per shader stage (WebGPU default: 8)",
    storage_buffers: 9,
    compare: &[""],
    shaders,
    create: |gpu, scene, p, light| Ok(Box::new(LeakTracing::new(gpu, scene, &Variant::HybridPcf(HybridSettings::from_values(p)), light)?)),
};

pub struct LeakTracing {
    mode: Mode,
    /// Map side (texels).
    res: u32,
    reuse: bool,
    mask_bits: u32,
    /// Map layers (hybrid levels).
    levels: usize,
    /// classify's uniform with this frame's cascade levels (`evaluate` adds the frame's flags).
    params: LtParams,
    /// The raster uniform last written for a cascade.
    map_params: FilteredParams,
    cascades: Option<Cascades>,
    /// Static map layers to re-render.
    static_dirty: Vec<bool>,
    /// Layer renders of the static map, of the dynamic map.
    static_renders: u32,
    dynamic_renders: u32,
    resources: Resources,
    map_pass: MapPass,
    classify: ClassifyPass,
    trace: TracePass,
    screen: Option<Screen>,
    /// The trace's `TraceParams` for (mask bits, pixels): made once per output size.
    trace_uniform: Option<((u32, u32), wgpu::Buffer)>,
}

impl LeakTracing {
    /// In stages: the variant's settings, the checked plan (setup.rs), the maps and buffers
    /// (resources.rs), the passes' pipelines and bind groups.
    pub fn new(gpu: &Gpu, scene: &GpuScene, variant: &Variant, light: &Light) -> Result<LeakTracing, GpuError> {
        let settings = setup::read(variant);
        let plan = setup::plan(gpu, scene, &settings, light)?;
        let resources = Resources::new(gpu, &plan);
        let name = plan.mode.name();
        let map_pass = MapPass::new(gpu, scene, name, &resources.map_uniforms);
        let classify = ClassifyPass::new(gpu, name, &plan.params);
        let trace = TracePass::new(gpu, scene, name);
        Ok(LeakTracing {
            mode: plan.mode,
            res: plan.res,
            reuse: plan.reuse,
            mask_bits: plan.mask_bits,
            levels: plan.levels,
            params: plan.params,
            map_params: plan.map_params,
            cascades: plan.cascades,
            static_dirty: vec![true; plan.levels],
            static_renders: 0,
            dynamic_renders: 0,
            resources,
            map_pass,
            classify,
            trace,
            screen: None,
            trace_uniform: None,
        })
    }

    /// The screen-sized state for a `w x h` view (reallocated, without history, on a new size).
    fn screen(&mut self, gpu: &Gpu, w: u32, h: u32) -> &mut Screen {
        if !matches!(&self.screen, Some(s) if s.width == w && s.height == h) {
            self.screen = Some(Screen::new(gpu, self.mode.name(), w, h, self.mask_bits));
        }
        self.screen.as_mut().expect("allocated above")
    }

    /// The pixels listed for rays in the last frame (in list order).
    pub fn ray_list(&self, gpu: &Gpu) -> Vec<u32> {
        self.screen.as_ref().map_or_else(Vec::new, |s| s.ray_list(gpu))
    }

    /// Layer 0 of the static map and of the dynamic map (linear light depth, `res`^2 texels),
    /// as last rendered.
    pub fn maps(&self, gpu: &Gpu) -> (Vec<f32>, Option<Vec<f32>>) {
        let read = |t: &wgpu::Texture| bytemuck::pod_collect_to_vec(&gpu.read_texture(t, 4));
        (read(&self.resources.static_map), self.resources.dynamic_map.as_ref().map(read))
    }

    /// The temporal mask written in the last frame: 3 bits per pixel (`shadowlab_core::techniques::lt`).
    pub fn mask(&self, gpu: &Gpu) -> Vec<u32> {
        self.screen.as_ref().map_or_else(Vec::new, |s| s.mask(gpu, self.mask_bits))
    }
}

impl Technique for LeakTracing {
    /// Cascades: fit this frame's slices, keep or replace each level's box (section 3.3).
    fn prepare(&mut self, _gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        let t0 = web_time::Instant::now();
        if let Some(c) = self.cascades.as_mut() {
            let dirty = c.update(f, self.res, self.reuse, &mut self.params)?;
            for (l, d) in dirty.into_iter().enumerate() {
                if d {
                    self.map_params.light_view_proj = self.params.levels[l].view_proj;
                    self.map_params.texel_world = self.params.levels[l].info[0];
                    rec.write_buffer(&self.resources.map_uniforms[l], 0, bytemuck::bytes_of(&self.map_params));
                    self.static_dirty[l] = true;
                }
            }
            rec.cpu(&format!("{}.fit", self.mode.name()), t0.elapsed().as_secs_f64() * 1e3);
        } else if !self.reuse {
            self.static_dirty.iter_mut().for_each(|d| *d = true);
        }
        Ok(())
    }

    /// The static map's dirty layers and every layer of the dynamic map (maps.rs).
    fn render(&mut self, _gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        let name = self.mode.name();
        let label = format!("{name}.render");
        let dynamic = (f.scene.dynamic_first < f.scene.triangle_count).then_some(f.scene.dynamic_first..f.scene.triangle_count);
        if dynamic.is_some() && self.resources.dynamic_map.is_none() {
            return Err(GpuError::Invalid(format!("{name}: the scene gained dynamic triangles after creation")));
        }
        let redraw: Vec<usize> = (0..self.levels).filter(|l| self.static_dirty[*l]).collect();
        if redraw.is_empty() && dynamic.is_none() {
            return Ok(());
        }
        self.map_pass.record(rec, &label, f, &self.resources, &redraw, dynamic.clone());
        self.static_renders += redraw.len() as u32;
        self.dynamic_renders += if dynamic.is_some() { self.levels as u32 } else { 0 };
        self.static_dirty.iter_mut().for_each(|d| *d = false);
        Ok(())
    }

    /// Classification into the ray list (classify.rs), then the listed rays (trace.rs).
    fn evaluate(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        let name = self.mode.name();
        let (w, h) = (f.gbuffer.width, f.gbuffer.height);
        let has_dynamic = self.resources.dynamic_map.is_some() && f.scene.dynamic_first < f.scene.triangle_count;
        let frames = self.screen(gpu, w, h).frames;
        let mut params = self.params;
        params.frame = frames;
        params.flags |= if frames > 0 { FLAG_HAS_HISTORY } else { 0 } | if has_dynamic { FLAG_DYNAMIC } else { 0 };
        rec.write_buffer(&self.resources.uniform, 0, bytemuck::bytes_of(&params));
        let key = (self.mask_bits, w * h);
        if self.trace_uniform.as_ref().map(|(k, _)| *k) != Some(key) {
            self.trace_uniform = Some((key, TracePass::uniform(gpu, name, self.mask_bits, w * h)));
        }
        let trace = &self.trace_uniform.as_ref().expect("made above").1;
        let s = self.screen.as_ref().expect("allocated above");
        let classify = self.classify.group(gpu, f, name, &self.resources, s);
        let trace_groups = self.trace.groups(gpu, f, name, trace, s);
        self.classify.record(gpu, rec, name, &classify, s);
        self.trace.record(gpu, rec, name, f, &trace_groups, s);
        self.screen.as_mut().expect("allocated above").frames += 1;
        Ok(())
    }

    fn report(&mut self, gpu: &Gpu) -> TechniqueReport {
        let facts = report::Facts {
            temporal: self.mode == Mode::Lt,
            res: self.res,
            levels: self.levels,
            dynamic: self.resources.dynamic_map.is_some(),
            cascaded: self.cascades.is_some(),
            static_renders: self.static_renders,
            dynamic_renders: self.dynamic_renders,
            full: self.params.flags & FLAG_FULL != 0,
            mask_bits: self.mask_bits,
            static_map: &self.resources.static_map,
            screen: self.screen.as_ref(),
        };
        report::report(&facts, gpu)
    }
}
