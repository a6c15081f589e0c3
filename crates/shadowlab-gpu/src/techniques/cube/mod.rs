//! Point-light shadows with cube maps (seed 002 section 3.3.1, chapter 5.3), two registry
//! entries:
//! - `cube`: six `res x res` faces, one depth pass per face (no multiview: lavapipe and the
//!   trait's one-light-per-instance keep it simple; six passes are what the seed describes),
//!   per-face triangle culling in the vertex stage. Stored depth: linear distance to the light
//!   divided by `far`, 0 at the light (so sm's bias model in texels behaves the same on every
//!   face). Lookup: NxN nearest-texel PCF whose taps cross face edges onto the neighbour face.
//!   The face math is `shadowlab_core::techniques::cube` (CPU, tested) and `faces.wgsl`.
//! - `cube-notw` (notw.rs): NoTW per face: each face is a 90 degree square perspective frustum
//!   (a spot light along the face axis) handled by `warp::Warped` with the face's view samples
//!   only (its own desired view, count map and warps: 8 w^2 bytes per face), drawn into its
//!   layer of shared array textures (`warp::Layers`) so that one evaluation reads every face.
//!
//! `cube`'s map is made and reported in map.rs, its faces drawn in depth.rs, evaluated in
//! eval.rs; `cube-notw`'s per-face scenes are clip.rs.

mod clip;
mod depth;
mod eval;
mod map;
mod notw;
pub use map::read_layers;
pub use notw::CubeNotw;

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use shadowlab_core::light::Light;
use shadowlab_core::params::family::{Bias, PCF, RES};
use shadowlab_core::params::{Block, ParamDef, ParamSet, ParamTable};

use crate::record::Recorder;
use crate::technique::{counted_evaluation, FrameInputs, Technique, TechniqueInfo, TechniqueReport};
use crate::{Gpu, GpuError};

/// The face rules (`shadowlab_core::techniques::cube`), also composed into `virtual`'s shaders.
pub(crate) const FACES_WGSL: &str = include_str!("faces.wgsl");

pub fn shaders() -> Vec<(&'static str, String)> {
    let [dv, count, analysis, eval_notw] = notw::layer_sources();
    vec![
        ("cube/depth.wgsl", depth::source()),
        ("cube/eval.wgsl", eval::source()),
        ("cube/eval_notw.wgsl (desired views)", dv),
        ("cube/eval_notw.wgsl (count maps)", count),
        ("warp/analyze_layers.wgsl (six faces)", analysis),
        ("cube/eval_notw.wgsl (evaluation)", eval_notw),
        // six faces of 10 triangles each
        ("warp/subdiv_layers.wgsl (six faces)", crate::techniques::warp::layered_subdivision_source(&[10, 20, 30, 40, 50, 60])),
        ("warp/subdiv_scatter.wgsl (six faces)", crate::techniques::warp::layered_scatter_source(&[10, 20, 30, 40, 50, 60])),
    ]
}

shadowlab_core::param_choice! {
    /// How a face stores depth (`DEFAULT_DEPTH`).
    pub enum FaceDepth { Distance = "distance", Hardware = "hardware" }
}

/// How a face stores depth. `distance` (0): the linear distance to the light written by the
/// fragment stage (exact per fragment, but every fragment runs a shader and no early depth
/// test). `hardware` (1): the rasteriser's reversed depth near / z, with no fragment stage
/// where the scene has no cut-outs (as a GL depth pass with an empty fragment shader); the
/// evaluation recovers the distance along the texel's centre ray (the same quantity, rounded
/// differently). Default hardware: chosen on room light 1 and the courtyard lantern, checked on
/// conference light 1 and sponza-peer (1024x1024; res 512, pcf 3, res 1024): the same wrong %
/// to three decimals on all four, `cube.render` 3-8x faster (docs/bench/recorded_frame.md).
pub const DEFAULT_DEPTH: f64 = 1.0;
pub const DEPTH: ParamDef = ParamDef::choice("depth", FaceDepth::NAMES, DEFAULT_DEPTH as usize, "face depth: distance (linear distance per fragment: a fragment shader on every fragment) or hardware (reversed near/z from the rasteriser, no fragment stage without cut-outs; distance recovered in the evaluation)", "distance: seed 002 3.3.1; hardware: the NoTW authors' app (depth-only faces); measured in docs/bench/recorded_frame.md");

