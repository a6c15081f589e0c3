//! Recording a frame into the caller's command encoder.
//!
//! A technique's `prepare`, `render` and `evaluate` record their passes through a [`Recorder`]
//! that wraps the `&mut wgpu::CommandEncoder` the caller hands in; they never submit or wait by
//! themselves. Each group of passes is a *stage*, named `<technique>.<stage>`: the stage name is
//! the wgpu label and the timing key. What the caller does with the stages is its choice:
//! - [`Recorder::new`]: plain recording, as a host renderer uses it; the caller submits.
//! - [`Recorder::with_stamps`]: a GPU timestamp before and after each stage into one query set
//!   ([`FrameStamps`]), resolved once per frame (adapters with sane timestamps).
//! - [`Recorder::profiled`]: the breakdown run: every stage is submitted and waited for alone and
//!   timed by the wall clock (software adapters, whose timestamps read wrong). Its stage times
//!   add the submit and wait of each stage, so they are a breakdown, never the frame's total.
//!
//! A technique that must read the GPU back in the middle of a frame (a reduction whose result
//! the CPU needs before drawing) calls [`Recorder::sync`] or [`Recorder::read_buffer_as`]: what
//! was recorded so far is submitted and waited for, and the stall is counted with its reason.
//! Such techniques declare it in their registry entry (`TechniqueInfo::stalls`).
//!
//! [`drive`] is the one frame driver the lab, the viewer and the host examples share: a fresh
//! encoder, a [`Recorder`] of the chosen [`Clock`], the caller's recording, one submit (plus
//! the declared stalls) and one wait, and the frame's times.

use std::collections::BTreeMap;
use web_time::Instant;

use crate::Gpu;

/// Stages (pairs of timestamps) one frame can time.
pub const MAX_STAGES: u32 = 128;

/// The query set and buffers for one frame of per-stage GPU timestamps.
pub struct FrameStamps {
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    readback: wgpu::Buffer,
}

