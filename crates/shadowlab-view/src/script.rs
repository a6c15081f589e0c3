//! Scripted runs, for CI, the smoke test and long sessions: render N frames (or run S seconds)
//! and exit, orbit the camera by a fixed angle per frame, change a parameter at a given frame,
//! cycle technique A through specs and turn the light every N frames, print the resident
//! memory every S seconds, write the last frame.

use std::path::PathBuf;

#[derive(Clone, Debug, Default, PartialEq)]
pub struct Script {
    /// Render this many frames, then exit (0 status).
    pub exit_after: Option<usize>,
    /// Write the last frame's picture here (PNG).
    pub screenshot: Option<PathBuf>,
    /// Turn the camera about its target by this many degrees every frame.
    pub orbit_deg: f32,
    /// Orbit only during the first this many frames, then hold still (measures how soon the
    /// reference is current after the camera stops); `None`: every frame.
    pub orbit_frames: Option<usize>,
    /// Parameter changes of technique A: (frame, key, value).
    pub set_at: Vec<(usize, String, String)>,
    /// Destroy the GPU device before this frame (tests the handling of a lost device).
    pub lose_device_at: Option<usize>,
    /// Run this many seconds, then exit (0 status), whatever the frame count.
    pub exit_after_s: Option<f64>,
    /// Technique A becomes the next of these specs every `cycle_every` frames (round robin).
    pub cycle: Vec<String>,
    pub cycle_every: usize,
    /// Turn the light about the vertical axis by this many degrees at each cycle step.
    pub light_turn_deg: f32,
    /// Print the resident memory every this many seconds (`memory: ...` lines).
    pub memory_every_s: Option<f64>,
}

impl Script {
    /// Whether the run is scripted (frame-driven stillness, no waiting on the clock).
    pub fn is_scripted(&self) -> bool {
        self.exit_after.is_some() || self.exit_after_s.is_some()
    }

    /// The spec technique A changes to before `frame` (the light turns then too).
    pub fn cycle_step(&self, frame: usize) -> Option<&str> {
        if self.cycle.is_empty() || self.cycle_every == 0 || frame == 0 || !frame.is_multiple_of(self.cycle_every) {
            return None;
        }
        Some(&self.cycle[(frame / self.cycle_every) % self.cycle.len()])
    }

    /// The changes due at `frame`.
    pub fn changes_at(&self, frame: usize) -> impl Iterator<Item = (&str, &str)> {
        self.set_at.iter().filter(move |(f, _, _)| *f == frame).map(|(_, k, v)| (k.as_str(), v.as_str()))
    }
}

/// This process's resident memory (MiB), where the system says (Linux).
pub fn resident_mib() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let kb: f64 = s.lines().find(|l| l.starts_with("VmRSS:"))?.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}

/// Parses `FRAME:KEY=VALUE` (`--set-at 3:pcf=3`).
pub fn parse_set_at(text: &str) -> Result<(usize, String, String), String> {
    let bad = || format!("--set-at '{text}': expected FRAME:KEY=VALUE, e.g. 3:pcf=3");
    let (frame, kv) = text.split_once(':').ok_or_else(bad)?;
    let (k, v) = kv.split_once('=').ok_or_else(bad)?;
    let frame: usize = frame.trim().parse().map_err(|_| bad())?;
    if k.trim().is_empty() || v.trim().is_empty() {
        return Err(bad());
    }
    Ok((frame, k.trim().to_string(), v.trim().to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn set_at_parses_and_rejects() {
        assert_eq!(parse_set_at("3:pcf=3").unwrap(), (3, "pcf".into(), "3".into()));
        for bad in ["pcf=3", "x:pcf=3", "3:pcf", "3:=1", "3:pcf="] {
            assert!(parse_set_at(bad).unwrap_err().contains("FRAME:KEY=VALUE"), "{bad}");
        }
        let s = Script { set_at: vec![parse_set_at("2:a=1").unwrap(), parse_set_at("5:b=2").unwrap()], ..Default::default() };
        assert_eq!(s.changes_at(5).collect::<Vec<_>>(), vec![("b", "2")]);
        assert_eq!(s.changes_at(3).count(), 0);
    }

    #[test]
    fn the_cycle_steps_round_robin() {
        let s = Script { cycle: vec!["sm".into(), "vsm".into(), "lt".into()], cycle_every: 4, ..Default::default() };
        let steps: Vec<_> = (0..20).filter_map(|f| s.cycle_step(f).map(|x| (f, x))).collect();
        assert_eq!(steps, [(4, "vsm"), (8, "lt"), (12, "sm"), (16, "vsm")]);
        assert_eq!(Script::default().cycle_step(4), None);
        if cfg!(target_os = "linux") {
            assert!(resident_mib().unwrap() > 1.0);
        }
    }
}
