//! `sdsm`: sample distribution shadow maps (Lauritzen, Salvi and Lefohn, I3D 2011) on `csm`'s
//! maps, depth pass, evaluation and report. What it adds: the G-buffer's [min, max] view
//! depth (the shared min/max reduction), then a second reduction (`sdsm_bounds.wgsl`) that
//! splits that range logarithmically and reduces, per cascade, the light-space x/y/z bounds of
//! the samples the evaluation will look up in it; the CPU fits each cascade's box to those
//! bounds (`shadowlab_core::techniques::sdsm`). Both reductions run in one stage and are read
//! back with one sync (`sdsm.readback`), or, with `delayed`, the previous frame's are read
//! without one (frame 0: the frustum-slice fit, `csm`'s box fit of the log splits of the
//! camera's range).

use std::collections::BTreeMap;

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};
use shadowlab_core::camera::Camera;
use shadowlab_core::params::{Block, ParamDef, ParamSet, ParamTable};
use shadowlab_core::techniques::csm::{self as cascades, light_view, CascadeBox, Fit, ViewFrustum, DEPTH_STEPS_PER_OCTAVE};
use shadowlab_core::techniques::sdsm::{self as fit, CameraMotion, FittedBox, SampleBounds};

use super::{CascadeLookup, CascadeMaps, Cascaded, BLEND, ONE_CASCADE_BLEND};
use crate::record::{DelayedRead, Recorder};
use crate::reduce::{decode, from_order_key, ORDER_KEY_WGSL};
use crate::technique::{FrameInputs, TechniqueInfo};
use crate::{binding, Gpu, GpuError};

const BOUNDS_WGSL: &str = include_str!("sdsm_bounds.wgsl");
/// Words of the reduction's output (`sdsm_bounds.wgsl`): a 16-word header, 8 per cascade.
pub const OUT_WORDS: usize = 16 + 8 * cascades::MAX_CASCADES;
/// Bytes of that output: what the CPU reads back each frame, and the GPU memory SDSM keeps
/// beyond `csm`'s maps.
pub const OUT_BYTES: u64 = OUT_WORDS as u64 * 4;
/// Pixels per reduction thread side (`PER_THREAD` in sdsm_bounds.wgsl).
const PER_THREAD: u32 = 4;

fn shaders() -> Vec<(&'static str, String)> {
    let mut v = super::shaders();
    v.push(("csm/sdsm_bounds.wgsl", format!("{ORDER_KEY_WGSL}{BOUNDS_WGSL}")));
    v
}

pub const SDSM_INFO: TechniqueInfo = TechniqueInfo {
    name: "sdsm",
    summary: "sample distribution shadow maps: cascades split logarithmically between the view samples' min and max depth, each box fitted to the light-space bounds of its own samples",
    cost: "two G-buffer reductions (depth range; per-cascade light-space bounds) and one 320-byte readback (a sync; none when delayed), one scene pass per cascade, N^2 fetches per pixel",
    quality: "texels only where view samples are: finer than csm's slice fits, most where the view sees little of each slice; snapped sizes barely shimmer; delayed lags one frame",
    source: "Lauritzen, Salvi, Lefohn 2011 (I3D, sample distribution shadow maps); csm (Engel 2006) for the rest",
    lights: &["directional"],
    params: ParamTable::of::<SdsmSettings>(),
    stalls: "with delayed=false (default): sdsm.readback, the depth range, splits and per-cascade sample bounds read back before the fit; delayed=true (the previous frame's, frame 0 the frustum-slice fit) records without a stall",
    needs: "",
    // not in the default compare set (its cost is csm's, but the set's time is documented)
    compare: &[],
    shaders,
    create: |gpu, scene, p, light| Ok(Box::new(Cascaded::new_sdsm(gpu, scene, &SdsmSettings::from_values(p), light)?)),
};

shadowlab_core::param_set! {
    /// `sdsm`'s parameters: `csm`'s maps and lookup, with the samples' split blend and the
    /// delayed fit's reach.
    pub struct SdsmSettings {
        pub maps: CascadeMaps = Block::as_declared(),
        pub lambda: f64 = ParamDef::number("lambda", fit::DEFAULT_LAMBDA as f64, 0.0, 1.0, "split blend between the samples' min and max depth: 1 logarithmic, 0 uniform; low: coarse near cascade", "Lauritzen et al. 2011 section 3.1 (log partitioning of the tight range)"),
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

/// WGSL `SdsmReduce` (sdsm_bounds.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct SdsmReduce {
    pub light_view: [[f32; 4]; 4],
    pub near: f32,
    pub far: f32,
    pub count: f32,
    pub lambda: f32,
    pub steps: f32,
    pub pad0: f32,
    pub pad1: f32,
    pub pad2: f32,
}

/// Where a frame's boxes came from (the `bounds_source` counter).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Source {
    /// No reduction available (delayed frame 0, or no evaluated pixel): the frustum-slice fit.
    SliceFit = 0,
    /// This frame's samples (after the sync).
    ThisFrame = 1,
    /// The previous frame's samples (delayed, no sync).
    PreviousFrame = 2,
}

