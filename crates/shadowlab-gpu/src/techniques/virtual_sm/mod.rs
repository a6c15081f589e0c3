//! `virtual`: virtual (page-based) shadow maps for directional, spot and point lights, after
//! UE5's design. Directional: clipmap levels around the camera, each a virtual map of
//! `virtual_res` texels a side in pages of `page_res`. Spot: one perspective virtual map of the
//! cone with a mip chain (level k: `virtual_res / 2^k` texels a side) in the same pages. Point:
//! six such maps, one per cube face (90 degrees each), sharing the page table's list of levels
//! and the pool; a PCF kernel clamps at its face's edge (no lookup across faces). Only the pages
//! view samples need are rendered, into slots of one Depth32Float atlas (the physical pool,
//! `pool_mib`), and kept across frames while nothing moved over them. The CPU half (level
//! geometry, projections, page math, the pool) is `shadowlab_core::techniques::virtual_sm`.
//! (The folder is `virtual_sm`: `virtual` is a Rust keyword, and `vsm` is variance shadow
//! maps.) Stored depth: 0 = near; linear (directional) or post-projective (spot, as `sm`).
//!
//! Per frame: `prepare` marks the requested pages on the GPU (mark.wgsl), reads the flags and
//! per-page sample counts back (one stall, `virtual.readback`), and allocates slots on the CPU
//! in a priority order (coarse levels first, then the pages more samples read; a full pool makes
//! the finest pages fall back one level at a time, counted); `render` draws
//! the new pages, each with its own frustum (orthographic, or the spot's narrowed) into its slot, with the scene's chunks
//! culled per page; `evaluate` looks every PCF tap up through the page table (eval.wgsl).
//!
//! Static/dynamic split (UE5's): in scenes with moving geometry, a page that moving chunks lie
//! over also keeps a copy of its static geometry alone in a second, smaller atlas (the static
//! pool, `static_share` of the pool). When the moving geometry sweeps over the page again it
//! is rebuilt from that copy (copy.wgsl) plus the moving chunks, not from all its geometry.

mod bounds;
mod draw;
mod gpu;
mod params;
mod render;
mod report;

use bytemuck::{Pod, Zeroable};
pub use gpu::{VirtualShadows, CHUNK_TRIANGLES, DYNAMIC_CHUNK_TRIANGLES};
pub use params::*;
use shadowlab_core::params::{ParamSet, ParamTable};

use crate::shaders::compose_depth;
use crate::technique::{compose_view, TechniqueInfo};
use crate::techniques::cube::FACES_WGSL;

const PAGES_WGSL: &str = include_str!("pages.wgsl");
const MARK_WGSL: &str = include_str!("mark.wgsl");
const EVAL_WGSL: &str = include_str!("eval.wgsl");
const PAGE_WGSL: &str = include_str!("page.wgsl");
const COPY_WGSL: &str = include_str!("copy.wgsl");

/// Levels the uniform holds (WGSL `origins`).
pub const MAX_LEVELS: usize = 24;

pub fn shaders() -> Vec<(&'static str, String)> {
    vec![
        ("virtual_sm/mark.wgsl", mark_source()),
        ("virtual_sm/eval.wgsl", eval_source()),
        ("virtual_sm/page.wgsl", page_source()),
        ("virtual_sm/copy.wgsl", COPY_WGSL.to_string()),
    ]
}

fn mark_source() -> String {
    compose_view(&format!("{FACES_WGSL}{PAGES_WGSL}{MARK_WGSL}"), false)
}

fn eval_source() -> String {
    compose_view(&format!("{FACES_WGSL}{PAGES_WGSL}{}{EVAL_WGSL}", crate::techniques::sm::BIAS_WGSL), false)
}

fn page_source() -> String {
    compose_depth(PAGE_WGSL)
}

pub const INFO: TechniqueInfo = TechniqueInfo {
    name: "virtual",
    summary: "virtual shadow maps: clipmap levels (spot: one map's mip chain; point: six faces' chains) of 16K virtual texels in 128^2 pages; only the pages view samples need are rendered, cached across frames",
    cost: "a marking pass, one readback (a sync), per new page one atlas viewport with culled chunks; N^2 page-table lookups per pixel",
    quality: "about one texel per pixel everywhere (resolution_bias); a full pool makes fine pages fall back to coarser ones (reported)",
    source: "Epic Games, Unreal Engine 5 virtual shadow maps (2021); clipmaps: Tanner, Migdal, Jones 1998",
    lights: &["directional", "spot", "point"],
    params: ParamTable::of::<VirtualSettings>(),
    stalls: "virtual.readback: the page requests read back for the CPU allocation (every frame)",
    needs: "",
    compare: &[],
    shaders,
    create: |gpu, scene, p, light| Ok(Box::new(VirtualShadows::new(gpu, scene, &VirtualSettings::from_values(p), light)?)),
};

/// WGSL `VirtualParams` (pages.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct VirtualParams {
    /// xyz: light x axis; w: world size of a level-0 texel (spot: per unit of light depth).
    pub right: [f32; 4],
    /// xyz: light y axis; w: level-0 texels per world unit.
    pub up: [f32; 4],
    /// xyz: light direction; w: light depth of depth 0.
    pub dir: [f32; 4],
    /// x: light depth of depth 1, y: pixel angle, z: 2^resolution_bias, w: marking reach (texels).
    pub view: [f32; 4],
    /// levels, pages per side, page side, atlas columns.
    pub dims: [u32; 4],
    /// bias, slope_bias, normal_offset, max_slope.
    pub bias: [f32; 4],
    /// x: PCF width, y: projection (0 orthographic, 1 spot, 2 cube), z: mips per face, w: faces.
    pub pcf: [u32; 4],
    /// Spot, cube: xyz position, w tan(half-angle) (1 for a cube face).
    pub spot: [f32; 4],
    /// Cube: each face's right, up and travel direction (`Clipmap::axes`), 3 per face.
    pub face_axes: [[f32; 4]; 18],
    /// xy: window origins per level (pages).
    pub origins: [[i32; 4]; MAX_LEVELS],
}
