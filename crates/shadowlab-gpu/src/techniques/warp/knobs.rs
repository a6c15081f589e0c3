//! The [`Knobs`] a warped map runs with, made from the settings each variant declares
//! (settings.rs; `dpsm`'s hemispheres pass theirs field by field).

use shadowlab_core::params::family::Bias;

use super::settings::{BiasFootprint, DvSettings, NotwCore, NotwSettings, RtwSettings, Subdivision};
use super::Variant;

/// The settings a warped map runs with, made from the settings each variant declares. What a
/// variant's method does not have is fixed here ([`Knobs::fixed`]), not defaulted: RTW has no
/// smoothing window or uniform floor (its warps are 1D), NoTW no RTW importance, and the DV crop
/// (`notw-dv`, and `dpsm`'s plain paraboloids) no warp at all (subdivision only on a
/// paraboloid).
#[derive(Clone, Copy, Debug)]
pub struct Knobs {
    pub(crate) variant: Variant,
    /// Made for a hemisphere of a dual-paraboloid map ([`super::Projection::Paraboloid`]).
    pub(crate) paraboloid: bool,
    /// Cropped to the desired view.
    pub(crate) crop: bool,
    pub(crate) res: u32,
    pub(crate) pcf: u32,
    /// [`Bias::packed`]: bias, slope bias, normal offset, max slope.
    pub(crate) bias: [f32; 4],
    pub(crate) window: u32,
    pub(crate) blur: u32,
    pub(crate) mix: f32,
    pub(crate) w_dv: f32,
    pub(crate) w_eye: f32,
    pub(crate) interp: bool,
    /// Subdivision threshold (warped texels); 0 = off.
    pub(crate) subdiv: f32,
    pub(crate) subdiv_levels: u32,
    /// Pieces beyond the triangles; 0 = automatic.
    pub(crate) subdiv_capacity: u32,
    /// Smallest warped extent (texels) of an edge that is split; 0 = no bound.
    pub(crate) min_piece: f32,
    /// Planar subdivision's along-edge threshold (`depth_split`; 0 = the whole displacement).
    pub(crate) depth_split: f32,
    /// Queue levels before the tessellation (`tessellate`, tess.wgsl; 0: the queue alone).
    pub(crate) tessellate: u32,
    pub(crate) exact_depth: bool,
    pub(crate) close_cracks: bool,
    pub(crate) dv_margin: f32,
    pub(crate) strength: f32,
    pub(crate) bias_mode: u32,
    pub(crate) footprint_cap: f32,
    pub(crate) depth_clamp: u32,
    /// Exact inversion in the exact depth pass (the NoTW variants: notw, cube-notw, dpsm-notw).
    pub(crate) exact_inverse: bool,
    /// Leave hidden edges unsplit (`cull_hidden`; planar projections only).
    pub(crate) cull_hidden: bool,
    /// Tent-weighted smoothing across functions (`window_tent`, NoTW).
    pub(crate) tent: bool,
    /// Extra count of a shadow-edge sample (`edge_importance`; planar NoTW only).
    pub(crate) edge_importance: u32,
    /// Exact depth only on pieces spread more than this along the light (`exact_tol`; planar
    /// NoTW only; 0: all).
    pub(crate) exact_tol: f32,
}

impl Knobs {
    /// What every variant declares (map, lookup, bias, footprint), with everything else at the
    /// value of a method that lacks it: no smoothing, counts or RTW importance, no subdivision
    /// (1 level, automatic capacity) and so no exact depth, no DV margin, the full warp strength
    /// (there is none to scale), no hidden-edge culling, box smoothing, samples counted alone.
    #[allow(clippy::too_many_arguments)]
    fn fixed(
        variant: Variant,
        paraboloid: bool,
        crop: bool,
        res: u32,
        pcf: u32,
        bias: &Bias,
        footprint: &BiasFootprint,
        depth_clamp: u32,
    ) -> Knobs {
        Knobs {
            variant,
            paraboloid,
            crop,
            res,
            pcf,
            bias: bias.packed(),
            window: 0,
            blur: 0,
            mix: 0.0,
            w_dv: 0.0,
            w_eye: 0.0,
            interp: true,
            subdiv: 0.0,
            subdiv_levels: 1,
            subdiv_capacity: 0,
            min_piece: 0.0,
            depth_split: 0.0,
            tessellate: 0,
            exact_depth: false,
            close_cracks: false,
            dv_margin: 0.0,
            strength: 1.0,
            bias_mode: footprint.bias_mode,
            footprint_cap: footprint.footprint_cap,
            depth_clamp,
            exact_inverse: false,
            cull_hidden: false,
            tent: false,
            edge_importance: 0,
            exact_tol: 0.0,
        }
    }

