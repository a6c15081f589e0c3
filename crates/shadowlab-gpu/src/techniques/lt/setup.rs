//! Leak tracing's construction, stages 1 and 2: what a [`Variant`] declares, read into one
//! shape ([`Read`]), and the checked plan ([`Setup`], plain data): the map side and levels (cube
//! faces or cascades), the temporal mask's bits and the first values of both uniforms. The
//! errors of creation are returned here.

use bytemuck::Zeroable;
use shadowlab_core::light::Light;
use shadowlab_core::lightspace::{self, LightProjection};
use shadowlab_core::techniques::lt as leak;

use super::cascade::{single_level, Cascades};
use super::params::{LtSettings, MapLevels, Mode, Moments, Variant};
use super::uniforms::{LevelU, LtParams, MAX_MAPS};
use super::uniforms::{FLAG_FORCE_ALL, FLAG_FULL, FLAG_HISTORY_TEST, FLAG_POINT, FLAG_RR};
use crate::scene_gpu::GpuScene;
use crate::techniques::filtered::{FilteredParams, Kind};
use crate::{Gpu, GpuError};

/// Lights per technique instance (the lab runs one instance per light).
const LIGHTS: usize = 1;

/// Stage 1: a variant's settings in one shape. What a mode does not declare is absent (params.rs:
/// lt all; ltt no temporal mask (rr, full, history_test, depth_tol, normal_cos); hybrid-pcf no
/// filterable base (base, eps, the moment shape) but the PCF bias). The shader reads no slot a
/// mode leaves at 0.
pub(super) struct Read<'a> {
    pub mode: Mode,
    pub map: &'a MapLevels,
    pub reuse: bool,
    pub force_all: bool,
    /// lt, ltt: the base, LTT's eps, the moment shape.
    pub filterable: Option<(Kind, f64, &'a Moments)>,
    /// lt: the temporal mask.
    pub temporal: Option<&'a LtSettings>,
    /// hybrid-pcf: constant bias and normal offset (texels); 0 otherwise.
    pub pcf_bias: (f64, f64),
}

pub(super) fn read(variant: &Variant) -> Read<'_> {
    let (map, reuse, force_all) = match variant {
        Variant::Lt(s) => (&s.map, s.reuse, s.force_all),
        Variant::Ltt(s) => (&s.map, s.reuse, s.force_all),
        Variant::HybridPcf(s) => (&s.map, s.reuse, s.force_all),
    };
    let filterable = match variant {
        Variant::Lt(s) => Some((s.base, s.eps, &s.moments)),
        Variant::Ltt(s) => Some((s.base, s.eps, &s.moments)),
        Variant::HybridPcf(_) => None,
    };
    let temporal = match variant {
        Variant::Lt(s) => Some(s),
        _ => None,
    };
    let pcf_bias = match variant {
        Variant::HybridPcf(s) => (s.bias, s.normal_offset),
        _ => (0.0, 0.0),
    };
    Read { mode: variant.mode(), map, reuse, force_all, filterable, temporal, pcf_bias }
}

/// Stage 2: the checked plan.
pub(super) struct Setup {
    pub mode: Mode,
    /// Map side (texels).
    pub res: u32,
    pub reuse: bool,
    /// Map layers: the hybrid cascades, a point light's six faces, or one.
    pub levels: usize,
    /// Temporal mask bits per pixel.
    pub mask_bits: u32,
    /// The scene has moving triangles: a dynamic map beside the static one.
    pub dynamic: bool,
    pub cascades: Option<Cascades>,
    /// classify.wgsl's uniform at creation (`prepare` moves the cascades' levels, `evaluate`
    /// adds the frame and its flags).
    pub params: LtParams,
    /// The map raster's uniform (filtered/'s render.wgsl in single-depth mode), level 0's.
    pub map_params: FilteredParams,
}

/// Where the maps look from: level 0's projection (a point light's +x face), the cube faces,
/// and 1 / far (0 for a directional light).
struct Projection {
    lp: LightProjection,
    faces: Option<[LightProjection; 6]>,
    inv_far: f32,
}

