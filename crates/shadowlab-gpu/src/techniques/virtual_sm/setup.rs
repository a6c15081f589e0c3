//! `virtual`'s construction, stages 1 and 2: the settings checked against their rules, and
//! what is derived from them, the scene and the device ([`Setup`], plain data): the light's
//! clipmap at creation, the page table's size, the pool's shape (atlas and static pool), the
//! chunks of moving triangles. The errors of creation are returned here.

use shadowlab_core::light::Light;
use shadowlab_core::params::Auto;
use shadowlab_core::params::ParamSet;
use shadowlab_core::techniques::virtual_sm::Clipmap;

use super::bounds::chunk_count;
use super::draw::DYNAMIC_CHUNK_TRIANGLES;
use super::params::VirtualSettings;
use crate::scene_gpu::GpuScene;
use crate::{Gpu, GpuError};

/// The physical pool in page slots: the atlas (columns x rows) and the static copies' pool.
pub(super) struct Pool {
    pub cols: u32,
    pub rows: u32,
    /// Columns and rows of the static pool (rows 0: no static copies).
    pub static_cols: u32,
    pub static_rows: u32,
}

pub(super) struct Setup {
    pub light: Light,
    /// The `levels` parameter (the clipmap's levels, or a perspective map's mips at most).
    pub levels_param: u32,
    /// Level indices of the page table (a cube's: 6 x its mips).
    pub levels: u32,
    /// Levels per face, and faces (6 for a point light).
    pub mips: u32,
    pub faces: u32,
    pub virtual_res: u32,
    pub page_res: u32,
    pub extent0: f32,
    /// `resolution_bias`: a fixed bias, or `auto` (chosen per frame).
    pub lod: Auto,
    /// Texels marked around a sample: the kernel, the normal offset's sideways shift, one texel
    /// of rounding.
    pub reach: f32,
    /// The light's clipmap at creation (the light never moves): the chunks' rectangles, the
    /// uniform's fixed part.
    pub proto: Clipmap,
    pub pages_per_side: u32,
    /// Page-table entries: levels x pages per side^2.
    pub table_len: u64,
    pub pool: Pool,
    /// Triangles before the moving ones, and the chunks of the moving ones (0: nothing moves).
    pub split: u32,
    pub dynamic_chunks: u32,
}

/// Settings that break [`VirtualSettings`]'s rules are an error.
pub(super) fn plan(gpu: &Gpu, scene: &GpuScene, p: &VirtualSettings, light: &Light) -> Result<Setup, GpuError> {
    p.validate().map_err(|e| GpuError::Invalid(format!("virtual: {e}")))?;
    let (virtual_res, page_res) = (p.virtual_res, p.page_res);
    let extent0 = p.level0_extent as f32;
    // the light's projection at creation (the light never moves): chunk rectangles, levels
    let proto = Clipmap::for_light(light, &scene.bounds, scene.bounds.center(), p.levels, virtual_res, page_res, extent0);
    let pool = pool(gpu, scene, p)?;
    let pages_per_side = virtual_res / page_res;
    let split = scene.dynamic_first.min(scene.triangle_count);
    let moving = split < scene.triangle_count;
    let kernel_half = (p.pcf as f32 - 1.0) * 0.5;
    Ok(Setup {
        light: *light,
        levels_param: p.levels,
        levels: proto.levels,
        mips: proto.mips,
        faces: proto.faces(),
        virtual_res,
        page_res,
        extent0,
        lod: p.resolution_bias,
        reach: kernel_half + p.bias.normal_offset as f32 + 1.0,
        pages_per_side,
        table_len: (proto.levels * pages_per_side * pages_per_side) as u64,
        proto,
        pool,
        split,
        dynamic_chunks: if moving { chunk_count(split, scene.triangle_count, DYNAMIC_CHUNK_TRIANGLES) } else { 0 },
    })
}

/// The pool of `pool_mib`: the static copies' share first (only where something moves), the
/// atlas from the rest; an error if no page is left for the atlas.
fn pool(gpu: &Gpu, scene: &GpuScene, p: &VirtualSettings) -> Result<Pool, GpuError> {
    let page_res = p.page_res;
    let max = gpu.limits.max_texture_dimension_2d;
    let page_bytes = page_res as f64 * page_res as f64 * 4.0;
    let pool_mib = p.pool_mib;
    let static_mib = pool_mib * p.static_share;
    // the static copies come out of the pool, and only where something moves
    let moving = scene.dynamic_first < scene.triangle_count;
    let static_slots = if moving { atlas_shape((static_mib * 1048576.0 / page_bytes).floor() as u32, page_res, max) } else { (1, 0) };
    let slots = ((pool_mib * 1048576.0 - (static_slots.0 * static_slots.1) as f64 * page_bytes) / page_bytes).floor() as u32;
    let (cols, rows) = atlas_shape(slots, page_res, max);
    if rows == 0 {
        return Err(GpuError::Invalid(format!("virtual: pool_mib {pool_mib} holds no page of {page_res}^2 besides its static copies")));
    }
    Ok(Pool { cols, rows, static_cols: static_slots.0, static_rows: static_slots.1 })
}

/// An atlas of at most `slots` pages in full rows (columns, rows), each side within `max`
/// texels: a power-of-two column count around sqrt(slots) when that holds as many pages as any
/// shape can, otherwise the squarest shape that holds the most (168 slots: 14 x 12, where 16
/// columns would hold 160).
fn atlas_shape(slots: u32, page_res: u32, max: u32) -> (u32, u32) {
    let side = (max / page_res).max(1);
    let fit = |c: u32| (c, (slots / c).min(side));
    let count = |(c, r): (u32, u32)| c * r;
    let pow2 = fit(((slots as f64).sqrt().ceil() as u32).next_power_of_two().min(side).max(1));
    let most = (1..=side).map(|c| count(fit(c))).max().unwrap_or(0);
    if count(pow2) == most {
        return pow2;
    }
    (1..=side).map(fit).filter(|s| count(*s) == most).min_by_key(|(c, r)| c.abs_diff(*r)).unwrap_or(pow2)
}

#[cfg(test)]
mod tests {
    use super::atlas_shape;

    #[test]
    fn atlas_shapes_hold_as_many_pages_as_fit() {
        // the default pool (192 pages) keeps its power-of-two shape
        assert_eq!(atlas_shape(192, 128, 16384), (16, 12));
        // the pool less its static copies: 168 pages, all of them (16 columns held 160)
        let (c, r) = atlas_shape(168, 128, 16384);
        assert_eq!((c * r, c.abs_diff(r)), (168, 2));
        assert_eq!(atlas_shape(24, 128, 16384), (8, 3));
        // a prime count: the most full rows can hold (worked out by hand), within the limit
        for (slots, max, most) in [(167, 16384, 166), (167, 2048, 165), (5, 256, 4), (1, 128, 1)] {
            let (c, r) = atlas_shape(slots, 128, max);
            assert!(c * 128 <= max && r * 128 <= max, "{slots} {max}: {c} x {r}");
            assert_eq!(c * r, most, "{slots} {max}: {c} x {r}");
        }
    }
}