shadowlab_core::param_set! {
    /// `cube`'s parameters: sm's apply unchanged (`res` is per face, the seeds' 512; the bias is in
    /// texels of the face at the sample; sm's bias sweep was on directional/spot lights, see
    /// docs/bench/point.md for the point-light check), then how the faces store depth.
    pub struct CubeSettings {
        pub res: u32 = RES,
        pub pcf: u32 = PCF,
        pub bias: Bias = Block::as_declared(),
        pub depth: FaceDepth = DEPTH,
    }
}

pub const INFO: TechniqueInfo = TechniqueInfo {
    name: "cube",
    summary: "cube shadow map for point lights: six 90-degree faces (reversed hardware depth, or linear light distance), seamless NxN PCF across face edges",
    cost: "six depth passes over the scene (per-face triangle culling) + N^2 fetches per pixel; 6 res^2 x 4 bytes",
    quality: "as sm per face; the face the camera looks into gets all the view samples (seed 002 Fig. 5.6)",
    source: "seed 002 section 3.3.1 and chapter 5.3 (CubeSM)",
    lights: &["point"],
    params: ParamTable::of::<CubeSettings>(),
    stalls: "",
    needs: "",
    storage_buffers: 8,
    compare: &[""],
    shaders,
    create: |gpu, scene, p, light| Ok(Box::new(CubeMap::new(gpu, scene, &CubeSettings::from_values(p), light)?)),
};

use crate::techniques::warp as w;

/// cube-notw's smoothing window (rows/columns averaged). notw's 16 bends shadow edges in the
/// room (512 x 512 view, 256 per face: 1.04 % wrong at 16, 0.65 at 128, subdiv 2); too high
/// and the warp tends to RTW's rectilinear one.
pub const DEFAULT_NOTW_WINDOW: f64 = 128.0;
/// cube-notw's subdivision threshold (warped texels): the bend a warped edge may keep, i.e. how
/// far shadow edges shift (the errors of `cube-notw` are runs of false-lit pixels along one side
/// of floor shadow edges, not seams). 1024x1024 output, 512 per face, room / courtyard lantern /
/// conference light, wrong %: with notw's n.o. 0.5 and blur 8: 1 -> 0.361 / 0.212 / 0.369,
/// 0.5 -> 0.316 / 0.204 / 0.325; with n.o. 0.25 and blur 4: 0.5 -> 0.290 / 0.171 / 0.276, 0.25
/// -> 0.271 / 0.161 / 0.263 (docs/bench/point.md). Pieces 79 k -> 164 k -> 359 k on the room, 0.26 M
/// -> 0.55 M -> 1.19 M on the courtyard. Lower: more pieces (time, capacity), higher: bent edges.
pub const DEFAULT_NOTW_SUBDIV: f64 = 0.25;
/// cube-notw's normal offset (warped texels). notw's 0.5 -> 0.25: room / courtyard lantern /
/// conference 0.361 -> 0.341 / 0.212 -> 0.201 / 0.369 -> 0.327 % wrong (the same change as
/// `dpsm-notw`'s). Low: acne (false shadow grows 0.144 -> 0.174 % on the room), high: shifted
/// shadows (false lit).
pub const DEFAULT_NOTW_NORMAL_OFFSET: f64 = 0.25;
/// cube-notw's blur of the counts (half-width, texels). notw's 8 -> 4 alone: 0.361 -> 0.357 /
/// 0.212 -> 0.209 / 0.369 -> 0.367; with subdiv 0.5 and n.o. 0.25 together the three give
/// 0.290 / 0.171 / 0.276 (docs/bench/point.md). With mix 1 (`DEFAULT_NOTW_MIX`), 4 -> 2:
/// see there (docs/bench/point_quality.md). Too high: the sampling evens out less; too low: a
/// kink per texel (more pieces).
pub const DEFAULT_NOTW_BLUR: f64 = 2.0;
/// cube-notw's uniform floor of the counts (fraction of the mean count per texel). A cube face
/// holds fairly even samples (CV 0.56-0.75 on the room's faces), so notw's floor of 2 x the mean
/// leaves the warp almost flat. Room / courtyard lantern / conference light 1, wrong %
/// (1024x1024, 512 per face, subdiv 0.25, n.o. 0.25): mix 2 blur 4 (before) 0.271 / 0.161 /
/// 0.263, mix 1 blur 2 0.239 / 0.152 / 0.248, mix 0.5 blur 2 0.241 / 0.159 / 0.249; on the room
/// mix 0 0.285, 0.25 0.264 (blur 4) (docs/bench/point_quality.md). Too low: rows with few
/// samples magnify wildly (bends); too high: the warp fades to the identity.
pub const DEFAULT_NOTW_MIX: f64 = 1.0;