pub(super) fn plan(gpu: &Gpu, scene: &GpuScene, s: &Read, light: &Light) -> Result<Setup, GpuError> {
    let res = s.map.res;
    gpu.check_size(res, res, "shadow map")?;
    let proj = project(scene, s.mode.name(), res, light)?;
    let mask_bits = leak::mask_texel_bits(LIGHTS).map_err(GpuError::Invalid)?;
    let cascades = match *light {
        Light::Directional { direction } if s.map.cascades > 1 => Some(Cascades {
            count: s.map.cascades as usize,
            lambda: s.map.lambda as f32,
            enlarge: s.map.enlarge as f32,
            dir: direction,
            kept: vec![None; s.map.cascades as usize - 1],
        }),
        _ => None,
    };
    let levels = if proj.faces.is_some() { 6 } else { cascades.as_ref().map_or(1, |c| c.levels()) };
    Ok(Setup {
        mode: s.mode,
        res,
        reuse: s.reuse,
        levels,
        mask_bits,
        dynamic: scene.dynamic_first < scene.triangle_count,
        cascades,
        params: lt_params(s, &proj, res, levels, mask_bits),
        map_params: map_params(s, &proj, res),
    })
}

fn project(scene: &GpuScene, name: &str, res: u32, light: &Light) -> Result<Projection, GpuError> {
    // point: six cube faces, one layer each (level 0 = the +x face stands for all below)
    let faces = match *light {
        Light::Point { position } => Some(leak::cube_faces(position, &scene.bounds, res)),
        _ => None,
    };
    let lp = match &faces {
        Some(f) => f[0],
        None => lightspace::fit(light, &scene.bounds, res)
            .ok_or_else(|| GpuError::Invalid(format!("{name}: unsupported light ({})", light.kind())))?,
    };
    let inv_far = match *light {
        Light::Spot { position, .. } | Light::Point { position } => {
            let far = scene.bounds.corners().iter().map(|c| (*c - position).length()).fold(0.0f32, f32::max);
            1.0 / far.max(1e-6)
        }
        _ => 0.0,
    };
    Ok(Projection { lp, faces, inv_far })
}

/// The moment shape as the shaders read it (min_variance, c, c_pos, c_neg, moment_bias); 0 without a filterable base.
fn moments(s: &Read) -> (f32, f32, f32, f32, f32) {
    s.filterable.map_or((0.0, 0.0, 0.0, 0.0, 0.0), |(_, _, m)| {
        (m.min_variance as f32, m.c as f32, m.c_pos as f32, m.c_neg as f32, m.moment_bias as f32)
    })
}

fn lt_params(s: &Read, proj: &Projection, res: u32, levels: usize, mask_bits: u32) -> LtParams {
    let flag = |on: bool, bit: u32| if on { bit } else { 0 };
    let flags = s.temporal.map_or(0, |t| flag(t.rr, FLAG_RR) | flag(t.full, FLAG_FULL) | flag(t.history_test, FLAG_HISTORY_TEST))
        | flag(s.force_all, FLAG_FORCE_ALL)
        | flag(proj.faces.is_some(), FLAG_POINT);
    let (bias, normal_offset) = s.pcf_bias;
    let (min_variance, esm_c, evsm_c_pos, evsm_c_neg, moment_bias) = moments(s);
    let (depth_tol, normal_cos) = s.temporal.map_or((0.0, 0.0), |t| (t.depth_tol as f32, t.normal_cos as f32));
    let mut level_u = [LevelU::zeroed(); MAX_MAPS];
    level_u[0] = single_level(proj.lp.view_proj, proj.lp.texel);
    for (l, f) in proj.faces.iter().flatten().enumerate() {
        level_u[l] = single_level(f.view_proj, f.texel);
    }
    LtParams {
        levels: level_u,
        layers: levels as f32,
        perspective: proj.lp.perspective as u32 as f32,
        res: res as f32,
        inv_far: proj.inv_far,
        technique: s.mode as u32,
        base: s.filterable.map_or(0, |(base, _, _)| base.index() as u32),
        frame: 0,
        flags,
        min_variance,
        esm_c,
        evsm_c_pos,
        evsm_c_neg,
        moment_bias,
        depth_bias: bias as f32,
        normal_offset: normal_offset as f32,
        eps: s.filterable.map_or(0.0, |(_, eps, _)| eps as f32),
        depth_tol,
        normal_cos,
        mask_bits: mask_bits as f32,
        pad0: 0.0,
    }
}

/// The raster of filtered/ in single-depth mode: linear depth into an R32Float target.
fn map_params(s: &Read, proj: &Projection, res: u32) -> FilteredParams {
    let (min_variance, esm_c, evsm_c_pos, evsm_c_neg, _) = moments(s);
    FilteredParams {
        light_view_proj: proj.lp.view_proj.to_cols_array_2d(),
        texel_world: proj.lp.texel,
        perspective: proj.lp.perspective as u32 as f32,
        res: res as f32,
        inv_far: proj.inv_far,
        kind: 0,
        single_depth: 1,
        mip_levels: 1,
        min_variance,
        esm_c,
        evsm_c_pos,
        evsm_c_neg,
        ..FilteredParams::zeroed()
    }
}