impl FrameStamps {
    pub fn new(gpu: &Gpu) -> FrameStamps {
        let n = 2 * MAX_STAGES;
        let set = gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("frame.timestamps"),
            ty: wgpu::QueryType::Timestamp,
            count: n,
        });
        let size = n as u64 * 8;
        let resolve = gpu.buffer(&wgpu::BufferDescriptor {
            label: Some("frame.timestamps.resolve"),
            size,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let readback = gpu.buffer(&wgpu::BufferDescriptor {
            label: Some("frame.timestamps.readback"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        FrameStamps { set, resolve, readback }
    }
}

enum Timing<'a> {
    None,
    Stamps(&'a FrameStamps, Vec<String>),
    Profile(BTreeMap<String, f64>),
}

/// What a recorded frame leaves for its caller (see [`Recorder::finish`]).
#[derive(Debug, Default)]
pub struct Recorded {
    /// Stage names in recording order, each with its timestamp pair index (timestamp frames).
    pub stamped: Vec<String>,
    /// Wall-clock ms per stage of a profiled frame (wait per stage); summed over repeated names.
    pub profile_ms: BTreeMap<String, f64>,
    /// Mid-frame submits and waits ([`Recorder::sync`]), by reason, in order.
    pub stalls: Vec<String>,
}

impl Recorded {
    /// Per-stage ms from the resolved timestamps of this frame (after the caller's submit and
    /// wait); repeated stage names add up.
    pub fn read_stamps(&self, gpu: &Gpu, stamps: &FrameStamps) -> BTreeMap<String, f64> {
        let mut out = BTreeMap::new();
        if self.stamped.is_empty() {
            return out;
        }
        let t: Vec<u64> = gpu.map_read_as(&stamps.readback, 2 * self.stamped.len());
        let period = gpu.queue.get_timestamp_period() as f64 * 1e-6;
        for (i, name) in self.stamped.iter().enumerate() {
            *out.entry(name.clone()).or_insert(0.0) += t[2 * i + 1].saturating_sub(t[2 * i]) as f64 * period;
        }
        out
    }
}

/// Records a frame's stages into the caller's encoder (see the module docs).
pub struct Recorder<'a> {
    gpu: &'a Gpu,
    enc: &'a mut wgpu::CommandEncoder,
    timing: Timing<'a>,
    stalls: Vec<String>,
    /// Stage-name prefix rewrite (`from`, `to`): a technique built from another's passes
    /// (cube-notw's faces are notw maps) names their stages as its own.
    rename: Option<(String, String)>,
}

impl<'a> Recorder<'a> {
    /// Plain recording into `enc`; the caller submits.
    pub fn new(gpu: &'a Gpu, enc: &'a mut wgpu::CommandEncoder) -> Recorder<'a> {
        Recorder { gpu, enc, timing: Timing::None, stalls: Vec::new(), rename: None }
    }

    /// Recording with a timestamp pair around each stage (the adapter must offer
    /// `TIMESTAMP_QUERY_INSIDE_ENCODERS`: `gpu.gpu_timestamps`).
    pub fn with_stamps(gpu: &'a Gpu, enc: &'a mut wgpu::CommandEncoder, stamps: &'a FrameStamps) -> Recorder<'a> {
        Recorder { gpu, enc, timing: Timing::Stamps(stamps, Vec::new()), stalls: Vec::new(), rename: None }
    }

    /// The breakdown run: each stage submitted and waited for alone, timed by the wall clock.
    pub fn profiled(gpu: &'a Gpu, enc: &'a mut wgpu::CommandEncoder) -> Recorder<'a> {
        Recorder { gpu, enc, timing: Timing::Profile(BTreeMap::new()), stalls: Vec::new(), rename: None }
    }

    pub fn gpu(&self) -> &'a Gpu {
        self.gpu
    }

    /// The encoder, for commands outside a named stage (copies, clears).
    pub fn encoder(&mut self) -> &mut wgpu::CommandEncoder {
        self.enc
    }

    /// Stages named `from...` are recorded as `to...` until the rewrite is set back (returns
    /// the previous rewrite).
    pub fn set_rename(&mut self, rename: Option<(String, String)>) -> Option<(String, String)> {
        std::mem::replace(&mut self.rename, rename)
    }

    /// Records `f`'s passes as stage `name` (label and timing key).
    pub fn stage<R>(&mut self, name: &str, f: impl FnOnce(&mut wgpu::CommandEncoder) -> R) -> R {
        let renamed = self.rename.as_ref().and_then(|(from, to)| name.strip_prefix(from.as_str()).map(|rest| format!("{to}{rest}")));
        let name = renamed.as_deref().unwrap_or(name);
        match &mut self.timing {
            Timing::None => f(self.enc),
            Timing::Stamps(stamps, names) => {
                let i = names.len() as u32;
                assert!(i < MAX_STAGES, "more than {MAX_STAGES} timed stages in one frame");
                self.enc.write_timestamp(&stamps.set, 2 * i);
                let r = f(self.enc);
                self.enc.write_timestamp(&stamps.set, 2 * i + 1);
                names.push(name.to_string());
                r
            }
            Timing::Profile(_) => {
                // what was recorded before this stage is not part of it
                submit_and_wait(self.gpu, self.enc, name);
                let t0 = Instant::now();
                let r = f(self.enc);
                submit_and_wait(self.gpu, self.enc, name);
                let ms = t0.elapsed().as_secs_f64() * 1e3;
                if let Timing::Profile(m) = &mut self.timing {
                    *m.entry(name.to_string()).or_insert(0.0) += ms;
                }
                r
            }
        }
    }

    /// Adds CPU work of `ms` done inside the frame (a fit between passes) to the breakdown of a
    /// profiled frame, as stage `name`; other frames count it in their wall clock only.
    pub fn cpu(&mut self, name: &str, ms: f64) {
        if let Timing::Profile(m) = &mut self.timing {
            *m.entry(name.to_string()).or_insert(0.0) += ms;
        }
    }

    /// Writes `data` into `buf` at `offset`, ordered with the recorded passes (a copy from a
    /// pooled upload buffer, `Gpu::upload`; `queue.write_buffer` would land before the whole
    /// frame).
    pub fn write_buffer(&mut self, buf: &wgpu::Buffer, offset: u64, data: &[u8]) {
        if data.is_empty() {
            return;
        }
        let size = (data.len() as u64).div_ceil(4) * 4;
        if offset + size > buf.size() {
            // a buffer refused over a limit is a 4-byte stand-in (`Gpu::buffer`)
            self.gpu.refuse(format!("a write of {} bytes at offset {offset} does not fit its buffer of {} bytes", data.len(), buf.size()));
            return;
        }
        let staging = self.gpu.upload(size);
        {
            let mut view = staging.slice(..size).get_mapped_range_mut().expect("an upload buffer is mapped until its copy is recorded");
            view.slice(..data.len()).copy_from_slice(data);
            if size as usize > data.len() {
                view.slice(data.len()..).copy_from_slice(&[0; 4][..size as usize - data.len()]);
            }
        }
        staging.unmap();
        self.enc.copy_buffer_to_buffer(&staging, 0, buf, offset, size);
        self.gpu.recycle_upload(self.enc, &staging);
    }

    /// The mid-frame stalls so far.
    pub fn stalls(&self) -> &[String] {
        &self.stalls
    }

    /// Submits what was recorded so far and waits: a declared mid-frame stall (`why` names it).
    pub fn sync(&mut self, why: &str) {
        submit_and_wait(self.gpu, self.enc, why);
        self.stalls.push(why.to_string());
    }

    /// Copies `count` values of `buf` into a staging buffer in the frame, then
    /// [`Recorder::sync`]s and reads them: one stall, one submit.
    pub fn read_buffer_as<T: bytemuck::Pod>(&mut self, buf: &wgpu::Buffer, count: usize, why: &str) -> Vec<T> {
        let size = ((count * std::mem::size_of::<T>()) as u64).div_ceil(4) * 4;
        let staging = self.gpu.readback(size.max(4));
        self.enc.copy_buffer_to_buffer(buf, 0, &staging, 0, size);
        self.sync(why);
        let out = self.gpu.map_read_as(&staging, count);
        self.gpu.give_readback(staging);
        out
    }

    /// Ends recording: on a timestamp frame records the one resolve (and its copy for reading).
    pub fn finish(self) -> Recorded {
        let mut out = Recorded { stalls: self.stalls, ..Default::default() };
        match self.timing {
            Timing::None => {}
            Timing::Stamps(stamps, names) => {
                if !names.is_empty() {
                    let n = 2 * names.len() as u32;
                    self.enc.resolve_query_set(&stamps.set, 0..n, &stamps.resolve, 0);
                    self.enc.copy_buffer_to_buffer(&stamps.resolve, 0, &stamps.readback, 0, n as u64 * 8);
                }
                out.stamped = names;
            }
            Timing::Profile(m) => out.profile_ms = m,
        }
        out
    }
}

