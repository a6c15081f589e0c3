//! `resolution_bias=auto`: the finest resolution bias whose marked pages fit the page pool,
//! chosen inside each frame (UE5 raises its resolution LOD bias when the pool is over budget;
//! here the frame marks again, one step coarser, until its pages fit), with hysteresis across
//! frames so that a view whose pages nearly fill the pool does not alternate between biases.
//!
//! Per frame: mark at [`AutoLod::first`]; while [`AutoLod::after`] says so, mark again at the
//! coarser bias it gives; then [`AutoLod::chose`] the bias the frame used. The result depends
//! only on the frames seen, never on timing.

/// The finest bias `auto` uses: the measured best fixed setting under a sun at equal memory
/// (-1.5; docs/bench/virtual.md). Finer: more pages, and rarely better where they fit.
pub const AUTO_FINEST: f32 = -1.5;
/// The coarsest: past it a full pool falls back level by level (flagged degraded), as a fixed
/// bias does.
pub const AUTO_COARSEST: f32 = 2.0;
/// One step of the search (a quarter level: about 1.4x the pages of a view's area).
pub const AUTO_STEP: f32 = 0.25;
/// A frame whose pages fill less than this share of the pool tries one step finer next frame
/// (one step needs about 1.4x the pages, so below 0.6 it most likely fits; hysteresis: between
/// 0.6 and 1 the bias stays).
pub const AUTO_REFINE_BELOW: f32 = 0.6;
/// Frames to wait after a finer step did not fit before trying it again.
pub const AUTO_RETRY_FRAMES: u32 = 8;

/// The state `auto` keeps across frames.
#[derive(Clone, Debug, PartialEq)]
pub struct AutoLod {
    /// The bias the last frame used.
    pub bias: f32,
    /// Whether the last frame's pages left room for one step finer.
    room: bool,
    /// Frames left before a finer step that failed is tried again.
    cooldown: u32,
    /// The bias this frame started at (to see whether its finer try failed).
    started: f32,
}

impl Default for AutoLod {
    fn default() -> Self {
        AutoLod { bias: AUTO_FINEST, room: false, cooldown: 0, started: AUTO_FINEST }
    }
}

impl AutoLod {
    /// The bias this frame marks first: one step finer than the last frame's when it left room
    /// (and no recent finer try failed), else the last frame's.
    pub fn first(&mut self) -> f32 {
        let finer = (self.bias - AUTO_STEP).max(AUTO_FINEST);
        self.started = if self.room && self.cooldown == 0 && finer < self.bias { finer } else { self.bias };
        self.started
    }

    /// After marking at `bias`: `Some(coarser)` to mark again when its `requested` pages do not
    /// fit the pool's `slots`, `None` when they do (or the coarsest bias is reached).
    pub fn after(bias: f32, requested: usize, slots: usize) -> Option<f32> {
        (requested > slots && bias < AUTO_COARSEST).then(|| (bias + AUTO_STEP).min(AUTO_COARSEST))
    }

    /// The frame used `bias`, with `requested` pages of `slots`.
    pub fn chose(&mut self, bias: f32, requested: usize, slots: usize) {
        if bias > self.started {
            // a finer try did not fit: wait before trying it again
            self.cooldown = if self.started < self.bias { AUTO_RETRY_FRAMES } else { 0 };
        } else {
            self.cooldown = self.cooldown.saturating_sub(1);
        }
        self.bias = bias;
        self.room = (requested as f32) < AUTO_REFINE_BELOW * slots as f32;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A view needing `pages(bias)` pages: one frame of the search; returns (bias, marks).
    fn frame(lod: &mut AutoLod, slots: usize, pages: impl Fn(f32) -> usize) -> (f32, u32) {
        let mut b = lod.first();
        let mut marks = 1;
        while let Some(c) = AutoLod::after(b, pages(b), slots) {
            b = c;
            marks += 1;
        }
        lod.chose(b, pages(b), slots);
        (b, marks)
    }

    /// Pages of a view: quadrupling per level finer (a view's area), `at0` at bias 0.
    fn area(at0: f32) -> impl Fn(f32) -> usize {
        move |b| (at0 * (-2.0 * b).exp2()).round() as usize
    }

    #[test]
    fn a_still_view_settles_on_the_finest_bias_that_fits_and_stays() {
        let mut lod = AutoLod::default();
        // 100 pages at bias 0: -1.5 needs 800, -0.5 needs 200, -0.25 needs 141 of 160
        let (b, marks) = frame(&mut lod, 160, area(100.0));
        assert_eq!((b, marks), (-0.25, 6), "five steps up from -1.5");
        for _ in 0..20 {
            // 141 of 160 leaves no room for a finer step: no extra marks, the same bias
            assert_eq!(frame(&mut lod, 160, area(100.0)), (-0.25, 1));
        }
        // everything fits at the finest bias
        let mut lod = AutoLod::default();
        assert_eq!(frame(&mut lod, 1000, area(50.0)), (-1.5, 1));
        assert_eq!(frame(&mut lod, 1000, area(50.0)), (-1.5, 1));
    }

    #[test]
    fn room_is_taken_one_step_at_a_time_and_a_failed_step_waits() {
        let mut lod = AutoLod { bias: 0.0, room: false, cooldown: 0, started: 0.0 };
        // 40 pages at 0 of 160: room while under 96 pages: -0.25 (57), -0.5 (80), then -0.75 (113)
        let seen: Vec<f32> = (0..6).map(|_| frame(&mut lod, 160, area(40.0)).0).collect();
        assert_eq!(seen, [0.0, -0.25, -0.5, -0.75, -0.75, -0.75], "113 of 160 leaves no room");
        // pages that fill 55 % but need 1.6x for a finer step: the try fails, then waits 8 frames
        let pages = |b: f32| if b < 0.0 { 200 } else { 88 };
        let mut lod = AutoLod { bias: 0.0, room: true, cooldown: 0, started: 0.0 };
        let marks: Vec<u32> = (0..10).map(|_| frame(&mut lod, 160, pages).1).collect();
        assert_eq!(lod.bias, 0.0);
        assert_eq!(marks, [2, 1, 1, 1, 1, 1, 1, 1, 1, 2], "one failed try, then eight frames without");
    }

    #[test]
    fn a_pool_too_small_at_the_coarsest_bias_stops_there() {
        let mut lod = AutoLod::default();
        let (b, marks) = frame(&mut lod, 4, area(1000.0));
        assert_eq!(b, AUTO_COARSEST);
        assert_eq!(marks, 1 + ((AUTO_COARSEST - AUTO_FINEST) / AUTO_STEP) as u32);
        assert_eq!(AutoLod::after(AUTO_COARSEST, 10_000, 4), None);
    }
}
