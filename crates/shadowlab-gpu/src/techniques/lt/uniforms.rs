//! Leak tracing's structs shared with WGSL (classify.wgsl, trace.wgsl, args.wgsl), their flag
//! bits and the limits of their arrays.

use bytemuck::{Pod, Zeroable};

/// Hybrid map levels at most (cascades 0-2; a 4th cascade is ray traced, seed 004 section 4).
pub const MAX_LEVELS: usize = 3;
/// Map layers at most: a point light's six cube faces (`shadowlab_core::techniques::lt::cube_faces`).
pub const MAX_MAPS: usize = 6;

/// WGSL `Level` (classify.wgsl): one cascade or the whole map.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct LevelU {
    pub view_proj: [[f32; 4]; 4],
    /// x: world texel (per unit of light depth for spot), y/z: view depths served.
    pub info: [f32; 4],
}

/// WGSL `LtParams` (classify.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct LtParams {
    pub levels: [LevelU; MAX_MAPS],
    /// Hybrid levels (map layers).
    pub layers: f32,
    /// 1 if perspective.
    pub perspective: f32,
    pub res: f32,
    /// 1 / far.
    pub inv_far: f32,
    /// `Mode` (params.rs) as its index.
    pub technique: u32,
    /// `base` as its `Kind` (filtered/) index.
    pub base: u32,
    /// Frame index (frames with history).
    pub frame: u32,
    /// `FLAG_*`.
    pub flags: u32,
    pub min_variance: f32,
    pub esm_c: f32,
    pub evsm_c_pos: f32,
    pub evsm_c_neg: f32,
    pub moment_bias: f32,
    /// Texels (hybrid-pcf).
    pub depth_bias: f32,
    /// Texels (hybrid-pcf).
    pub normal_offset: f32,
    /// LTT: a ray where eps < s < 1 - eps.
    pub eps: f32,
    /// Reprojection test: relative depth tolerance and minimum normal cosine.
    pub depth_tol: f32,
    pub normal_cos: f32,
    /// Temporal mask bits per pixel.
    pub mask_bits: f32,
    pub pad0: f32,
}

/// WGSL `TraceParams` (trace.wgsl, args.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct TraceParams {
    pub cfg: [u32; 4],
}

pub const FLAG_RR: u32 = 1;
pub const FLAG_FULL: u32 = 2;
pub const FLAG_FORCE_ALL: u32 = 4;
pub const FLAG_HISTORY_TEST: u32 = 8;
pub const FLAG_DYNAMIC: u32 = 16;
pub const FLAG_HAS_HISTORY: u32 = 32;
pub const FLAG_POINT: u32 = 64;
