//! Per-stage timing. On every adapter here we use wall clock with a device wait after each
//! stage: lavapipe's timestamp queries read wrong for compute passes and inside render passes.
//! The pass name is the wgpu label and the timing key.

use std::collections::BTreeMap;
use std::time::Instant;

use crate::Gpu;

/// Name of the timer used, printed with every time.
pub const TIMER_NAME: &str = "wall-clock + device wait per stage";

#[derive(Default)]
pub struct StageTimer {
    /// Samples per stage name, in milliseconds.
    pub samples: BTreeMap<String, Vec<f64>>,
}

impl StageTimer {
    /// Records `f`'s commands in one encoder, submits, waits, and adds the elapsed time under `name`.
    pub fn stage<R>(&mut self, gpu: &Gpu, name: &str, f: impl FnOnce(&mut wgpu::CommandEncoder) -> R) -> R {
        let t0 = Instant::now();
        let mut enc = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(name) });
        let r = f(&mut enc);
        gpu.queue.submit([enc.finish()]);
        gpu.wait();
        self.add(name, t0.elapsed().as_secs_f64() * 1e3);
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
