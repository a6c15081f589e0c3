//! `iasm`'s construction, stages 1 and 2: the settings as the technique reads them and what is
//! derived and checked from them, the scene and the device ([`Setup`], plain data): the light
//! basis, the square's side, the chunks' light-space boxes (bounded once on the GPU, chunks.rs)
//! and, with store=atlas, the atlas layout. The errors of creation are returned here.

use glam::{Vec2, Vec3};
use shadowlab_core::light::Light;
use shadowlab_core::techniques::iasm::{self as core, Anchor, Placement, THESIS_RESOLUTIONS, TILE_COUNT};

use super::chunks::chunk_bounds;
use super::params::{IasmFit, IasmSettings, IasmStore};
use crate::scene_gpu::GpuScene;
use crate::{Gpu, GpuError};

/// store=atlas: the atlas's size and the top-left corner of each rank's square
/// (`shadowlab_core::techniques::iasm::atlas_layout`).
pub(super) struct AtlasLayout {
    pub width: u32,
    pub height: u32,
    pub slots: [[u32; 2]; TILE_COUNT],
}

pub(super) struct Setup {
    /// m and k of equation 3.1 (k 0: half the square's side).
    pub m: f32,
    pub k: f32,
    /// The fixed square's side (world units).
    pub size: f32,
    /// Texels of the sample's tile.
    pub bias: f32,
    pub normal_offset: f32,
    pub delayed: bool,
    pub snap: bool,
    pub anchor: Anchor,
    /// Triangles per culling chunk, and in the scene.
    pub chunk: u32,
    pub triangles: u32,
    pub light_dir: Vec3,
    /// The light basis at the origin: the placement until the first frame's.
    pub basis: Placement,
    /// Texels of the resolution set (the linear buffer's).
    pub texels: u64,
    /// Light-space (x, y, depth) boxes of the chunks.
    pub boxes: Vec<(Vec3, Vec3)>,
    pub atlas: Option<AtlasLayout>,
    /// fit=view: the fitted square's margin (None: the thesis's fixed rule).
    pub fit_margin: Option<f32>,
}

pub(super) fn plan(gpu: &Gpu, scene: &GpuScene, p: &IasmSettings, light: &Light) -> Result<Setup, GpuError> {
    let Light::Directional { direction } = *light else {
        return Err(GpuError::Invalid(format!("iasm supports directional lights only, not {}", light.kind())));
    };
    let texels = core::texels(&THESIS_RESOLUTIONS);
    if texels * 4 > gpu.limits.max_storage_buffer_binding_size {
        return Err(GpuError::Invalid(format!(
            "iasm: its shadow buffer needs {:.1} MiB, over this device's max_storage_buffer_binding_size of {:.1} MiB",
            (texels * 4) as f64 / (1u64 << 20) as f64,
            gpu.limits.max_storage_buffer_binding_size as f64 / (1u64 << 20) as f64
        )));
    }
    let chunk = p.chunk.max(1);
    let (right, up, dir) = core::light_basis(direction);
    let basis = Placement { right, up, dir, origin: Vec2::ZERO, size: 1.0 };
    let boxes = chunk_bounds(gpu, scene, chunk)?.into_iter().map(|(a, b)| core::light_box(&basis, a, b)).collect();
    let sb = core::light_box(&basis, scene.bounds.min, scene.bounds.max);
    let size = match p.size as f32 {
        s if s > 0.0 => s,
        _ => (sb.1.x - sb.0.x).max(sb.1.y - sb.0.y).max(1e-3),
    };
    let atlas = (p.store == IasmStore::Atlas).then(|| atlas_layout(gpu)).transpose()?;
    Ok(Setup {
        m: p.m as f32,
        k: p.k as f32,
        size,
        bias: p.bias as f32,
        normal_offset: p.normal_offset as f32,
        delayed: p.delayed,
        snap: p.snap,
        anchor: p.anchor.into(),
        chunk,
        triangles: scene.triangle_count,
        light_dir: direction,
        basis,
        texels,
        boxes,
        atlas,
        fit_margin: (p.fit == IasmFit::View).then_some(p.margin as f32),
    })
}

fn atlas_layout(gpu: &Gpu) -> Result<AtlasLayout, GpuError> {
    let (width, height, slots) =
        core::atlas_layout(&THESIS_RESOLUTIONS).ok_or_else(|| GpuError::Invalid("iasm: resolution set does not fit an atlas".into()))?;
    gpu.check_size(width, height, "iasm atlas")?;
    Ok(AtlasLayout { width, height, slots })
}
