//! `sdsm`: sample distribution shadow maps (Lauritzen, Salvi and Lefohn, I3D 2011) on `csm`'s
//! maps, depth pass, evaluation and report (a [`Cascaded`] of techniques/csm). What it adds
//! (fit.rs): the G-buffer's [min, max] view depth (the shared min/max reduction), then csm's
//! sample-bounds reduction (`csm/sdsm_bounds.wgsl`) that splits that range logarithmically and
//! reduces, per cascade, the light-space x/y/z bounds of the samples the evaluation will look up
//! in it; the CPU fits each cascade's box to those bounds (`shadowlab_core::techniques::sdsm`).
//! Both reductions run in one stage and are read back with one sync (`sdsm.readback`), or, with
//! `delayed`, the previous frame's are read without one (frame 0: the frustum-slice fit,
//! `csm`'s box fit of the log splits of the camera's range).

mod fit;

use shadowlab_core::light::Light;
use shadowlab_core::params::{Block, ParamDef, ParamSet, ParamTable};
use shadowlab_core::techniques::sdsm as cpu;

use crate::record::Recorder;
use crate::scene_gpu::GpuScene;
use crate::technique::{FrameInputs, Technique, TechniqueInfo, TechniqueReport};
use crate::techniques::csm::{self, CascadeLookup, CascadeMaps, Cascaded, Shared, BLEND, ONE_CASCADE_BLEND, SDSM_BOUNDS_BYTES};
use crate::{Gpu, GpuError};
use fit::SampleFit;

fn shaders() -> Vec<(&'static str, String)> {
    let mut v = csm::shaders();
    v.push(("csm/sdsm_bounds.wgsl", csm::bounds_source()));
    v
}

pub const INFO: TechniqueInfo = TechniqueInfo {
    name: "sdsm",
    summary: "sample distribution shadow maps: cascades split logarithmically between the view samples' min and max depth, each box fitted to the light-space bounds of its own samples",
    cost: "two G-buffer reductions (depth range; per-cascade light-space bounds) and one 320-byte readback (a sync; none when delayed), one scene pass per cascade, N^2 fetches per pixel",
    quality: "texels only where view samples are: finer than csm's slice fits, most where the view sees little of each slice; snapped sizes barely shimmer; delayed lags one frame",
    source: "Lauritzen, Salvi, Lefohn 2011 (I3D, sample distribution shadow maps); csm (Engel 2006) for the rest",
    lights: &["directional"],
    params: ParamTable::of::<SdsmSettings>(),
    stalls: "with delayed=false (default): sdsm.readback, the depth range, splits and per-cascade sample bounds read back before the fit; delayed=true (the previous frame's, frame 0 the frustum-slice fit) records without a stall",
    needs: "",
    storage_buffers: 8,
    // not in the default compare set (its cost is csm's, but the set's time is documented)
    compare: &[""],
    shaders,
    create: |gpu, scene, p, light| Ok(Box::new(Sdsm::new(gpu, scene, &SdsmSettings::from_values(p), light)?)),
};

