//! `virtual`'s parameter table: the page geometry of UE5's virtual shadow maps, the pool, and
//! `sm`'s PCF and bias family (biases in texels of the level a sample uses).

use shadowlab_core::params::family::{Bias, PCF};
use shadowlab_core::params::{Auto, Block, ParamDef};

/// Virtual texels per level side: UE5's 16K virtual maps. Lower: coarser levels sooner (more
/// levels needed); higher: more pages per level (bigger page table and request buffer).
pub const DEFAULT_VIRTUAL_RES: f64 = 16384.0;
/// Page side: UE5's 128 x 128 pages. Smaller pages waste less pool on partly used pages but
/// need more draws; larger pages fewer draws, more waste.
pub const DEFAULT_PAGE_RES: f64 = 128.0;
/// Clipmap levels: enough that the coarsest one covers any scene at the default level-0
/// extent (2^15 x 1.28 m). Too few: distant samples clamp to a too-fine level whose window
/// does not hold them (lit).
pub const DEFAULT_LEVELS: f64 = 16.0;
/// World side of level 0: UE5's first clipmap level 6 (radius 2^6 cm, so 1.28 m across) in
/// scene units taken as metres. Too large: near samples get coarser texels than their pixels.
pub const DEFAULT_LEVEL0_EXTENT: f64 = 1.28;
// Resolution (LOD) bias: `auto` by default, the finest bias from -1.5 (the best fixed setting
// measured under suns at equal memory) whose pages fit the pool, chosen per frame
// (shadowlab_core::techniques::virtual_sm::AutoLod). A number: 0 = the level whose texel is the
// first at least as large as the pixel's footprint; negative: finer (more pages); positive:
// coarser; a pool it overfills falls back level by level (flagged degraded).
/// Physical pool: 12 MiB, the memory of `csm`'s default 3 x 1024^2 maps (issue 17's
/// equal-memory comparison): 192 pages of 128^2.
pub const DEFAULT_POOL_MIB: f64 = 12.0;
/// Share of the pool for the static copies of pages under moving geometry (UE5's
/// static/dynamic split): such a page is rebuilt from its copy plus the moving chunks instead of
/// from all its geometry. Only scenes with moving geometry take it from the pool (1/8: 24 of
/// the default 192 pages). 0: no copies (every invalidated page is drawn whole). Larger: fewer
/// pages drawn whole on long paths, fewer pages for the view.
pub const DEFAULT_STATIC_SHARE: f64 = 0.125;

shadowlab_core::param_set! {
    /// `virtual`'s parameters.
    pub struct VirtualSettings {
        pub virtual_res: u32 = ParamDef::integer(
            "virtual_res",
            DEFAULT_VIRTUAL_RES,
            256.0,
            65536.0,
            "virtual texels per clipmap level side (a multiple of page_res)",
            "UE5 virtual shadow maps: 16K",
        ),
        pub page_res: u32 = ParamDef::integer("page_res", DEFAULT_PAGE_RES, 16.0, 8192.0, "page side in texels (a power of two)", "UE5 virtual shadow maps: 128"),
        pub levels: u32 = ParamDef::integer(
            "levels",
            DEFAULT_LEVELS,
            1.0,
            24.0,
            "clipmap levels; level k covers 2^k x level0_extent (spot: mip levels of the one map, at most down to one page)",
            "shadowlab: covers 42 km at the default extent",
        ),
        pub level0_extent: f64 = ParamDef::number(
            "level0_extent",
            DEFAULT_LEVEL0_EXTENT,
            1e-4,
            1e6,
            "world side of clipmap level 0 (scene units; directional lights only)",
            "UE5 r.Shadow.Virtual.Clipmap.FirstLevel = 6 (radius 2^6 cm)",
        ),
        pub resolution_bias: Auto = ParamDef::auto_number(
            "resolution_bias",
            -8.0,
            8.0,
            "level = ceil(log2(pixel footprint / level-0 texel at the sample) + bias); negative: finer texels, more pages; auto: the finest bias from -1.5 in quarter steps (up to +2) whose pages fit the pool, chosen per frame (marking again when they do not), with hysteresis",
            "UE5 r.Shadow.Virtual.ResolutionLodBiasDirectional and DynamicRes (pool budget); auto's start -1.5: shadowlab, docs/bench/virtual.md",
        ),
        pub pool_mib: f64 = ParamDef::number(
            "pool_mib",
            DEFAULT_POOL_MIB,
            0.0625,
            2048.0,
            "physical page pool (MiB of Depth32Float pages)",
            "csm's 3 x 1024^2 (issue 17)",
        ),
        pub static_share: f64 = ParamDef::number(
            "static_share",
            DEFAULT_STATIC_SHARE,
            0.0,
            0.9,
            "share of pool_mib for static copies of pages under moving geometry (scenes with moving geometry only; 0: none)",
            "UE5 static/dynamic page split (r.Shadow.Virtual.Cache.StaticSeparate); share: shadowlab",
        ),
        pub pcf: u32 = PCF,
        pub bias: Bias = Block::as_declared(),
    }
    rules {
        /// Pages tile each level exactly.
        fn validate(&self) -> Result<(), String> {
            let (page_res, virtual_res) = (self.page_res, self.virtual_res);
            if !page_res.is_power_of_two() || virtual_res % page_res != 0 {
                return Err(format!("page_res {page_res} must be a power of two dividing virtual_res {virtual_res}"));
            }
            Ok(())
        }

        fn ineffective(&self) -> Vec<(&'static str, String)> {
            if self.bias.slope_bias == 0.0 && self.pcf == 1 {
                vec![("max_slope", "it clamps the slope bias and the PCF kernel's bias, and slope_bias=0 with pcf=1 has neither".to_string())]
            } else {
                Vec::new()
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use shadowlab_core::params::ParamSet;

    use super::*;
    use crate::registry::testing::{err, ok};

    #[test]
    fn virtual_lists_its_keys_as_before_and_reads_them_typed() {
        let keys: Vec<_> = VirtualSettings::defs().iter().map(|d| d.key).collect();
        assert_eq!(
            keys,
            [
                "virtual_res",
                "page_res",
                "levels",
                "level0_extent",
                "resolution_bias",
                "pool_mib",
                "static_share",
                "pcf",
                "bias",
                "slope_bias",
                "max_slope",
                "normal_offset"
            ]
        );
        let s = VirtualSettings::from_values(&ok("virtual:pool_mib=64,static_share=0,pcf=3,slope_bias=1").values);
        assert_eq!((s.pool_mib, s.static_share, s.pcf, s.virtual_res, s.page_res), (64.0, 0.0, 3, 16384, 128));
        assert_eq!(s.bias.packed(), [0.5, 1.0, 0.5, 4.0]);
    }

    #[test]
    fn virtual_checks_its_pages_and_rejects_keys_without_effect() {
        let e = err("virtual:page_res=96");
        assert!(e.contains("technique 'virtual': page_res 96 must be a power of two dividing virtual_res 16384"), "{e}");
        assert!(err("virtual:virtual_res=1000,page_res=64").contains("page_res 64 must be a power of two dividing virtual_res 1000"));
        ok("virtual:virtual_res=2048,page_res=64");
        assert!(err("virtual:max_slope=2").contains("max_slope has no effect"));
        ok("virtual:pcf=3,max_slope=2");
        ok("virtual:slope_bias=0.5,max_slope=2");
    }
}
