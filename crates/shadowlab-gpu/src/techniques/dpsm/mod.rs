//! Dual-paraboloid shadow maps for point lights (seed 002 section 3.3.2), two registry entries:
//! - `dpsm`: two `res x res` depth maps, one per hemisphere of the split plane
//!   (`shadowlab_core::techniques::dpsm`: the plane through the light perpendicular to `split`, +Y by
//!   default), the paraboloid mapping of eq. 3.3-3.10 applied per vertex. The mapping is not
//!   linear, so long edges are split first by the warping module's GPU subdivision
//!   (warp/subdiv.wgsl, `subdiv` = largest bend in texels). Stored depth: linear, distance /
//!   far, 0 at the light.
//! - `dpsm-notw`: NoTW (seed 000 section 3) per hemisphere: each hemisphere's desired view,
//!   count map, row and column warps over its own view samples (seed 002 section 5.3).
//!
//! Both are two instances of the warping module's `Warped` in its paraboloid projection mode
//! (warp/params.wgsl `base_clip`), each drawing into its layer of shared array textures
//! (`warp::Layers`): no pass is duplicated here. One subdivision makes both maps' pieces
//! (`warp::LayerSubdivision` over a copy of the scene's triangle indices a hemisphere, the scene
//! itself the frame's), one evaluation reads both maps, each view sample through the map of its
//! hemisphere (warp/params.wgsl `owns_sample`, eval_maps.wgsl).

use shadowlab_core::light::Light;
use shadowlab_core::metrics::sampling_stats;
use shadowlab_core::params::family::{self, Bias};
use shadowlab_core::params::{Block, ParamDef, ParamSet, ParamTable};
use shadowlab_core::techniques::dpsm::{split_axis, DualParaboloid, Hemisphere, SPLIT_AXES};

use crate::record::Recorder;
use crate::scene_gpu::GpuScene;
use crate::technique::{FrameInputs, Technique, TechniqueInfo, TechniqueReport};
use crate::techniques::warp::{self, Knobs, LayerPasses, LayerSubdivision, Layers, NotwCore, Projection, Subdivision, Warped};
use crate::{Gpu, GpuError};