/// How [`drive`] times a frame.
#[derive(Clone, Copy)]
pub enum Clock<'a> {
    /// The wall clock around the one submit and wait (software adapters).
    Wall,
    /// The wall clock, and a timestamp pair around each stage (adapters with sane timestamps).
    Stamped(&'a FrameStamps),
    /// The breakdown run: each stage submitted and waited for alone ([`Recorder::profiled`]).
    Profiled,
}

impl<'a> Clock<'a> {
    /// Stamped when `stamps` are given, else the wall clock.
    pub fn of(stamps: Option<&'a FrameStamps>) -> Clock<'a> {
        stamps.map_or(Clock::Wall, Clock::Stamped)
    }
}

/// What [`drive`] measured of one frame.
#[derive(Debug, Default)]
pub struct Driven {
    /// Recording, submit and wait, by the wall clock (ms).
    pub wall_ms: f64,
    /// Per-stage GPU ms from the timestamps ([`Clock::Stamped`]).
    pub stamped_ms: Option<BTreeMap<String, f64>>,
    /// Per-stage wall ms of a profiled frame ([`Clock::Profiled`]); empty otherwise.
    pub profile_ms: BTreeMap<String, f64>,
    /// Mid-frame submits and waits, by reason.
    pub stalls: Vec<String>,
}

/// Records one frame with `record` into a fresh encoder labelled `label`, submits it once and
/// waits. The commands are submitted even when `record` fails part way (what it recorded is
/// valid), and then its error is returned.
pub fn drive(
    gpu: &Gpu,
    label: &str,
    clock: Clock,
    record: impl FnOnce(&mut Recorder) -> Result<(), crate::GpuError>,
) -> Result<Driven, crate::GpuError> {
    let t0 = Instant::now();
    let mut enc = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) });
    let mut rec = match clock {
        Clock::Wall => Recorder::new(gpu, &mut enc),
        Clock::Stamped(s) => Recorder::with_stamps(gpu, &mut enc, s),
        Clock::Profiled => Recorder::profiled(gpu, &mut enc),
    };
    let recorded = record(&mut rec);
    let done = rec.finish();
    gpu.submit(enc.finish());
    gpu.wait();
    let wall_ms = t0.elapsed().as_secs_f64() * 1e3;
    recorded?;
    let stamped_ms = match clock {
        Clock::Stamped(s) => Some(done.read_stamps(gpu, s)),
        _ => None,
    };
    Ok(Driven { wall_ms, stamped_ms, profile_ms: done.profile_ms, stalls: done.stalls })
}

