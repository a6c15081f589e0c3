//! Per-stage timing. The pass name is the wgpu label and the timing key.
//!
//! Two timers: GPU timestamps written on the encoder before and after each stage (on hardware
//! adapters that offer them), or wall clock with a device wait after each stage (software
//! adapters: lavapipe's timestamp queries read wrong for compute passes and inside render
//! passes). `SHADOWLAB_TIMER=wall|gpu` overrides the choice. Reports name the timer used.

use std::collections::BTreeMap;
use std::time::Instant;

use crate::{Gpu, GpuError};

pub const WALL_TIMER: &str = "wall clock + device wait per stage";
pub const TIMESTAMP_TIMER: &str = "GPU timestamps per stage";

/// Whether to time with GPU timestamps on this adapter (when it supports them).
pub fn want_timestamps(info: &wgpu::AdapterInfo) -> Result<bool, GpuError> {
    match std::env::var("SHADOWLAB_TIMER").as_deref() {
        Ok("wall") => Ok(false),
        Ok("gpu") => Ok(true),
        Ok(other) => Err(GpuError::Invalid(format!("SHADOWLAB_TIMER={other}: expected 'wall' or 'gpu'"))),
        Err(_) => Ok(info.device_type != wgpu::DeviceType::Cpu),
    }
}

#[derive(Default)]
pub struct StageTimer {
    /// Samples per stage name, in milliseconds.
    pub samples: BTreeMap<String, Vec<f64>>,
}

impl StageTimer {
    /// Records `f`'s commands in one encoder, submits, waits, and adds the stage's time under
    /// `name` (GPU timestamps when `gpu.gpu_timestamps`, else the wall clock).
    pub fn stage<R>(&mut self, gpu: &Gpu, name: &str, f: impl FnOnce(&mut wgpu::CommandEncoder) -> R) -> R {
        let t0 = Instant::now();
        let mut enc = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(name) });
        let queries = gpu.gpu_timestamps.then(|| {
            let set =
                gpu.device.create_query_set(&wgpu::QuerySetDescriptor { label: Some(name), ty: wgpu::QueryType::Timestamp, count: 2 });
            enc.write_timestamp(&set, 0);
            set
        });
        let r = f(&mut enc);
        let resolved = queries.map(|set| {
            enc.write_timestamp(&set, 1);
            let buf = gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamps"),
                size: 16,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            enc.resolve_query_set(&set, 0..2, &buf, 0);
            buf
        });
        gpu.queue.submit([enc.finish()]);
        gpu.wait();
        let wall = t0.elapsed().as_secs_f64() * 1e3;
        let ms = match resolved {
            Some(buf) => {
                let t: Vec<u64> = gpu.read_buffer_as(&buf, 2);
                t[1].saturating_sub(t[0]) as f64 * gpu.queue.get_timestamp_period() as f64 * 1e-6
            }
            None => wall,
        };
        self.add(name, ms);
        r
    }

    pub fn add(&mut self, name: &str, ms: f64) {
        self.samples.entry(name.to_string()).or_default().push(ms);
    }

    /// Median per stage.
    pub fn medians(&self) -> BTreeMap<String, f64> {
        self.samples.iter().map(|(k, v)| (k.clone(), median(v))).collect()
    }
}

pub fn median(v: &[f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let mut s = v.to_vec();
    s.sort_by(|a, b| a.total_cmp(b));
    let n = s.len();
    if n % 2 == 1 {
        s[n / 2]
    } else {
        0.5 * (s[n / 2 - 1] + s[n / 2])
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn median_of_even_and_odd() {
        assert_eq!(super::median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(super::median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
        assert_eq!(super::median(&[]), 0.0);
    }
}