/// SDSM's part of a [`Cascaded`]: the bounds reduction and the last fit.
pub(super) struct SampleFit {
    reduce: BoundsReduce,
    reduce_params: SdsmReduce,
    uniform: wgpu::Buffer,
    out: wgpu::Buffer,
    delayed: Option<DelayedRead>,
    /// Texels around the samples' bounds: 1 for snapping (the origin moves by at most half a
    /// texel), the normal offset (the evaluation looks up the sample moved that far along its
    /// normal), half the PCF kernel, and 1 for rounding.
    margin: f32,
    /// The last frame's frustum-slice boxes are `Cascaded::boxes`; these are its sample
    /// bounds and fitted boxes (None: no sample, the slice box is used).
    bounds: Vec<Option<SampleBounds>>,
    fitted: Vec<Option<FittedBox>>,
    source: Source,
    /// `reach` (delayed only: 0 otherwise).
    reach: f32,
    /// The camera of the frame whose reduction the delayed copy holds.
    read_camera: Option<Camera>,
    /// The last frame's sweep of each cascade's bounds (light view, world units; the
    /// `reach_i_*` counters).
    swept: Vec<Vec3>,
}

/// One readback, decoded.
struct Readback {
    range: (f32, f32),
    splits: Vec<f32>,
    bounds: Vec<Option<SampleBounds>>,
}

/// The reduction's words (layout in sdsm_bounds.wgsl), or None when no sample was reduced.
fn decode_out(w: &[u32], count: usize) -> Option<Readback> {
    if w[2] as usize != count {
        return None;
    }
    let range = decode([w[0], w[1]])?;
    let splits = (0..=count).map(|i| f32::from_bits(w[4 + i])).collect();
    let bounds = (0..count).map(|c| decode_bounds(w, c)).collect();
    Some(Readback { range, splits, bounds })
}

/// Cascade `c`'s light-space sample bounds in the reduction's words (None: no sample).
pub(crate) fn decode_bounds(w: &[u32], c: usize) -> Option<SampleBounds> {
    let b = &w[16 + 8 * c..24 + 8 * c];
    (b[6] > 0).then(|| SampleBounds {
        lo: Vec3::new(from_order_key(!b[0]), from_order_key(!b[1]), from_order_key(!b[2])),
        hi: Vec3::new(from_order_key(b[3]), from_order_key(b[4]), from_order_key(b[5])),
        samples: b[6],
    })
}

/// The sample-bounds reduction (`sdsm_bounds.wgsl`) as shared plumbing: `sdsm` reduces per
/// cascade; `iasm:fit=view` uses it with one cascade (every sample in cascade 0, the depth
/// range unused) for the bounds of all evaluated samples in its own light basis.
pub(crate) struct BoundsReduce {
    pub pipeline: wgpu::ComputePipeline,
    pub layout: wgpu::BindGroupLayout,
}

impl BoundsReduce {
    pub fn new(gpu: &Gpu, label: &str) -> BoundsReduce {
        let layout = binding::layout(
            &gpu.device,
            label,
            wgpu::ShaderStages::COMPUTE,
            &[binding::uniform(), binding::texture_float(), binding::storage(true), binding::storage(true), binding::storage(false)],
        );
        let pipeline = gpu.compute_pipeline(label, &format!("{ORDER_KEY_WGSL}{BOUNDS_WGSL}"), "main", &[&layout]);
        BoundsReduce { pipeline, layout }
    }

