//! Which timer a report's figures come from. The pass name is the wgpu label and the timing
//! key (see [`crate::record`]).
//!
//! The timed figure of a frame is always one recorded frame with one submit. On hardware
//! adapters that offer timestamps inside encoders it is the span of GPU timestamps written
//! around each stage (one query set, one resolve per frame), which also gives the per-stage
//! times. On software adapters (lavapipe's timestamp queries read wrong for compute passes and
//! inside render passes) it is the whole frame's wall clock from its one submit to its one wait;
//! the per-stage breakdown then comes from a separate profiled run of the same frame with a
//! wait per stage, and is never added up as the total. `SHADOWLAB_TIMER=wall|gpu` overrides the
//! choice. Reports name the timers used.

use crate::GpuError;

/// The timed frame on a wall-clock adapter.
pub const WALL_TIMER: &str = "wall clock of the whole frame: one submit, one wait";
/// The timed frame and its stages on a timestamp adapter.
pub const TIMESTAMP_TIMER: &str = "GPU timestamps around each stage, one resolve per frame";
/// The per-stage breakdown on a wall-clock adapter.
pub const PROFILE_TIMER: &str = "profiled run: wall clock + submit and device wait per stage (a breakdown, not the frame's time)";

/// Whether to time with GPU timestamps on this adapter (when it supports them).
pub fn want_timestamps(info: &wgpu::AdapterInfo) -> Result<bool, GpuError> {
    match std::env::var("SHADOWLAB_TIMER").as_deref() {
        Ok("wall") => Ok(false),
        Ok("gpu") => Ok(true),
        Ok(other) => Err(GpuError::Invalid(format!("SHADOWLAB_TIMER={other}: expected 'wall' or 'gpu'"))),
        Err(_) => Ok(info.device_type != wgpu::DeviceType::Cpu),
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