    /// With `s`'s subdivision and `exact_depth` (which subdivision makes available).
    fn subdividing(self, s: &Subdivision, exact_depth: bool) -> Knobs {
        Knobs {
            subdiv: s.subdiv,
            subdiv_levels: s.subdiv_levels,
            subdiv_capacity: s.subdiv_capacity,
            min_piece: s.min_piece,
            depth_split: s.depth_split,
            tessellate: s.tessellate,
            exact_depth,
            ..self
        }
    }

    /// NoTW's block on a planar map or a paraboloid hemisphere, cropped to the desired view.
    fn notw_core(c: &NotwCore, res: u32, paraboloid: bool, tent: bool) -> Knobs {
        Knobs {
            window: c.window,
            blur: c.blur,
            mix: c.mix,
            interp: c.interp,
            close_cracks: c.close_cracks,
            dv_margin: c.dv_margin,
            strength: c.strength,
            exact_inverse: c.exact_inverse,
            tent,
            ..Knobs::fixed(Variant::Notw, paraboloid, true, res, c.pcf, &c.bias, &c.footprint, c.depth_clamp)
                .subdividing(&c.subdivision, c.exact_depth)
        }
    }

    /// `rtw`: planar, cropped; no smoothing window, uniform floor or NoTW options.
    pub fn rtw(s: &RtwSettings) -> Knobs {
        Knobs {
            blur: s.blur,
            w_dv: s.w_dv,
            w_eye: s.w_eye,
            interp: s.interp,
            close_cracks: s.close_cracks,
            dv_margin: s.dv_margin,
            strength: s.strength,
            ..Knobs::fixed(Variant::Rtw, false, true, s.res, s.pcf, &s.bias, &s.footprint, s.depth_clamp)
                .subdividing(&s.subdivision, s.exact_depth)
        }
    }

    /// `notw` (and each face of `cube-notw`): planar, cropped, every NoTW option.
    pub fn notw(s: &NotwSettings) -> Knobs {
        let k = Knobs::notw_core(&s.core, s.res, false, s.window_tent);
        Knobs { cull_hidden: k.subdiv > 0.0 && s.cull_hidden, edge_importance: s.edge_importance, exact_tol: s.exact_tol, ..k }
    }

    /// `notw-dv`: planar, cropped, no warp and no subdivision.
    pub fn dv(s: &DvSettings) -> Knobs {
        Knobs { dv_margin: s.dv_margin, ..Knobs::fixed(Variant::Dv, false, true, s.res, s.pcf, &s.bias, &BiasFootprint::unwarped(), 0) }
    }

    /// A hemisphere of `dpsm` (its settings: map side, lookup and bias, subdivision, exact
    /// depth): the plain paraboloid map (no crop, no warp), subdivided.
    pub fn dpsm(res: u32, pcf: u32, bias: &Bias, subdivision: &Subdivision, exact_depth: bool) -> Knobs {
        Knobs::fixed(Variant::Dv, true, false, res, pcf, bias, &BiasFootprint::unwarped(), 0).subdividing(subdivision, exact_depth)
    }

    /// A hemisphere of `dpsm-notw` (its settings: NoTW's block, map side, `window_tent`): NoTW
    /// on the paraboloid map, cropped (no hidden-edge culling or edge importance: those need a
    /// planar occluder map).
    pub fn dpsm_notw(core: &NotwCore, res: u32, tent: bool) -> Knobs {
        Knobs::notw_core(core, res, true, tent)
    }
}

#[cfg(test)]
mod tests {
    use shadowlab_core::params::ParamSet;

    use super::*;
    use crate::techniques::warp::tests::error;

    #[test]
    fn knobs_fix_what_a_variant_lacks() {
        let dv = Knobs::dv(&DvSettings::defaults());
        assert_eq!((dv.variant, dv.crop, dv.paraboloid), (Variant::Dv, true, false));
        assert_eq!((dv.subdiv, dv.subdiv_levels, dv.exact_depth, dv.strength, dv.interp), (0.0, 1, false, 1.0, true));
        let rtw = Knobs::rtw(&RtwSettings::defaults());
        assert_eq!((rtw.window, rtw.mix, rtw.exact_inverse, rtw.tent, rtw.edge_importance), (0, 0.0, false, false, 0));
        // hidden-edge culling only with subdivision
        let mut s = NotwSettings::defaults();
        s.cull_hidden = true;
        assert!(Knobs::notw(&s).cull_hidden);
        assert_eq!(Knobs::notw(&s).bias, [crate::techniques::warp::DEFAULT_NOTW_BIAS as f32, 0.0, 0.5, 4.0]);
        s.core.subdivision.subdiv = 0.0;
        assert!(!Knobs::notw(&s).cull_hidden);
        // "off" is judged in the uniform's precision, by the rules as by the knobs
        assert!(error("notw:subdiv=1e-50,cull_hidden=true").contains("cull_hidden has no effect"));
    }
}