    /// Clears `out` (OUT_BYTES) and reduces the evaluated samples of `f` into it with the
    /// parameters in `uniform` (`SdsmReduce`) and the [min, max] view depth in `depth_mm`.
    pub fn record(
        &self,
        gpu: &Gpu,
        enc: &mut wgpu::CommandEncoder,
        label: &str,
        f: &FrameInputs,
        uniform: &wgpu::Buffer,
        depth_mm: &wgpu::Buffer,
        out: &wgpu::Buffer,
    ) {
        let view = f.gbuffer.position.create_view(&Default::default());
        let group = binding::group(
            &gpu.device,
            label,
            &self.layout,
            &[
                uniform.as_entire_binding(),
                wgpu::BindingResource::TextureView(&view),
                f.gbuffer.mask.as_entire_binding(),
                depth_mm.as_entire_binding(),
                out.as_entire_binding(),
            ],
        );
        enc.clear_buffer(out, 0, None);
        let (w, h) = (f.gbuffer.width.div_ceil(PER_THREAD), f.gbuffer.height.div_ceil(PER_THREAD));
        gpu.dispatch_2d(enc, label, &self.pipeline, &[&group], w, h);
    }
}

impl SampleFit {
    pub(super) fn new(gpu: &Gpu, p: &SdsmSettings, dir: Vec3, count: usize) -> SampleFit {
        let reduce_params = SdsmReduce {
            light_view: light_view(dir).to_cols_array_2d(),
            near: 0.0,
            far: 0.0,
            count: count as f32,
            lambda: p.lambda as f32,
            steps: DEPTH_STEPS_PER_OCTAVE,
            pad0: 0.0,
            pad1: 0.0,
            pad2: 0.0,
        };
        SampleFit {
            reduce: BoundsReduce::new(gpu, "sdsm.bounds"),
            uniform: gpu.uniform("sdsm.bounds", &reduce_params),
            reduce_params,
            out: gpu.storage("sdsm.bounds", OUT_BYTES),
            delayed: p.delayed.then(|| DelayedRead::new(gpu, "sdsm.delayed", OUT_BYTES)),
            margin: 2.0 + p.lookup.normal_offset as f32 + 0.5 * (p.lookup.pcf as f32 - 1.0),
            bounds: Vec::new(),
            fitted: Vec::new(),
            source: Source::SliceFit,
            reach: if p.delayed { p.reach as f32 } else { 0.0 },
            read_camera: None,
            swept: Vec::new(),
        }
    }

    /// Records the bounds reduction (after `depth`'s min/max reduction of the same frame).
    fn record(&self, gpu: &Gpu, enc: &mut wgpu::CommandEncoder, f: &FrameInputs, depth: &crate::reduce::MinMax) {
        depth.record(gpu, enc, "sdsm.reduce", &f.gbuffer.position, &f.gbuffer.mask);
        self.reduce.record(gpu, enc, "sdsm.bounds", f, &self.uniform, &depth.result, &self.out);
    }

    /// The report's SDSM counters: where the boxes came from, and per cascade the samples,
    /// their bounds, the fitted box and its area and texels against the frustum slice's.
    pub(super) fn counters(&self, slices: &[CascadeBox], c: &mut BTreeMap<String, f64>) {
        c.insert("bounds_source".into(), self.source as u32 as f64);
        c.insert("fitted_cascades".into(), self.fitted.iter().flatten().count() as f64);
        c.insert("bounds_bytes".into(), OUT_BYTES as f64);
        for (i, s) in slices.iter().enumerate() {
            let slice_area = (2.0 * s.half as f64).powi(2);
            c.insert(format!("slice_texel_{i}"), s.texel as f64);
            let b = self.bounds.get(i).copied().flatten();
            c.insert(format!("samples_{i}"), b.map_or(0.0, |b| b.samples as f64));
            if self.delayed.is_some() {
                let d = self.swept.get(i).copied().unwrap_or(Vec3::ZERO);
                for (k, v) in [("x", d.x), ("y", d.y), ("z", d.z)] {
                    c.insert(format!("reach_{i}_{k}"), v as f64);
                }
            }
            let Some(fb) = self.fitted.get(i).copied().flatten() else {
                c.insert(format!("area_ratio_{i}"), 1.0);
                continue;
            };
            c.insert(format!("area_ratio_{i}"), fb.area() as f64 / slice_area);
            c.insert(format!("texel_x_{i}"), fb.texel.x as f64);
            c.insert(format!("texel_y_{i}"), fb.texel.y as f64);
            // light-view boxes: the fitted one and the samples' bounds it was fitted to
            let o = fb.origin.as_dvec2();
            let h = fb.half.as_dvec2();
            for (k, v) in [("x0", o.x - h.x), ("x1", o.x + h.x), ("y0", o.y - h.y), ("y1", o.y + h.y)] {
                c.insert(format!("box_{i}_{k}"), v);
            }
            c.insert(format!("box_{i}_znear"), fb.near_z as f64);
            c.insert(format!("box_{i}_zfar"), fb.far_z as f64);
            if let Some(b) = b {
                for (k, v) in [("lo", b.lo), ("hi", b.hi)] {
                    c.insert(format!("bounds_{i}_{k}_x"), v.x as f64);
                    c.insert(format!("bounds_{i}_{k}_y"), v.y as f64);
                    c.insert(format!("bounds_{i}_{k}_z"), v.z as f64);
                }
            }
        }
    }
}