/// Side of each hemisphere's map (texels). The setting: 512 per hemisphere against
/// 1024x1024 output (seeds 000/002 evaluate 512 maps).
pub const DEFAULT_RES: f64 = 512.0;
/// Split axis: +Y (a horizontal split plane). The floor and the table tops of indoor scenes lie in
/// the lower hemisphere, away from the seam; walls cross it.
pub const DEFAULT_SPLIT: f64 = 0.0;
/// Subdivision threshold (texels of bend of an edge under the paraboloid mapping). Room light 1,
/// 1024x1024 output, 512 maps: 1 -> 0.740 % wrong, 0.5 -> 0.704 %, 0.25 -> 0.692 % (docs/bench/point.md);
/// lower: more pieces (10 k -> 15 k per hemisphere from 0.5 to 0.25), higher: bent edges
/// (triangles drawn along chords of the paraboloid: misplaced shadow edges, leaks).
pub const DEFAULT_SUBDIV: f64 = 0.5;
/// `dpsm-notw`: the paraboloid and the warp bend together; room light 1: 2 (warp's default for
/// notw) -> 1.13 % wrong (worse than dpsm), 1 -> 0.72, 0.5 -> 0.556, 0.25 -> 0.508 (with
/// blur 4), at 0.2 M -> 0.5 M pieces in the lower hemisphere. 0.25 -> 0.125 (room / courtyard
/// lantern / conference light 1, 1024x1024): 0.400 -> 0.391 / 0.297 -> 0.284 / 0.507 -> 0.487 %
/// for ~2x the pieces (room 81 k -> 163 k, courtyard 0.31 M -> 0.58 M; none dropped)
/// (docs/bench/point_quality.md).
pub const DEFAULT_NOTW_SUBDIV: f64 = 0.125;
/// `dpsm-notw`'s blur of the counts (half-width, texels). Room light 1 (subdiv 0.5): 8 (warp's
/// default) -> 0.570 %, 4 -> 0.556, 2 -> 0.551; 4 halves the pieces of 2. At subdiv 0.125,
/// 4 -> 2: room 0.391 -> 0.382, courtyard lantern 0.284 -> 0.268, conference light 1 0.487 ->
/// 0.483 % wrong, the same pieces (163 k / 583 k / 600 k) (docs/bench/point_quality.md).
/// Too high: flatter warp; too low: a kink per texel (more pieces).
pub const DEFAULT_NOTW_BLUR: f64 = 2.0;
/// Constant bias (texels). The depth between subdivided vertices is interpolated along chords of
/// the paraboloid, so acne needs more than `sm`'s 0.5. See docs/bench/point.md.
pub const DEFAULT_BIAS: f64 = 1.0;
/// `dpsm-notw`'s constant bias (warped texels), with `DEFAULT_NOTW_NORMAL_OFFSET` and
/// `DEFAULT_NOTW_WINDOW`. Room / conference / courtyard lantern (wrong %; these sweeps used a
/// lantern at (1.9, 2.6, -6.6), since replaced by setups/point-courtyard.toml's): bias 0.5 -> 0.470 /
/// 0.587 / 0.760 (acne), 1 -> 0.401 / 0.498 / 0.398, 1.25 -> 0.399 / 0.499 / 0.358, 1.5 ->
/// 0.400 / 0.507 / 0.339. High: leaks (false lit grows).
pub const DEFAULT_NOTW_BIAS: f64 = 1.5;
/// `dpsm-notw`'s normal offset (warped texels). 0.5 (sm's) -> 0.25 with window 128, bias 1: room
/// 0.438 -> 0.401, conference 0.580 -> 0.498, courtyard lantern 0.402 -> 0.398 % wrong. (For
/// `dpsm` 0.25 is worse on courtyard: 0.586 -> 1.059, acne; it keeps sm's 0.5.)
pub const DEFAULT_NOTW_NORMAL_OFFSET: f64 = 0.25;
/// `dpsm-notw`'s smoothing window (functions averaged). The warp module's 16 (the authors'
/// code, planar maps) bends the paraboloid maps too much: room / conference / courtyard lantern
/// (bias 2) 16 -> 0.508 / 0.743 / 0.633 % wrong, 32 -> 0.516 / 0.725 / 0.416, 64 -> 0.455 /
/// 0.704 / 0.375, 128 -> 0.448 / 0.641 / 0.392, 256 -> 0.459 / 0.621 / 0.400, 511 -> 0.502 /
/// 0.618 / 0.426. Low: neighbouring rows warp apart, edges bend; high: RTW-like, less even.
/// `dpsm-notw`'s bias footprint (`bias_mode`, warp::BIAS_MODE): 0 (isotropic), not `notw`'s 2.
/// Room / courtyard lantern / conference light 1, wrong % (1024x1024, 512 per hemisphere):
/// mode 0 0.382 / 0.268 / 0.483, mode 2 0.385 / 1.086 / 0.489 (acne on the lantern: false
/// shadow 0.153 -> 0.988) (docs/bench/point_quality.md).
pub const DEFAULT_NOTW_BIAS_MODE: f64 = 0.0;
pub const DEFAULT_NOTW_WINDOW: f64 = 128.0;

pub const RES: ParamDef =
    family::RES.with_default(DEFAULT_RES, family::RES.source).with_doc("side of each hemisphere's map (texels); two maps");
pub const SPLIT: ParamDef = ParamDef::choice("split", SPLIT_AXES, DEFAULT_SPLIT as usize, "axis of the front hemisphere: the split plane passes through the light perpendicular to it; pick one that keeps the seam off the important surfaces", "seed 002 section 3.3.2 (the model-view matrix sets the split); y: shadowlab choice for indoor scenes");
const DPSM_SUBDIV: ParamDef = warp::SUBDIV.with_default(DEFAULT_SUBDIV, "seed 002 section 3.3.2 (tessellation needed); value: shadowlab measurement (docs/bench/point.md)").with_doc("split triangles until the paraboloid mapping (and warp) bends no edge by more than this many texels from its rasterised chord; 0 = off (big triangles drawn as chords: wrong); low: many pieces");
const NOTW_SUBDIV: ParamDef = DPSM_SUBDIV.with_default(
    DEFAULT_NOTW_SUBDIV,
    "shadowlab measurement on room, courtyard lantern, conference point lights (docs/bench/point.md, point_quality.md)",
);
const NOTW_BLUR: ParamDef = warp::NOTW_BLUR.with_default(
    DEFAULT_NOTW_BLUR,
    "shadowlab measurement on room, courtyard lantern, conference point lights (docs/bench/point.md, point_quality.md)",
);
const DPSM_BIAS: ParamDef =
    family::BIAS.with_default(DEFAULT_BIAS, "shadowlab sweep on room/conference point lights (docs/bench/point.md)");