/// Submits the encoder's commands so far (replacing it with a fresh one of the same label) and
/// waits for the device.
fn submit_and_wait(gpu: &Gpu, enc: &mut wgpu::CommandEncoder, label: &str) {
    let fresh = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) });
    let done = std::mem::replace(enc, fresh);
    gpu.submit(done.finish());
    gpu.wait();
}

/// A readback that never stalls a frame: the frame records a copy of a buffer into a staging
/// buffer mapped on submit ([`DelayedRead::record`]); the next frame takes the words if the
/// GPU has finished them ([`DelayedRead::take`], which polls the device without waiting).
/// Delayed modes (`csm:delayed=true`, `iasm:delayed=true`) use it for the previous frame's
/// reduction instead of a [`Recorder::sync`].
pub struct DelayedRead {
    staging: wgpu::Buffer,
    ready: std::sync::Arc<std::sync::atomic::AtomicBool>,
    /// A copy recorded and not yet taken.
    pending: bool,
}

impl DelayedRead {
    pub fn new(gpu: &Gpu, label: &str, size: u64) -> DelayedRead {
        let staging = gpu.buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: size.div_ceil(4).max(1) * 4,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        DelayedRead { staging, ready: Default::default(), pending: false }
    }

    /// Records the copy of `src` (its first `staging` bytes) and maps the copy when the frame's
    /// commands are done. Call [`DelayedRead::take`] first in a frame that records again.
    pub fn record(&mut self, rec: &mut Recorder, src: &wgpu::Buffer) {
        if self.pending {
            // the last copy was never taken: drop it (its mapping may still be in flight)
            let _ = self.take::<u32>(rec.gpu(), 0);
            if self.pending {
                return;
            }
        }
        let size = self.staging.size();
        let enc = rec.encoder();
        enc.copy_buffer_to_buffer(src, 0, &self.staging, 0, size);
        self.ready.store(false, std::sync::atomic::Ordering::Release);
        let ready = self.ready.clone();
        enc.map_buffer_on_submit(&self.staging, wgpu::MapMode::Read, .., move |r| {
            if r.is_ok() {
                ready.store(true, std::sync::atomic::Ordering::Release);
            }
        });
        self.pending = true;
    }

    /// The last recorded copy's first `count` values, if its frame has finished on the GPU
    /// (polls without waiting); None if nothing was recorded or it is not done yet.
    pub fn take<T: bytemuck::Pod>(&mut self, gpu: &Gpu, count: usize) -> Option<Vec<T>> {
        if !self.pending {
            return None;
        }
        let _ = gpu.device.poll(wgpu::PollType::Poll);
        if !self.ready.load(std::sync::atomic::Ordering::Acquire) {
            return None;
        }
        let out = {
            let view = self.staging.slice(..).get_mapped_range().ok()?;
            bytemuck::pod_collect_to_vec(&view[..count * std::mem::size_of::<T>()])
        };
        self.staging.unmap();
        self.pending = false;
        Some(out)
    }
}
