//! Every buffer shadowlab makes goes through [`Gpu::buffer`] (or the helpers built on it:
//! `storage`, `uniform`, `buffer_init`) and every bind group through [`Gpu::bind_group`] (or
//! `binding::group`), which count them: the per-frame hygiene test records each technique's
//! frames and asserts that a frame after the first creates no buffer (and, for the techniques
//! it lists, no bind group; `tests/hygiene.rs`), and a source check keeps `create_buffer` calls
//! out of every other file.
//!
//! What a frame needs afresh each time comes from two pools instead of new buffers:
//! - uploads ([`Gpu::upload`]): mapped `COPY_SRC` buffers that
//!   [`crate::record::Recorder::write_buffer`] fills and copies from; each is mapped again when
//!   its frame's commands have run, then handed out again;
//! - readbacks ([`Gpu::readback`]): `MAP_READ` buffers for mid-frame and report readbacks,
//!   returned once read.
//!
//! Both hand out buffers by power-of-two size class (at least 256 bytes) and keep at most
//! [`POOL_CAP`] idle buffers and [`POOL_BYTES`] idle bytes each. A buffer larger than
//! [`POOL_BYTES`] (a report's readback of a large map) is made at its own size and dropped
//! after use.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

use crate::Gpu;

/// Idle buffers a pool keeps; more are dropped.
pub const POOL_CAP: usize = 64;
/// Idle bytes a pool keeps; a buffer that would exceed them is dropped.
pub const POOL_BYTES: u64 = 64 << 20;

/// The counter and pools a [`Gpu`] holds.
#[derive(Default)]
pub struct Alloc {
    buffers: AtomicU64,
    bind_groups: AtomicU64,
    dispatches: AtomicU64,
    uploads: Arc<Mutex<Vec<wgpu::Buffer>>>,
    reads: Mutex<Vec<wgpu::Buffer>>,
}

/// The pools' size class of `size` bytes; above [`POOL_BYTES`] (never kept) the size itself,
/// in whole words, rather than up to twice it.
fn class(size: u64) -> u64 {
    if size > POOL_BYTES {
        return size.div_ceil(4) * 4;
    }
    size.max(256).next_power_of_two()
}

fn take(pool: &Mutex<Vec<wgpu::Buffer>>, size: u64) -> Option<wgpu::Buffer> {
    let mut free = pool.lock().unwrap();
    let i = free.iter().position(|b| b.size() == class(size))?;
    Some(free.swap_remove(i))
}

fn give(pool: &Mutex<Vec<wgpu::Buffer>>, buf: wgpu::Buffer) {
    let mut free = pool.lock().unwrap();
    let idle: u64 = free.iter().map(|b| b.size()).sum();
    if free.len() < POOL_CAP && idle + buf.size() <= POOL_BYTES {
        free.push(buf);
    }
}

/// Why a buffer of `size` bytes with `usage` cannot be made on a device with `limits`: over
/// its largest buffer, or a storage buffer over its largest storage binding (shadowlab binds
/// storage buffers whole). The message names the buffer, both sizes and the limit.
pub fn over_limit(limits: &wgpu::Limits, label: &str, size: u64, usage: wgpu::BufferUsages) -> Option<String> {
    let mib = |b: u64| b as f64 / (1u64 << 20) as f64;
    let (limit, name) = if usage.contains(wgpu::BufferUsages::STORAGE) && size > limits.max_storage_buffer_binding_size {
        (limits.max_storage_buffer_binding_size, "max_storage_buffer_binding_size")
    } else if size > limits.max_buffer_size {
        (limits.max_buffer_size, "max_buffer_size")
    } else {
        return None;
    };
    Some(format!(
        "'{label}' needs {:.2} MiB, over this device's {name} of {:.2} MiB: use a smaller output size or map resolution",
        mib(size),
        mib(limit)
    ))
}

impl Gpu {
    /// Buffers created through this device wrapper so far.
    pub fn buffers_created(&self) -> u64 {
        self.alloc.buffers.load(Ordering::Relaxed)
    }

    /// Bind groups created through this device wrapper so far.
    pub fn bind_groups_created(&self) -> u64 {
        self.alloc.bind_groups.load(Ordering::Relaxed)
    }

    /// Compute dispatches recorded through this device wrapper so far (direct and indirect).
    pub fn dispatches(&self) -> u64 {
        self.alloc.dispatches.load(Ordering::Relaxed)
    }

    /// Records a dispatch of `groups` workgroups into `pass` (counted).
    pub fn dispatch(&self, pass: &mut wgpu::ComputePass, [x, y, z]: [u32; 3]) {
        self.alloc.dispatches.fetch_add(1, Ordering::Relaxed);
        pass.dispatch_workgroups(x, y, z);
    }

