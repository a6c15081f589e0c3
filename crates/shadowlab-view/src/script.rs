//! Scripted runs, for CI and the smoke test: render N frames and exit, orbit the camera by a
//! fixed angle per frame, change a parameter at a given frame, write the last frame.

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
}

impl Script {
    /// Whether the run is scripted (frame-driven stillness, no waiting on the clock).
    pub fn is_scripted(&self) -> bool {
        self.exit_after.is_some()
    }

    /// The changes due at `frame`.
    pub fn changes_at(&self, frame: usize) -> impl Iterator<Item = (&str, &str)> {
        self.set_at.iter().filter(move |(f, _, _)| *f == frame).map(|(_, k, v)| (k.as_str(), v.as_str()))
    }
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
}