/// cube-notw's bias footprint (`bias_mode`, warp::BIAS_MODE): 0 (isotropic), not `notw`'s 2.
/// Room / courtyard lantern / conference light 1, wrong % (1024x1024, 512 per face, bias 1.5):
/// mode 0 0.239 / 0.152 / 0.248, mode 2 0.568 / 1.522 / 0.393 (acne: false shadow 0.468 /
/// 1.469 / 0.266); on the room mode 2 with bias 3 0.266, 4.5 0.278, mode 1 0.240
/// (docs/bench/point_quality.md). The gradient footprint is smaller where the face projection
/// is steep, so the bias tuned with mode 0 no longer covers the depth slope there.
pub const DEFAULT_NOTW_BIAS_MODE: f64 = 0.0;

/// cube-notw smooths across functions with tent weights (`window_tent`, warp::WINDOW_TENT),
/// not the seeds' box. Chosen on the sibenik stress view (0.977 -> 0.886 % wrong; 1.92 M pieces
/// with the tent in a later run, against 4.13 M recorded for the box); checked on four views not used to choose it (512x512, default parameters
/// otherwise; wrong % box -> tent, pieces): room light 1 0.247 -> 0.223, 895 k -> 427 k;
/// courtyard lantern 0.171 -> 0.161, 4.33 M -> 1.29 M; conference light 1 0.252 -> 0.240,
/// 2.32 M -> 1.00 M; eaves light 0 0.334 -> 0.312, 8.61 M -> 5.98 M (docs/bench/stress.md).
pub const DEFAULT_NOTW_WINDOW_TENT: f64 = 1.0;

/// cube-notw's shadow-edge importance (`edge_importance`, warp::EDGE_IMPORTANCE): a view
/// sample on a shadow edge of the unwarped occluder map counts 9 instead of 1, so the faces'
/// warps give edges more texels. Chosen on room light 1 and the sibenik stress view (512x512,
/// wrong % for k = 0 / 2 / 4 / 8 / 16 / 32 / 64: room 0.223 / 0.193 / 0.176 / 0.163 / 0.146 /
/// 0.150 / 0.155; sibenik 0.886 / 0.834 / 0.817 / 0.781 / 0.793 / - / -; pieces grow with k,
/// sibenik 1.92 M at 0 to 2.79 M at 8 and 3.49 M at 16, so 8 rather than 16). Checked on three
/// views not used to choose it, k = 0 -> 8: conference light 1 0.240 -> 0.181, courtyard lantern
/// 0.161 -> 0.138, eaves light 0 0.312 -> 0.179 (eaves then fills the piece capacity on two
/// faces: flagged degraded, deterministic) (docs/bench/stress.md).
pub const DEFAULT_NOTW_EDGE_IMPORTANCE: f64 = 8.0;

/// cube-notw's depth: exact per fragment (the warp inverted, `DEFAULT_NOTW_EXACT_INVERSE`), not
/// `notw`'s interpolated depth (issue 48, step 1), with notw's former constant bias of 1.5 warped
/// texels.
/// `shadowlab tune -t 'cube-notw:exact_depth=false,subdiv=0.25|0.5,bias=1.5|2|2.5'` at 512x512
/// chose `subdiv=0.25` with bias 1.5 on room light 1 and bias 2.5 on point-courtyard, and
/// neither carried over to the view not used to choose it: conference light 1 0.182 against
/// 0.181 % wrong, sponza-peer 0.509 against 0.498 (docs/bench/warp.md). The interpolated depth
/// took 0.3-0.6x the frame there; a default only where validation agrees. Rerun after the leaner
/// analysis (step 3): 0.179 against 0.177, 0.521 against 0.512; still not.
pub const DEFAULT_NOTW_EXACT_DEPTH: f64 = 1.0;
pub const DEFAULT_NOTW_BIAS: f64 = 1.5;

