//! The sample-bounds reduction (`sdsm_bounds.wgsl`), shared plumbing of the techniques that fit
//! their maps to the view samples: after the G-buffer's [min, max] view depth (the shared
//! min/max reduction), it splits that range logarithmically and reduces, per cascade, the
//! light-space x/y/z bounds of the samples the evaluation will look up in it. `sdsm`
//! (techniques/sdsm) reduces per cascade; `iasm:fit=view` uses it with one cascade (every
//! sample in cascade 0, the depth range unused) for the bounds of all evaluated samples in its
//! own light basis.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use shadowlab_core::techniques::csm::MAX_CASCADES;
use shadowlab_core::techniques::sdsm::SampleBounds;

use crate::reduce::{from_order_key, ORDER_KEY_WGSL};
use crate::technique::FrameInputs;
use crate::{binding, Gpu};

const BOUNDS_WGSL: &str = include_str!("sdsm_bounds.wgsl");
/// Words of the reduction's output (`sdsm_bounds.wgsl`): a 16-word header, 8 per cascade.
pub const OUT_WORDS: usize = 16 + 8 * MAX_CASCADES;
/// Bytes of that output: what the CPU reads back each frame, and the GPU memory SDSM keeps
/// beyond `csm`'s maps.
pub const OUT_BYTES: u64 = OUT_WORDS as u64 * 4;
/// Pixels per reduction thread side (`PER_THREAD` in sdsm_bounds.wgsl).
const PER_THREAD: u32 = 4;

/// The composed reduction, listed as `csm/sdsm_bounds.wgsl`.
pub(crate) fn source() -> String {
    format!("{ORDER_KEY_WGSL}{BOUNDS_WGSL}")
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

/// Cascade `c`'s light-space sample bounds in the reduction's words (None: no sample).
pub(crate) fn decode_bounds(w: &[u32], c: usize) -> Option<SampleBounds> {
    let b = &w[16 + 8 * c..24 + 8 * c];
    (b[6] > 0).then(|| SampleBounds {
        lo: Vec3::new(from_order_key(!b[0]), from_order_key(!b[1]), from_order_key(!b[2])),
        hi: Vec3::new(from_order_key(b[3]), from_order_key(b[4]), from_order_key(b[5])),
        samples: b[6],
    })
}

/// The reduction's pipeline and layout.
pub(crate) struct BoundsReduce {
    pub pipeline: wgpu::ComputePipeline,
    pub layout: wgpu::BindGroupLayout,
    groups: binding::GroupCache,
}

impl BoundsReduce {
    pub fn new(gpu: &Gpu, label: &str) -> BoundsReduce {
        let layout = binding::layout(
            &gpu.device,
            label,
            wgpu::ShaderStages::COMPUTE,
            &[binding::uniform(), binding::texture_float(), binding::storage(true), binding::storage(true), binding::storage(false)],
        );
        let pipeline = gpu.compute_pipeline(label, &source(), "main", &[&layout]);
        BoundsReduce { pipeline, layout, groups: Default::default() }
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
        let group = self.groups.get(
            gpu,
            label,
            &self.layout,
            &[
                uniform.as_entire_binding(),
                wgpu::BindingResource::TextureView(&f.gbuffer.position_view),
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