    /// Records an indirect dispatch (arguments at `offset` in `args`) into `pass` (counted).
    pub fn dispatch_indirect(&self, pass: &mut wgpu::ComputePass, args: &wgpu::Buffer, offset: u64) {
        self.alloc.dispatches.fetch_add(1, Ordering::Relaxed);
        pass.dispatch_workgroups_indirect(args, offset);
    }

    /// A new bind group (counted).
    pub fn bind_group(&self, desc: &wgpu::BindGroupDescriptor) -> wgpu::BindGroup {
        self.alloc.bind_groups.fetch_add(1, Ordering::Relaxed);
        self.device.create_bind_group(desc)
    }

    /// A new buffer (counted). One over the device's limits is refused ([`Gpu::refuse`],
    /// named with the limit); the device then makes no memory for it.
    pub fn buffer(&self, desc: &wgpu::BufferDescriptor) -> wgpu::Buffer {
        self.alloc.buffers.fetch_add(1, Ordering::Relaxed);
        if let Some(msg) = over_limit(&self.limits, desc.label.unwrap_or("buffer"), desc.size, desc.usage) {
            self.refuse(msg);
            // an empty stand-in: what is recorded with it fails validation, reported after the refusal
            return self.device.create_buffer(&wgpu::BufferDescriptor { size: 4, mapped_at_creation: false, ..*desc });
        }
        self.device.create_buffer(desc)
    }

    /// A new buffer with its contents, made by [`Gpu::buffer`] (counted, refused over the
    /// limits) and written through its mapping at creation, as
    /// `wgpu::util::DeviceExt::create_buffer_init` does, except that a buffer the device could
    /// not map (a lost device) is reported by [`Gpu::take_error`] rather than a panic.
    pub fn buffer_desc_init(&self, desc: &wgpu::util::BufferInitDescriptor) -> wgpu::Buffer {
        let len = desc.contents.len() as u64;
        let size = len.div_ceil(wgpu::COPY_BUFFER_ALIGNMENT).max(1) * wgpu::COPY_BUFFER_ALIGNMENT;
        let buf = self.buffer(&wgpu::BufferDescriptor { label: desc.label, size, usage: desc.usage, mapped_at_creation: true });
        if buf.size() < size {
            return buf; // refused over a limit: an unmapped stand-in, already reported
        }
        match buf.slice(..).get_mapped_range_mut() {
            Ok(mut range) => range.slice(..desc.contents.len()).copy_from_slice(desc.contents),
            Err(e) => {
                self.errors_push(crate::GpuError::Validation(format!("'{}' could not be written: {e}", desc.label.unwrap_or("buffer"))))
            }
        }
        buf.unmap();
        buf
    }

    /// A mapped `COPY_SRC` buffer of at least `size` bytes (from the pool, or new). Give it
    /// back with [`Gpu::recycle_upload`] in the encoder that copies from it.
    pub(crate) fn upload(&self, size: u64) -> wgpu::Buffer {
        take(&self.alloc.uploads, size).unwrap_or_else(|| {
            self.buffer(&wgpu::BufferDescriptor {
                label: Some("upload"),
                size: class(size),
                usage: wgpu::BufferUsages::MAP_WRITE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: true,
            })
        })
    }

    /// Maps `buf` again when `enc`'s commands have run, and then returns it to the pool.
    pub(crate) fn recycle_upload(&self, enc: &mut wgpu::CommandEncoder, buf: &wgpu::Buffer) {
        let (pool, back) = (self.alloc.uploads.clone(), buf.clone());
        enc.map_buffer_on_submit(buf, wgpu::MapMode::Write, .., move |r| {
            if r.is_ok() {
                give(&pool, back);
            }
        });
    }

    /// An unmapped `MAP_READ | COPY_DST` buffer of at least `size` bytes (from the pool, or
    /// new); give it back with [`Gpu::give_readback`] once read.
    pub(crate) fn readback(&self, size: u64) -> wgpu::Buffer {
        take(&self.alloc.reads, size).unwrap_or_else(|| {
            self.buffer(&wgpu::BufferDescriptor {
                label: Some("readback"),
                size: class(size),
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        })
    }

    pub(crate) fn give_readback(&self, buf: wgpu::Buffer) {
        give(&self.alloc.reads, buf);
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn size_classes_are_powers_of_two_from_256() {
        assert_eq!(super::class(0), 256);
        assert_eq!(super::class(256), 256);
        assert_eq!(super::class(257), 512);
        assert_eq!(super::class(5000), 8192);
        // too large to keep: its own size, not the next power of two
        let big = super::POOL_BYTES + 6;
        assert_eq!(super::class(big), big + 2);
    }
}