/// cube-notw inverts the warp exactly per fragment (`exact_inverse`: the two 1D inversions,
/// searched from the fragment's screen-linear unwarped point), not by notw's former three
/// Newton steps. Since that search starts at the guess it costs a few texture reads instead of
/// the Newton steps' twelve warps. Chosen by the tune rule on room light 1 and point-courtyard
/// (512x512: 0.1649 / 0.1378 -> 0.1653 / 0.1373 % wrong, mean 0.1514 -> 0.1513) and checked on
/// conference light 1 and sponza-peer, not used to choose (0.1775 -> 0.1775, 0.5124 -> 0.5118:
/// no worse on 2 of 2); the frame takes 0.67-0.86x (docs/bench/warp.md, issue 48).
pub const DEFAULT_NOTW_EXACT_INVERSE: f64 = 1.0;

const CUBE_DEPTH_TUNE: &str =
    "shadowlab tune on room light 1 and point-courtyard, checked on conference light 1 and sponza-peer (docs/bench/warp.md, issue 48)";
const THREE_SETUPS: &str =
    "shadowlab measurement on the room, courtyard lantern and conference point lights (docs/bench/point.md, point_quality.md)";

shadowlab_core::param_set! {
    /// `cube-notw`'s parameters: notw's (same keys, order, ranges and docs: each face is a `notw`
    /// map), with the window, blur, mix, subdivision, normal offset, bias footprint, exact depth,
    /// bias, strength, smoothing tent and edge importance defaults measured for cube faces (tests/cube.rs
    /// checks the rows against notw's).
    pub struct CubeNotwSettings {
        pub notw: w::NotwSettings = Block::as_declared()
            .with(w::WINDOW.with_default(DEFAULT_NOTW_WINDOW, "shadowlab measurement on room's point light (docs/bench/point.md)"))
            .with(w::EXACT_INVERSE.with_default(
                DEFAULT_NOTW_EXACT_INVERSE,
                "shadowlab: chosen on room light 1 and point-courtyard, checked on conference light 1 and sponza-peer (docs/bench/warp.md, issue 48)",
            ))
            .with(w::NOTW_BLUR.with_default(DEFAULT_NOTW_BLUR, THREE_SETUPS))
            .with(w::MIX.with_default(DEFAULT_NOTW_MIX, THREE_SETUPS))
            .with(w::NOTW_SUBDIV.with_default(DEFAULT_NOTW_SUBDIV, THREE_SETUPS))
            .with(w::NORMAL_OFFSET.with_default(DEFAULT_NOTW_NORMAL_OFFSET, THREE_SETUPS))
            .with(w::BIAS_MODE.with_default(DEFAULT_NOTW_BIAS_MODE, THREE_SETUPS))
            .with(w::NOTW_EXACT.with_default(DEFAULT_NOTW_EXACT_DEPTH, CUBE_DEPTH_TUNE))
            .with(w::NOTW_BIAS.with_default(DEFAULT_NOTW_BIAS, CUBE_DEPTH_TUNE))
            // notw's strength of 0.8 was chosen on planar maps; the faces keep the full warp
            .with(w::STRENGTH)
            .with(w::WINDOW_TENT.with_default(
                DEFAULT_NOTW_WINDOW_TENT,
                "shadowlab: chosen on sibenik, checked on room, courtyard lantern, conference and eaves point lights (docs/bench/stress.md)",
            ))
            .with(w::EDGE_IMPORTANCE.with_default(
                DEFAULT_NOTW_EDGE_IMPORTANCE,
                "shadowlab: chosen on room and sibenik, checked on conference, courtyard lantern and eaves point lights (docs/bench/stress.md)",
            )),
    }
    rules {
        fn validate(&self) -> Result<(), String> {
            self.notw.validate()
        }
        fn ineffective(&self) -> Vec<(&'static str, String)> {
            self.notw.ineffective()
        }
    }
}

pub const NOTW_INFO: TechniqueInfo = TechniqueInfo {
    name: "cube-notw",
    summary: "NoTW per cube face: each face's view samples get their own desired view, count map and row/column warps",
    cost: "one pass each over the view for all faces' desired views, count maps and evaluation, one dispatch a step of notw's analysis for all faces, one subdivision of all faces' triangles (their pieces live at once); per face a warped depth pass (nothing drawn on a face without view samples); 8 w^2 bytes of warps per face",
    quality: "spreads the view samples over each face; faces with few samples gain little",
    source: "seed 002 chapter 5.3 (CubeSM w/ warping); seed 000 section 3",
    lights: &["point"],
    params: ParamTable::of::<CubeNotwSettings>(),
    stalls: "",
    needs: "11 storage buffers per shader stage (WebGPU default: 8): the GPU subdivision (with the hidden-edge pyramid)",
    storage_buffers: 11,
    compare: &[""],
    shaders,
    create: |gpu, scene, p, light| Ok(Box::new(CubeNotw::new(gpu, scene, &CubeNotwSettings::from_values(p), light)?)),
};