const NOTW_BIAS: ParamDef =
    family::BIAS.with_default(DEFAULT_NOTW_BIAS, "shadowlab sweep on room, conference, courtyard lantern (docs/bench/point.md)");
const NOTW_WINDOW: ParamDef =
    warp::WINDOW.with_default(DEFAULT_NOTW_WINDOW, "shadowlab sweep on room, conference, courtyard lantern (docs/bench/point.md)");
const NOTW_NORMAL_OFFSET: ParamDef = family::NORMAL_OFFSET
    .with_default(DEFAULT_NOTW_NORMAL_OFFSET, "shadowlab sweep on room, conference, courtyard lantern (docs/bench/point.md)");

/// Exact depth per fragment (the fragment's direction intersected with its triangle's plane,
/// through the inverted warp for `dpsm-notw`) instead of the depth interpolated along the chords
/// of subdivided pieces. Off: on room light 1 it did not help (dpsm 0.740 -> 0.783 % wrong,
/// dpsm-notw at subdiv 0.25 0.537 -> 0.543) and it disables early depth tests; with fine
/// subdivision the chords are short. See docs/bench/point.md.
pub const DEFAULT_EXACT_DEPTH: f64 = 0.0;
const EXACT: ParamDef = warp::EXACT_DEPTH.with_default(DEFAULT_EXACT_DEPTH, "shadowlab (docs/bench/point.md)").with_doc("write the exact depth per fragment: the distance along the fragment's direction (warp inverted by Newton steps for dpsm-notw) to its triangle's plane; false = depth interpolated between (warped) vertices, off along chords of the paraboloid; disables early depth test");

const NOTW_BIAS_MODE: ParamDef = warp::BIAS_MODE.with_default(
    DEFAULT_NOTW_BIAS_MODE,
    "shadowlab measurement on the room, courtyard lantern and conference point lights (docs/bench/point_quality.md)",
);

shadowlab_core::param_choice! {
    /// The split axis (`SPLIT`): the names of `SPLIT_AXES`, in its order.
    pub enum Split { Y = "y", X = "x", Z = "z" }
}

shadowlab_core::param_set! {
    /// `dpsm`'s parameters: the map side and split, the subdivision of the paraboloid mapping,
    /// exact depth, sm's lookup and bias (no warp, so no footprint mode; a paraboloid map clamps
    /// the exact depth to the piece's distance range, so no depth clamp).
    pub struct DpsmSettings {
        pub res: u32 = RES,
        pub split: Split = SPLIT,
        pub subdivision: Subdivision = Block::as_declared().with(DPSM_SUBDIV),
        pub exact_depth: bool = EXACT,
        pub pcf: u32 = family::PCF,
        pub bias: Bias = Block::as_declared().with(DPSM_BIAS),
    }
    rules {
        fn ineffective(&self) -> Vec<(&'static str, String)> {
            let mut v = self.subdivision.dead();
            v.extend(self.subdivision.paraboloid_dead());
            v
        }
    }
}

shadowlab_core::param_set! {
    /// `dpsm-notw`'s parameters: the map side and split, then NoTW's block (as `notw`'s, with
    /// sm's docs for the lookup and bias rows and the defaults measured for paraboloid maps) and
    /// the smoothing's tent.
    pub struct DpsmNotwSettings {
        pub res: u32 = RES,
        pub split: Split = SPLIT,
        pub core: NotwCore = Block::as_declared()
            .with(NOTW_WINDOW)
            .with(NOTW_BLUR)
            .with(NOTW_SUBDIV)
            .with(EXACT)
            .with(family::PCF)
            .with(NOTW_BIAS)
            .with(family::SLOPE_BIAS)
            .with(NOTW_NORMAL_OFFSET)
            .with(NOTW_BIAS_MODE),
        pub window_tent: bool = warp::WINDOW_TENT,
    }
    rules {
        fn validate(&self) -> Result<(), String> {
            self.core.validate_at(self.res)
        }
        fn ineffective(&self) -> Vec<(&'static str, String)> {
            self.core.dead(true)
        }
    }
}

