//! GPU min/max reduction of one channel of a float texture over masked pixels: shared plumbing
//! for techniques that fit their shadow data to the depth range actually visible (`csm`'s
//! tightening; the warping techniques' desired-view analysis later). The result stays on the
//! GPU in [`MinMax::result`] (two words, see `reduce.wgsl`); [`decode`] turns them into floats.
//! Reading them on the CPU costs a device sync (submit, wait, map): time it where it is used.

use bytemuck::{Pod, Zeroable};

use crate::{binding, Gpu};

/// `order_key` / `from_order_key` (WGSL), shared by the reductions that use them.
pub const ORDER_KEY_WGSL: &str = include_str!("order_key.wgsl");
const REDUCE_WGSL: &str = include_str!("reduce.wgsl");
/// Pixels per thread side (`PER_THREAD` in reduce.wgsl).
const PER_THREAD: u32 = 4;

pub fn shaders() -> Vec<(&'static str, String)> {
    vec![("reduce/reduce.wgsl", format!("{ORDER_KEY_WGSL}{REDUCE_WGSL}"))]
}

/// WGSL `ReduceParams`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct ReduceParams {
    pub channel: u32,
    pub _pad: [u32; 3],
}

/// Min/max of channel `channel` of a texture, over the pixels whose mask word is non-zero.
pub struct MinMax {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    params: wgpu::Buffer,
    /// Two u32 words: the complement of the min's order key, the max's order key.
    pub result: wgpu::Buffer,
    groups: binding::GroupCache,
}

impl MinMax {
    pub fn new(gpu: &Gpu, label: &str, channel: u32) -> MinMax {
        let layout = binding::layout(
            &gpu.device,
            label,
            wgpu::ShaderStages::COMPUTE,
            &[binding::uniform(), binding::texture_float(), binding::storage(true), binding::storage(false)],
        );
        let pipeline = gpu.compute_pipeline(label, &format!("{ORDER_KEY_WGSL}{REDUCE_WGSL}"), "main", &[&layout]);
        let params = gpu.uniform(label, &ReduceParams { channel: channel.min(3), _pad: [0; 3] });
        let result = gpu.storage(label, 8);
        MinMax { pipeline, layout, params, result, groups: Default::default() }
    }

    /// Records the reduction of `view` (of a `w x h` texture) under `mask` (one u32 per pixel);
    /// the bind group is kept while the view and mask stay.
    pub fn record(
        &self,
        gpu: &Gpu,
        enc: &mut wgpu::CommandEncoder,
        label: &str,
        (view, w, h): (&wgpu::TextureView, u32, u32),
        mask: &wgpu::Buffer,
    ) {
        let group = self.groups.get(
            gpu,
            label,
            &self.layout,
            &[
                self.params.as_entire_binding(),
                wgpu::BindingResource::TextureView(view),
                mask.as_entire_binding(),
                self.result.as_entire_binding(),
            ],
        );
        enc.clear_buffer(&self.result, 0, None);
        gpu.dispatch_2d(enc, label, &self.pipeline, &[&group], w.div_ceil(PER_THREAD), h.div_ceil(PER_THREAD));
    }

    /// Reads the result back (blocking: a device sync).
    pub fn read(&self, gpu: &Gpu) -> Option<(f32, f32)> {
        let w: Vec<u32> = gpu.read_buffer_as(&self.result, 2);
        decode([w[0], w[1]])
    }
}

/// The float of an order key (inverse of `order_key` in reduce.wgsl).
pub fn from_order_key(k: u32) -> f32 {
    if k & 0x8000_0000 != 0 {
        f32::from_bits(k & 0x7fff_ffff)
    } else {
        f32::from_bits(!k)
    }
}

/// (min, max) from the two result words, or None when no pixel was reduced.
pub fn decode(words: [u32; 2]) -> Option<(f32, f32)> {
    (words[1] != 0).then(|| (from_order_key(!words[0]), from_order_key(words[1])))
}

#[cfg(test)]
mod tests {
    use super::*;
    fn order_key(x: f32) -> u32 {
        let b = x.to_bits();
        if b & 0x8000_0000 != 0 {
            !b
        } else {
            b | 0x8000_0000
        }
    }
    #[test]
    fn order_keys_sort_like_floats_and_decode() {
        let xs = [-1e30f32, -3.5, -1e-20, -0.0, 0.0, 1e-20, 0.25, 7.0, 1e30];
        for w in xs.windows(2) {
            assert!(order_key(w[0]) <= order_key(w[1]), "{} {}", w[0], w[1]);
        }
        for x in xs {
            assert_eq!(from_order_key(order_key(x)).to_bits(), x.to_bits());
        }
        assert_eq!(decode([!order_key(-2.0), order_key(9.5)]), Some((-2.0, 9.5)));
        assert_eq!(decode([0, 0]), None);
    }
}