/// The light's position, or a clear error for other lights.
pub(crate) fn point_position(name: &str, light: &Light) -> Result<Vec3, GpuError> {
    match *light {
        Light::Point { position } => Ok(position),
        _ => Err(GpuError::Invalid(format!("{name} supports point lights only (got a {} light)", light.kind()))),
    }
}

/// WGSL `CubeFace` (depth.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct CubeFace {
    pub view_proj: [[f32; 4]; 4],
    pub light: [f32; 4],
    /// x: face index, y: near as f32 bits (depth=hardware).
    pub face: [u32; 4],
}

/// WGSL `CubeParams` (eval.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct CubeParams {
    pub position: [f32; 3],
    /// Distance normalisation (the scene's farthest point from the light).
    pub far: f32,
    pub res: f32,
    pub pcf: f32,
    /// Near plane (depth=hardware).
    pub near: f32,
    pub pad0: f32,
    /// Constant bias, slope-scaled bias, normal offset (texels), max slope: sm's `biased_point`.
    pub bias: [f32; 4],
}

/// A point light's cube shadow map: six layers of one Depth32Float array texture.
pub struct CubeMap {
    pub(crate) groups: crate::binding::GroupCache,
    res: u32,
    near: f32,
    /// `depth=hardware`: the faces hold reversed depth near / z.
    hardware: bool,
    far: f32,
    pcf: u32,
    map: wgpu::Texture,
    /// The six faces as one array view for the evaluation (made once: its bind group is kept).
    array_view: wgpu::TextureView,
    face_groups: Vec<wgpu::BindGroup>,
    depth_pipeline: wgpu::RenderPipeline,
    /// The static triangles of each face (vertex indices), culled once on the CPU.
    face_indices: Vec<(wgpu::Buffer, u32)>,
    /// Draws them without the vertex stage's per-face test.
    static_pipeline: wgpu::RenderPipeline,
    params: wgpu::Buffer,
    counts: wgpu::Buffer,
    eval_layout: wgpu::BindGroupLayout,
    /// The evaluation and its analysis variant.
    eval: crate::technique::EvalPipelines,
}

impl Technique for CubeMap {
    fn render(&mut self, _gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        self.render_faces(f, rec);
        Ok(())
    }

    counted_evaluation!();

    fn report(&mut self, gpu: &Gpu) -> TechniqueReport {
        map::report(self, gpu)
    }
}

/// A frame of `cube-notw`: one pass each for every face's desired view and count map and one
/// analysis dispatch a step (notw.rs `fit_warps`), one subdivision of every face's triangles,
/// each face's warped depth pass (notw.rs `draw_maps`), and one evaluation over every face;
/// nothing read back during the frame.
impl Technique for CubeNotw {
    fn prepare(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        self.fit_warps(gpu, f, rec)
    }

    fn render(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        self.draw_maps(gpu, f, rec)
    }

    counted_evaluation!();

    fn report(&mut self, gpu: &Gpu) -> TechniqueReport {
        self.face_report(gpu)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::techniques::warp::tests::{error, keys};

    #[test]
    fn the_tables_keep_their_keys_in_order_and_the_rules_apply() {
        assert_eq!(keys::<CubeSettings>(), ["res", "pcf", "bias", "slope_bias", "max_slope", "normal_offset", "depth"]);
        // each face is a notw map: notw's rows, twelve of them with other defaults (tests/cube.rs)
        assert_eq!(keys::<CubeNotwSettings>(), keys::<w::NotwSettings>());
        assert_eq!(keys::<CubeNotwSettings>().len(), 28);
        assert_eq!(CubeSettings::defaults().depth, FaceDepth::Hardware);
        assert_eq!(error("cube-notw:res=64"), "technique 'cube-notw': window 128 must be below res 64");
        assert!(error("cube-notw:subdiv=0,cull_hidden=true").contains("cull_hidden has no effect: subdiv=0"));
        for ok in ["cube:depth=distance,pcf=3", "cube-notw:res=256", "cube-notw:res=256,window=64,cull_hidden=true"] {
            assert_eq!(error(ok), "", "{ok}");
        }
    }
}