pub const INFO: TechniqueInfo = TechniqueInfo {
    name: "dpsm",
    summary: "dual-paraboloid shadow maps: two hemisphere depth maps of a point light, paraboloid mapping per vertex after GPU subdivision",
    cost:
        "one subdivision of the scene for both maps + two depth passes, one evaluation of both maps; 2 w^2 x 4 bytes; N^2 fetches per pixel",
    quality: "resolution fixed per solid angle (twice as fine at the rim as at the centre), blind to the view: aliasing near the camera",
    source: "Brabec, Annen, Seidel 2002; seed 002 section 3.3.2 (eq. 3.3-3.10)",
    lights: &["point"],
    params: ParamTable::of::<DpsmSettings>(),
    stalls: "",
    needs: "11 storage buffers per shader stage (WebGPU default: 8): the GPU subdivision (with the hidden-edge pyramid)",
    storage_buffers: 11,
    compare: &[""],
    shaders,
    create: |gpu, scene, p, light| Ok(Box::new(Dpsm::plain(gpu, scene, &DpsmSettings::from_values(p), light)?)),
};

pub const NOTW_INFO: TechniqueInfo = TechniqueInfo {
    name: "dpsm-notw",
    summary: "dual-paraboloid maps warped by NoTW per hemisphere: desired view, count map, row and column warps of each hemisphere's view samples",
    cost: "one pass each over the view for both hemispheres' desired views, count maps and evaluation, one dispatch a step of notw's analysis for both, one subdivision of the scene for both; per hemisphere a warped depth pass; 2 x (4 + 8) w^2 bytes",
    quality: "the view samples of each hemisphere spread over its whole map; seam at the split plane",
    source: "seed 002 section 5.3 (DPSM with NoTW), seed 000 section 3",
    lights: &["point"],
    params: ParamTable::of::<DpsmNotwSettings>(),
    stalls: "",
    needs: "11 storage buffers per shader stage (WebGPU default: 8): the GPU subdivision (with the hidden-edge pyramid)",
    storage_buffers: 11,
    compare: &[""],
    shaders,
    create: |gpu, scene, p, light| Ok(Box::new(Dpsm::notw(gpu, scene, &DpsmNotwSettings::from_values(p), light)?)),
};

/// Both maps' evaluation: a view sample goes to the map of its hemisphere.
const EVAL_MAPS_WGSL: &str = include_str!("eval_maps.wgsl");

/// The warping module's shaders, and the desired views and count maps (`dpsm-notw`) and the
/// evaluation of both maps.
pub fn shaders() -> Vec<(&'static str, String)> {
    let mut v = warp::shaders();
    v.push(("dpsm/eval_maps.wgsl (desired views)", warp::layered_dv_source("", EVAL_MAPS_WGSL)));
    v.push(("dpsm/eval_maps.wgsl (count maps)", warp::layered_count_source("", EVAL_MAPS_WGSL)));
    v.push(("warp/analyze_layers.wgsl (two hemispheres)", warp::layered_analysis_source(2)));
    v.push(("dpsm/eval_maps.wgsl (evaluation)", warp::layered_eval_source("", EVAL_MAPS_WGSL)));
    v
}

/// A point light's two hemisphere maps.
pub struct Dpsm {
    maps: [Warped; 2],
    /// Their warps, maps, DV bounds and counts, a layer each, and the passes over both (the
    /// desired views of `dpsm-notw`, the evaluation).
    layers: Layers,
    passes: LayerPasses,
    /// Both hemispheres' subdivision (`subdiv` > 0), before either draws.
    subdivision: Option<LayerSubdivision>,
    warped: bool,
    res: u32,
    pcf: u32,
}

impl Dpsm {
    /// `dpsm`: the two plain paraboloid maps.
    pub fn plain(gpu: &Gpu, scene: &GpuScene, p: &DpsmSettings, light: &Light) -> Result<Dpsm, GpuError> {
        Dpsm::new(gpu, scene, &Knobs::dpsm(p.res, p.pcf, &p.bias, &p.subdivision, p.exact_depth), p.split, light, false)
    }

    /// `dpsm-notw`: the two maps warped by NoTW (its window checked against `res` by
    /// [`DpsmNotwSettings`]'s rules).
    pub fn notw(gpu: &Gpu, scene: &GpuScene, p: &DpsmNotwSettings, light: &Light) -> Result<Dpsm, GpuError> {
        Dpsm::new(gpu, scene, &Knobs::dpsm_notw(&p.core, p.res, p.window_tent), p.split, light, true)
    }

