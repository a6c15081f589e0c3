//! Leak tracing's map levels: one whole-scene (or spot) map, or the hybrid cascades of a
//! directional light with the reuse of seed 004 section 3.3 (`shadowlab_core::techniques::lt::reuse_box`,
//! `reusable`): per frame the slices are fitted, each kept box is reused while it still holds
//! its slice, else replaced by the enlarged fit and its layer marked for re-rendering.

use glam::Vec3;
use shadowlab_core::scene::Bounds;
use shadowlab_core::techniques::csm::{self as cascades, CascadeBox, Fit, ViewFrustum};
use shadowlab_core::techniques::lt as leak;

use super::uniforms::{LevelU, LtParams};
use crate::technique::FrameInputs;
use crate::GpuError;

/// View depth served by the only level of a single map.
const ALL_DEPTHS: f32 = 1e30;

pub(super) struct Cascades {
    /// Total cascades (the last one ray traced).
    pub count: usize,
    pub lambda: f32,
    pub enlarge: f32,
    pub dir: Vec3,
    pub kept: Vec<Option<CascadeBox>>,
}

impl Cascades {
    /// Hybrid levels (map layers).
    pub fn levels(&self) -> usize {
        self.count - 1
    }

    /// Fits this frame's slices; returns which layers need re-rendering (their box changed),
    /// and writes the levels into `params`. `reuse` off: fresh boxes, all layers re-rendered.
    pub fn update(&mut self, f: &FrameInputs, res: u32, reuse: bool, params: &mut LtParams) -> Result<Vec<bool>, GpuError> {
        let view_proj = f.camera.view_proj(f.gbuffer.width, f.gbuffer.height);
        let frustum = ViewFrustum::from_view_proj(view_proj, f.camera.position)
            .ok_or_else(|| GpuError::Invalid("lt: the view's projection is not a perspective frustum".into()))?;
        let splits = cascades::practical_splits(frustum.near, frustum.far, self.count, self.lambda);
        let bounds: &Bounds = &f.scene.bounds;
        let mut dirty = vec![false; self.levels()];
        for l in 0..self.levels() {
            let fit = cascades::fit_cascade(&frustum, self.dir, bounds, splits[l], splits[l + 1], res, true, Fit::Sphere);
            let keep = reuse && matches!(&self.kept[l], Some(k) if leak::reusable(k, &fit));
            if !keep {
                self.kept[l] = Some(if reuse { leak::reuse_box(&fit, bounds, self.enlarge, res) } else { fit });
                dirty[l] = true;
            }
            let b = self.kept[l].as_ref().expect("set above");
            params.levels[l] = LevelU { view_proj: b.view_proj.to_cols_array_2d(), info: [b.texel, splits[l], splits[l + 1], 0.0] };
        }
        Ok(dirty)
    }
}

/// The level of a single map (whole scene or spot) with world texel `texel`.
pub(super) fn single_level(view_proj: glam::Mat4, texel: f32) -> LevelU {
    LevelU { view_proj: view_proj.to_cols_array_2d(), info: [texel, 0.0, ALL_DEPTHS, 0.0] }
}
