//! `iasm`'s parameter table and its choices (`anchor`, `store`, `fit`).

use shadowlab_core::params::family;
use shadowlab_core::params::ParamDef;
use shadowlab_core::techniques::iasm::Anchor;

/// m of equation 3.1: a sample at the camera weighs 1 + m, one at w >= k weighs 1. The thesis
/// gives no value. Too low: the ranking follows sample counts (wide far tiles win); too high:
/// a few near pixels outrank a whole tile of mid-distance ground.
pub const DEFAULT_M: f64 = 4.0;
/// k of equation 3.1 in world units; 0 = half the light square's side (the distance from the
/// camera to the square's centre). The thesis gives no value. Too low: every sample beyond k
/// weighs the same; too high: distance hardly matters.
pub const DEFAULT_K: f64 = 0.0;
/// Square side in world units; 0 = the scene bounds' extent across the light (thesis 5: "the
/// frustum sides have been empirically chosen to encompass all geometry in the scene").
/// Too small: geometry ahead falls outside (lit); too large: coarse tiles.
pub const DEFAULT_SIZE: f64 = 0.0;
/// Constant bias in texels of the tile (as `sm`); 0.5 from `sm`'s sweep.
pub const DEFAULT_BIAS: f64 = family::DEFAULT_BIAS;
/// Normal offset in texels of the tile (as `sm`); 0.5 from `sm`'s sweep; low: acne at grazing
/// light, high: shifted shadows.
pub const DEFAULT_NORMAL_OFFSET: f64 = family::DEFAULT_NORMAL_OFFSET;
/// Where the tiles' depth lives: 0 = buffer (the thesis's linear storage buffer, exactly the
/// set's 6,860,800 bytes, fragments write by atomic max: no early depth test), 1 = atlas (the
/// same tiles in a 2048 x 1024 Depth32Float atlas, 8,388,608 bytes, hardware depth test). The
/// atlas rendered the tiles 1.4-3x faster on every measured setup (lavapipe, 2026-11-22,
/// docs/bench/iasm.md), so it is the default, as issue 6 asks; results are the same.
pub const DEFAULT_STORE: f64 = 1.0;
/// Triangles per culling chunk (vertex order). Small: many draw calls and CPU culling work;
/// large: loose bounds that pass every tile (the thesis's village worst case).
pub const DEFAULT_CHUNK: f64 = 256.0;
/// How the square is placed: 0 = fixed (the thesis's rule: ahead of the camera, side `size`),
/// 1 = view (fitted to the light-space bounds of the evaluated samples, thesis 3.2 / ch. 5's
/// suggestion; `size` and `anchor` unused). View is the default: chosen on courtyard and
/// city_corner (0.20 / 0.12 % wrong against fixed's 0.35 / 1.74 at 1024x1024) and better than
/// fixed on all four held-out views (city, sponza, warp-courtyard, foliage; BENCHMARKS.md
/// "Issue 18: iasm fitted to the view").
pub const DEFAULT_FIT: usize = 1;
/// `fit=view`: fraction of the samples' larger light-space extent added on each side of the
/// square (the side always holds two extra coarsest texels for snapping and the normal offset).
/// Low: a sample the camera moves out of a delayed fit is lit; high: coarser tiles. 0.05 was
/// the best of 0, 0.01, 0.02, 0.05, 0.1, 0.2 on courtyard + city_corner (mean 0.163 % wrong);
/// the wrong % is not monotonic in it (where the tile borders fall moves with the side).
pub const DEFAULT_MARGIN: f64 = 0.05;

shadowlab_core::param_choice! {
    /// `anchor`: where the camera sits on the fixed square (`shadowlab_core::techniques::iasm::Anchor`).
    pub enum IasmAnchor { Circle = "circle", Tile = "tile" }
}

impl From<IasmAnchor> for Anchor {
    fn from(a: IasmAnchor) -> Anchor {
        match a {
            IasmAnchor::Circle => Anchor::Circle,
            IasmAnchor::Tile => Anchor::TileCentre,
        }
    }
}

shadowlab_core::param_choice! {
    /// `store`: where the tiles' depth lives (see [`DEFAULT_STORE`]).
    pub enum IasmStore { Buffer = "buffer", Atlas = "atlas" }
}

shadowlab_core::param_choice! {
    /// `fit`: how the square is placed (see [`DEFAULT_FIT`]).
    pub enum IasmFit { Fixed = "fixed", View = "view" }
}