shadowlab_core::param_set! {
    /// `sdsm`'s parameters: `csm`'s maps and lookup, with the samples' split blend and the
    /// delayed fit's reach.
    pub struct SdsmSettings {
        pub maps: CascadeMaps = Block::as_declared(),
        pub lambda: f64 = ParamDef::number("lambda", cpu::DEFAULT_LAMBDA as f64, 0.0, 1.0, "split blend between the samples' min and max depth: 1 logarithmic, 0 uniform; low: coarse near cascade", "Lauritzen et al. 2011 section 3.1 (log partitioning of the tight range)"),
        pub blend: f64 = BLEND,
        pub snap: bool = ParamDef::flag("snap", true, "snap each fitted box: half sides rounded up to 2^(1/16) steps (a fixed set of texel sizes, at most 9 % more area), kept from the last frame until the samples need 2 steps less, and the origin moved by whole texels of that size: the map does not shimmer while the size holds", "Valient 2008 (stable CSM) applied to fitted bounds; steps: shadowlab_core::techniques::sdsm::SIZE_STEPS_PER_OCTAVE"),
        pub delayed: bool = ParamDef::flag("delayed", false, "use the previous frame's reduction (splits and bounds, read back without a stall; frame 0 uses the frustum-slice fit) instead of this frame's (one sync), each cascade's bounds swept by `reach` x the camera's motion since; a sample outside its cascade's box tries the coarser cascades, then the finer ones, then counts as lit", "Lauritzen et al. 2011 (GPU-only fit) / shadowlab's recorded-frame seam (docs/bench/recorded_frame.md)"),
        pub reach: f64 = ParamDef::number("reach", 1.0, 0.0, 4.0, "with delayed: grow each cascade's last-frame sample bounds by this x the camera's motion since that frame (swept along how far the view moved at the cascade's far split: the step plus the turn's displacement there, shadowlab_core::techniques::sdsm::CameraMotion); 0: as read back; higher: more margin for what the motion uncovers, coarser texels while moving", "shadowlab (1 = the motion bound for points that stay in view); measured in docs/bench/sdsm.md"),
        pub lookup: CascadeLookup = Block::as_declared(),
    }
    rules {
        fn ineffective(&self) -> Vec<(&'static str, String)> {
            let mut v = Vec::new();
            if self.maps.cascades == 1 {
                v.push(("blend", ONE_CASCADE_BLEND.to_string()));
            }
            if !self.delayed {
                v.push(("reach", "it sweeps the previous frame's bounds, and delayed=false fits this frame's".to_string()));
            }
            v.extend(self.lookup.ineffective());
            v
        }
    }
}

/// `csm`'s cascades (maps, depth passes, evaluation, stage names `sdsm.*`) with their boxes
/// fitted to the view samples.
pub struct Sdsm {
    cascades: Cascaded,
    fit: SampleFit,
}

impl Sdsm {
    pub fn new(gpu: &Gpu, scene: &GpuScene, p: &SdsmSettings, light: &Light) -> Result<Sdsm, GpuError> {
        let shared = Shared { maps: &p.maps, lookup: &p.lookup, lambda: p.lambda, blend: p.blend, snap: p.snap };
        let cascades = Cascaded::build(gpu, scene, light, "sdsm", shared)?;
        let fit = SampleFit::new(gpu, p, cascades.light_dir(), cascades.count());
        Ok(Sdsm { cascades, fit })
    }
}

/// A frame of `sdsm`: the reductions, readback and fit (fit.rs), then `csm`'s passes over the
/// fitted boxes; `csm`'s report with the fit's counters and the reduction's memory.
impl Technique for Sdsm {
    fn prepare(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        self.fit.prepare(&mut self.cascades, gpu, f, rec)
    }

    fn render(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        self.cascades.render(gpu, f, rec)
    }

    fn evaluate(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        self.cascades.evaluate(gpu, f, rec)
    }

    fn analyze(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        self.cascades.analyze(gpu, f, rec)
    }

    fn report(&mut self, gpu: &Gpu) -> TechniqueReport {
        let mut r = self.cascades.report(gpu);
        // sdsm keeps its reduction's output too
        r.shadow_data_bytes += SDSM_BOUNDS_BYTES;
        self.fit.counters(self.cascades.boxes(), &mut r.counters);
        r
    }
}

#[cfg(test)]
mod tests {
    use shadowlab_core::params::ParamSet;

    use super::SdsmSettings;
    use crate::registry::testing::{err, keys, ok};

    #[test]
    fn sdsm_lists_its_keys_as_before() {
        assert_eq!(
            keys(SdsmSettings::defs()),
            ["cascades", "res", "lambda", "blend", "snap", "delayed", "reach", "bias", "normal_offset", "pcf", "max_slope"]
        );
    }

    #[test]
    fn sdsm_rejects_keys_without_effect() {
        let e = err("sdsm:reach=2");
        assert!(e.contains("technique 'sdsm': reach has no effect"), "{e}");
        ok("sdsm:delayed=true,reach=2");
        assert!(err("sdsm:cascades=1,blend=0.2").contains("blend has no effect"));
        assert!(err("sdsm:max_slope=2").contains("max_slope has no effect"));
        let s = SdsmSettings::from_values(&ok("sdsm:res=2048,cascades=4,blend=0.2,pcf=3,max_slope=2").values);
        assert_eq!((s.maps.cascades, s.maps.res, s.blend, s.lookup.pcf, s.lookup.max_slope), (4, 2048, 0.2, 3, 2.0));
    }
}