    fn new(gpu: &Gpu, scene: &GpuScene, k: &Knobs, split: Split, light: &Light, warped: bool) -> Result<Dpsm, GpuError> {
        let name = if warped { "dpsm-notw" } else { "dpsm" };
        let Light::Point { position } = *light else {
            return Err(GpuError::Invalid(format!("{name} supports point lights only (got a {} light)", light.kind())));
        };
        let (res, pcf) = (k.res, k.pcf);
        gpu.check_size(res, res, "paraboloid map")?;
        let axis = split_axis(split.index()).expect("one axis per split name");
        let dp = DualParaboloid::fit(position, axis, &scene.bounds)
            .ok_or_else(|| GpuError::Invalid(format!("{name}: light position {position} or scene bounds not usable")))?;
        let labels: [&'static str; 2] = if warped { ["dpsm-notw.front", "dpsm-notw.back"] } else { ["dpsm.front", "dpsm.back"] };
        // dpsm-notw: both desired views, count maps and warps made together (dpsm crops none);
        // one subdivision of the scene for both hemispheres (a copy of it each)
        let subdivides = k.subdiv > 0.0;
        let layers = Layers::new(gpu, name, k, 2, warped, subdivides).repeating_scene();
        let make = |i: usize| {
            let h = Hemisphere::BOTH[i];
            let proj = Projection::Paraboloid { view: dp.view(h), hemisphere: h };
            Warped::with_projection_in(gpu, scene, k, proj, labels[i], Some((&layers, i as u32)))
        };
        let mut maps = [make(0)?, make(1)?];
        let passes = LayerPasses::new(gpu, name, &layers, &[&maps[0], &maps[1]], "", EVAL_MAPS_WGSL);
        let t = scene.triangle_count;
        let subdivision = subdivides
            .then(|| LayerSubdivision::new(gpu, name, &layers, &passes, &[&maps[0], &maps[1]], scene, &[t, 2 * t]))
            .transpose()?;
        if let Some(s) = &subdivision {
            for (i, m) in maps.iter_mut().enumerate() {
                m.draw_owner_pieces(s.draw(i));
            }
        }
        Ok(Dpsm { maps, layers, passes, subdivision, warped, res, pcf })
    }
}

impl Technique for Dpsm {
    fn prepare(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        if self.warped {
            self.passes.reduce_dv(gpu, f, rec, &self.layers);
            self.passes.count(gpu, f, rec, &self.layers);
            self.passes.analyze(gpu, rec, &self.layers);
        }
        Ok(())
    }

    fn render(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        if let Some(s) = &self.subdivision {
            s.record(gpu, rec, &f.scene.group);
        }
        for m in &mut self.maps {
            m.render(gpu, f, rec)?;
        }
        Ok(())
    }

    /// One pass: each sample through the map of its hemisphere.
    fn evaluate(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        self.passes.record(gpu, f, rec, &self.layers, false);
        Ok(())
    }

    fn analyze(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        self.passes.record(gpu, f, rec, &self.layers, true);
        Ok(())
    }