shadowlab_core::param_set! {
    /// `iasm`'s parameters.
    pub struct IasmSettings {
        pub m: f64 = ParamDef::number("m", DEFAULT_M, 0.0, 1000.0, "importance weight of near samples, p = 1 + m clamp(1 - w/k, 0, 1)", "seed 001 eq. 3.1 (no value given; shadowlab choice)"),
        pub k: f64 = ParamDef::number("k", DEFAULT_K, 0.0, 1e6, "importance range (world units); 0 = half the light square's side", "seed 001 eq. 3.1 (no value given; shadowlab choice)"),
        pub size: f64 = ParamDef::number("size", DEFAULT_SIZE, 0.0, 1e6, "side of the light square (world units); 0 = scene extent across the light", "seed 001 ch. 5: sides chosen to encompass all geometry"),
        pub bias: f64 = family::BIAS.with_doc("constant depth bias, texels of the sample's tile; low: acne, high: peter-panning"),
        pub normal_offset: f64 = family::NORMAL_OFFSET.with_doc("offset along the normal, texels of the sample's tile"),
        pub delayed: bool = ParamDef::flag("delayed", false, "use the previous frame's importance and near/far planes (no readback stall)", "seed 001 4.3, deferred delayed IASM"),
        pub snap: bool = ParamDef::flag("snap", true, "move the square in steps of the coarsest texel (tile/16) so texel grids do not shimmer", "shadowlab addition (not in seed 001)"),
        pub anchor: IasmAnchor = ParamDef::choice("anchor", IasmAnchor::NAMES, 0, "circle: camera on the inscribed circle (Fig. 3.1); tile: then shifted so the camera sits at a tile centre (no four-tile corner at the camera)", "seed 001 3.2 / ch. 5 suggested fix"),
        pub store: IasmStore = ParamDef::choice("store", IasmStore::NAMES, DEFAULT_STORE as usize, "buffer: one storage buffer, linear per-tile layout, atomic-max depth writes (thesis 3.5, exactly the set's texels); atlas: the tiles in a 2 r0 x r0 Depth32Float atlas, hardware depth test (conventional)", "seed 001 3.2/3.5; default = the faster on lavapipe (docs/bench/iasm.md)"),
        pub fit: IasmFit = ParamDef::choice("fit", IasmFit::NAMES, DEFAULT_FIT, "fixed: the thesis's square of side `size` ahead of the camera (Fig. 3.1); view: centred on and sized to the light-space bounds of the evaluated view samples (one more reduction and a one-thread placement on the GPU, read back with the statistics; `size`, `anchor` unused)", "seed 001 3.2 / ch. 5 (suggested: fit the frustum to the view); reduction from sdsm (Lauritzen et al. 2011)"),
        pub margin: f64 = ParamDef::number("margin", DEFAULT_MARGIN, 0.0, 1.0, "fit=view: fraction of the samples' extent added on each side of the square", "shadowlab choice (BENCHMARKS.md, issue 18)"),
        pub chunk: u32 = ParamDef::integer("chunk", DEFAULT_CHUNK, 1.0, 1e7, "triangles per culling chunk (vertex order)", "shadowlab choice; seed 001 4.3: culling decides the cost"),
    }
    rules {
        // (with fit=view, `size` and `anchor` still place the square of a frame without
        // evaluated samples, and `size` bounds the fitted side from below: not listed)
        fn ineffective(&self) -> Vec<(&'static str, String)> {
            let mut v = Vec::new();
            if self.m == 0.0 {
                v.push(("k", "it shapes the weight of near samples, and m=0 weighs every sample 1".to_string()));
            }
            if self.fit == IasmFit::Fixed {
                v.push(("margin", "it widens the square fitted to the view, and fit=fixed places the thesis's square".to_string()));
            }
            v
        }
    }
}

#[cfg(test)]
mod tests {
    use shadowlab_core::params::ParamSet;

    use super::*;
    use crate::registry::testing::{err, ok};

    #[test]
    fn iasm_lists_its_keys_as_before_and_reads_them_typed() {
        let keys: Vec<_> = IasmSettings::defs().iter().map(|d| d.key).collect();
        assert_eq!(keys, ["m", "k", "size", "bias", "normal_offset", "delayed", "snap", "anchor", "store", "fit", "margin", "chunk"]);
        let d = IasmSettings::defaults();
        assert_eq!((d.store, d.fit, d.anchor, d.margin, d.chunk), (IasmStore::Atlas, IasmFit::View, IasmAnchor::Circle, 0.05, 256));
        let s = IasmSettings::from_values(&ok("iasm:fit=fixed,size=200,anchor=tile,store=buffer").values);
        assert_eq!((s.fit, s.size, Anchor::from(s.anchor), s.store), (IasmFit::Fixed, 200.0, Anchor::TileCentre, IasmStore::Buffer));
    }

    #[test]
    fn iasm_rejects_keys_without_effect() {
        let e = err("iasm:fit=fixed,margin=0.1");
        assert!(e.contains("technique 'iasm': margin has no effect"), "{e}");
        ok("iasm:fit=view,margin=0.1");
        ok("iasm:margin=0.1");
        assert!(err("iasm:m=0,k=3").contains("k has no effect"));
        ok("iasm:m=2,k=3");
        // size and anchor still place a fitted square's frames without samples
        ok("iasm:fit=view,size=200,anchor=tile");
    }
}
