//! Leak tracing's screen-sized state: the temporal mask and the reprojection history
//! (ping-pong), the ray list and the indirect dispatch arguments.

use crate::Gpu;

/// Screen-sized buffers, reallocated when the view size changes.
pub(super) struct Screen {
    pub width: u32,
    pub height: u32,
    /// Temporal mask, ping-pong: `mask_bits` per pixel packed in u32 words.
    pub masks: [wgpu::Buffer; 2],
    /// (linear view depth, packed normal) per pixel, ping-pong, for the reprojection test.
    pub history: [wgpu::Buffer; 2],
    /// list[0] = count, then pixel indices.
    pub list: wgpu::Buffer,
    pub args: wgpu::Buffer,
    /// Frames evaluated at this size; the mask written last is `masks[(frames + 1) % 2]`.
    pub frames: u32,
}

impl Screen {
    /// Buffers for a `w x h` view with `mask_bits` bits of mask per pixel; no history yet.
    pub fn new(gpu: &Gpu, name: &str, w: u32, h: u32, mask_bits: u32) -> Screen {
        let n = w as u64 * h as u64;
        let per_word = (32 / mask_bits) as u64;
        let mask = || gpu.storage(&format!("{name}.mask"), n.div_ceil(per_word) * 4);
        let history = || gpu.storage(&format!("{name}.history"), n * 8);
        let args = gpu.buffer(&wgpu::BufferDescriptor {
            label: Some(&format!("{name}.args")),
            size: 16,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Screen {
            width: w,
            height: h,
            masks: [mask(), mask()],
            history: [history(), history()],
            list: gpu.storage(&format!("{name}.list"), (n + 1) * 4),
            args,
            frames: 0,
        }
    }

    /// The pixels listed for rays in the last frame (in list order).
    pub fn ray_list(&self, gpu: &Gpu) -> Vec<u32> {
        let words: Vec<u32> = gpu.read_buffer_as(&self.list, (self.width * self.height + 1) as usize);
        words[1..1 + words[0] as usize].to_vec()
    }

    /// The temporal mask written in the last frame (`mask_bits` per pixel in the words): 3 bits
    /// per pixel (`shadowlab_core::techniques::lt`).
    pub fn mask(&self, gpu: &Gpu, mask_bits: u32) -> Vec<u32> {
        let n = (self.width * self.height) as usize;
        let per = (32 / mask_bits) as usize;
        let words: Vec<u32> = gpu.read_buffer_as(&self.masks[((self.frames + 1) % 2) as usize], n.div_ceil(per));
        (0..n).map(|i| (words[i / per] >> ((i % per) as u32 * mask_bits)) & 7).collect()
    }
}