/// SDSM's `prepare`: the reductions (and this frame's readback, or the previous frame's), the
/// splits and the boxes.
pub(super) fn prepare(t: &mut Cascaded, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
    let view_proj = f.camera.view_proj(f.gbuffer.width, f.gbuffer.height);
    let frustum = ViewFrustum::from_view_proj(view_proj, f.camera.position)
        .ok_or_else(|| GpuError::Invalid("sdsm: the view's projection is not a perspective frustum".into()))?;
    let s = t.sample_fit.as_mut().expect("sdsm has its sample fit");
    s.reduce_params.near = frustum.near;
    s.reduce_params.far = frustum.far;
    rec.write_buffer(&s.uniform, 0, bytemuck::bytes_of(&s.reduce_params));
    let depth = &t.reduce;
    let (words, source, read_camera) = if let Some(d) = s.delayed.as_mut() {
        let prev = d.take::<u32>(gpu, OUT_WORDS);
        let read_camera = if prev.is_some() { s.read_camera.take() } else { None };
        rec.stage("sdsm.analyze", |enc| s.record(gpu, enc, f, depth));
        let d = s.delayed.as_mut().expect("delayed");
        d.record(rec, &s.out);
        s.read_camera = Some(f.camera);
        (prev, Source::PreviousFrame, read_camera)
    } else {
        rec.stage("sdsm.analyze", |enc| s.record(gpu, enc, f, depth));
        let t0 = std::time::Instant::now();
        let w: Vec<u32> = rec.read_buffer_as(&s.out, OUT_WORDS, "sdsm.readback");
        rec.cpu("sdsm.readback", t0.elapsed().as_secs_f64() * 1e3);
        (Some(w), Source::ThisFrame, None)
    };

    let t0 = std::time::Instant::now();
    let count = t.count;
    let (splits, bounds, source) = match words.and_then(|w| decode_out(&w, count)) {
        Some(r) => {
            t.depth_range = Some(r.range);
            // delayed: what the camera's motion since that frame brings into view next to
            // last frame's samples (0 for a still camera: the bounds as read)
            let aspect = f.gbuffer.width as f32 / f.gbuffer.height.max(1) as f32;
            let motion = read_camera.map(|c| CameraMotion::between(&c, &f.camera, aspect)).filter(|_| s.reach > 0.0);
            let lv = light_view(t.dir);
            s.swept = (0..count)
                .map(|i| motion.map_or(Vec3::ZERO, |m| lv.transform_vector3(m.displacement(r.splits[i + 1])) * s.reach))
                .collect();
            let bounds = r.bounds.iter().zip(&s.swept).map(|(b, &d)| b.map(|b| b.swept(d, 0.0))).collect();
            (r.splits, bounds, source)
        }
        None => {
            t.depth_range = None;
            s.swept = vec![Vec3::ZERO; count];
            (fit::sample_splits(frustum.near, frustum.far, None, count, t.lambda), vec![None; count], Source::SliceFit)
        }
    };
    let scene = &f.scene.bounds;
    let slices = cascades::fit_cascades(&frustum, t.dir, scene, &splits, t.res, t.snap, Fit::Box);
    // the previous frame's sizes, for the snapped sizes' hysteresis
    let prev: Vec<Option<glam::Vec2>> = (0..count).map(|i| s.fitted.get(i).copied().flatten().map(|fb| fb.extent)).collect();
    let fitted: Vec<Option<FittedBox>> = slices
        .iter()
        .zip(&bounds)
        .zip(prev)
        .map(|((sl, b), p)| b.map(|b| fit::fit_to_samples(sl, &b, scene, t.res, t.snap, s.margin, p)))
        .collect();
    let boxes: Vec<(Mat4, f32)> =
        slices.iter().zip(&fitted).map(|(sl, fb)| fb.map_or((sl.view_proj, sl.texel), |fb| (fb.view_proj, fb.max_texel()))).collect();
    (s.bounds, s.fitted, s.source) = (bounds, fitted, source);
    t.upload(rec, &boxes, &splits);
    t.boxes = slices;
    rec.cpu("sdsm.fit", t0.elapsed().as_secs_f64() * 1e3);
    Ok(())
}