    fn report(&mut self, gpu: &Gpu) -> TechniqueReport {
        let n = (self.res * self.res) as u64;
        let mut r = TechniqueReport::default();
        // the subdivision's counters over both maps, and the pieces each drew
        let pieces = self.subdivision.as_ref().map(|s| s.report(gpu, 2 * n as usize, &mut r));
        let mut all_counts = Vec::with_capacity(2 * n as usize);
        let mut total_samples = [0u64; 2];
        for (i, m) in self.maps.iter_mut().enumerate() {
            let h = Hemisphere::BOTH[i].name();
            let sub = m.report(gpu);
            r.degraded.extend(sub.degraded.iter().map(|d| format!("{h} hemisphere: {d}")));
            let counts = m.read_counts_final(gpu);
            total_samples[i] = counts.iter().map(|&c| c as u64).sum();
            all_counts.extend_from_slice(&counts);
            for (k, v) in sub.counters {
                if k.ends_with("_before_warp") || k == "dv_area_fraction" {
                    r.counters.insert(format!("{h}.{k}"), v);
                } else if k == "exact_depth_fragments" {
                    *r.counters.entry(k).or_default() += v;
                }
            }
            for mut img in sub.images {
                if !self.warped {
                    img.name =
                        img.name.replace("count map after warping", "view samples per texel").replace("warped shadow map", "shadow map");
                }
                img.name = format!("{h} hemisphere: {}", img.name);
                r.images.push(img);
            }
            if let Some(p) = &pieces {
                r.counters.insert(format!("{h}.subdiv_triangles_drawn"), p[i] as f64);
                r.counters.insert(format!("{h}.subdiv_pieces_per_texel"), p[i] as f64 / n as f64);
            }
            let s = sampling_stats(&counts);
            r.counters.insert(format!("{h}.used_texel_fraction"), s.used_texel_fraction);
            r.counters.insert(format!("{h}.samples_per_used_texel_cv"), s.samples_per_used_texel_cv);
        }
        // maps (f32 depth) + warps (two R32Float res x res per hemisphere) + DV bounds
        let warp_bytes = if self.warped { 2 * 8 * n } else { 0 };
        r.shadow_data_bytes = 2 * 4 * n + warp_bytes + if self.warped { 2 * 32 } else { 0 };
        r.sampling = Some(sampling_stats(&all_counts));
        let c = &mut r.counters;
        c.insert("fetches_per_pixel".into(), (self.pcf * self.pcf) as f64);
        c.insert("shadow_map_texels".into(), 2.0 * n as f64);
        // both maps' exact-depth fragments, per texel of the two (0 without exact_depth)
        let frags = *c.entry("exact_depth_fragments".into()).or_default();
        c.insert("exact_depth_fragments_per_texel".into(), frags / (2 * n) as f64);
        c.insert("warp_bytes".into(), warp_bytes as f64);
        // work buffers of both maps + their one subdivision
        let maps: u64 = self.maps.iter().map(|m| m.scratch_bytes()).sum();
        c.insert("scratch_bytes".into(), (maps + self.subdivision.as_ref().map_or(0, |s| s.bytes())) as f64);
        let sum = (total_samples[0] + total_samples[1]).max(1) as f64;
        c.insert("front.sample_fraction".into(), total_samples[0] as f64 / sum);
        r
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::techniques::warp::tests::{error, keys};

    #[test]
    fn the_tables_keep_their_keys_in_order() {
        #[rustfmt::skip]
        let dpsm = ["res", "split", "subdiv", "subdiv_levels", "subdiv_capacity", "min_piece", "depth_split", "tessellate", "exact_depth", "pcf", "bias",
            "slope_bias", "max_slope", "normal_offset"];
        #[rustfmt::skip]
        let notw = ["res", "split", "window", "blur", "mix", "interp", "subdiv", "subdiv_levels", "subdiv_capacity", "min_piece",
            "depth_split", "tessellate", "close_cracks", "exact_depth", "pcf", "bias", "slope_bias", "max_slope", "normal_offset", "dv_margin", "strength",
            "bias_mode", "footprint_cap", "depth_clamp", "exact_inverse", "window_tent"];
        assert_eq!(keys::<DpsmSettings>(), dpsm);
        assert_eq!(keys::<DpsmNotwSettings>(), notw);
        assert_eq!(Split::NAMES, SPLIT_AXES);
    }

    #[test]
    fn the_rules_reject_conflicts_and_dead_keys() {
        assert_eq!(error("dpsm-notw:res=128"), "technique 'dpsm-notw': window 128 must be below res 128");
        assert!(error("dpsm:subdiv=0,subdiv_levels=3").contains("subdiv_levels has no effect: subdiv=0"));
        assert!(error("dpsm:bias_mode=2").contains("has no parameter 'bias_mode'"));
        assert!(error("dpsm:depth_clamp=1").contains("has no parameter 'depth_clamp'"));
        assert!(error("dpsm-notw:exact_depth=true,depth_clamp=1").contains("depth_clamp has no effect: a paraboloid map"));
        // dpsm-notw's exact depth is off by default
        assert!(error("dpsm-notw:exact_inverse=true").contains("exact_inverse has no effect: exact_depth=false"));
        assert!(error("dpsm-notw:footprint_cap=2").contains("footprint_cap has no effect: bias_mode=0"));
        for spec in ["dpsm:depth_split=1", "dpsm-notw:depth_split=1"] {
            assert!(error(spec).contains("depth_split has no effect: a paraboloid map's subdivision"), "{spec}");
        }
        assert!(error("dpsm:subdiv=0,depth_split=1").contains("depth_split has no effect: subdiv=0"));
        for ok in ["dpsm:split=x,subdiv=0,exact_depth=true", "dpsm-notw:exact_depth=true,exact_inverse=true", "dpsm-notw:res=256"] {
            assert_eq!(error(ok), "", "{ok}");
        }
    }
}
