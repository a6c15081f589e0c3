//! The per-frame plan of `iasm` from the analysis read back (thesis 3.4, 3.5): empty tiles,
//! per-tile near/far planes (the receivers' depth range, extended towards the light to every
//! chunk over the tile), culled draws, ranking, resolutions and offsets. The decisions
//! themselves are `shadowlab_core::techniques::iasm`'s; this glues them to the GPU readback.

use glam::Vec3;
use shadowlab_core::techniques::iasm::{self as core, Placement, THESIS_RESOLUTIONS, TILE_COUNT};

/// Words of the analysis's statistics (analysis.wgsl): 8 per tile, then the samples outside.
pub(super) const STATS_WORDS: usize = TILE_COUNT * 8 + 1;
/// Words the fit (fit.rs, fit.wgsl) writes after the statistics: a flag (1: fitted, 0: no
/// sample), the square's origin x, y and side, the samples' bounds x0, y0, x1, y1 (f32 bits)
/// and their count.
pub(super) const FIT_WORDS: usize = 9;
/// Words read back a frame: the statistics, then `fit=view`'s square (unused without it).
pub(super) const READ_WORDS: usize = STATS_WORDS + FIT_WORDS;

/// What the analysis found per tile.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TileStats {
    pub importance: [f64; TILE_COUNT],
    pub samples: [u32; TILE_COUNT],
    pub depth_min: [f32; TILE_COUNT],
    pub depth_max: [f32; TILE_COUNT],
    /// Evaluated samples outside the square (lit: no shadow data there).
    pub outside: u32,
}

/// The f32 of an ordered key (the atomics' encoding of analysis.wgsl and bounds.wgsl).
pub(crate) fn unkey(k: u32) -> f32 {
    f32::from_bits(if k & 0x8000_0000 != 0 { k & 0x7fff_ffff } else { !k })
}

impl TileStats {
    pub(super) fn parse(w: &[u32]) -> TileStats {
        let mut s = TileStats::default();
        for t in 0..TILE_COUNT {
            let b = &w[t * 8..t * 8 + 8];
            s.importance[t] = ((b[1] as u64) << 32 | b[0] as u64) as f64 / 64.0;
            s.samples[t] = b[2];
            s.depth_min[t] = unkey(b[3]);
            s.depth_max[t] = unkey(b[4]);
        }
        s.outside = w[TILE_COUNT * 8];
        s
    }
}

/// The plan of one frame: placement, per-tile resolution (0 = empty), layout, planes, draws.
#[derive(Clone, Debug, Default)]
pub struct Plan {
    pub stats: TileStats,
    pub order: [usize; TILE_COUNT],
    pub res: [u32; TILE_COUNT],
    pub empty: [bool; TILE_COUNT],
    pub off: [u32; TILE_COUNT],
    pub near: [f32; TILE_COUNT],
    pub far: [f32; TILE_COUNT],
    /// Vertex ranges drawn per tile.
    pub draws: Vec<Vec<(u32, u32)>>,
}

/// Ranks, assigns, lays out, sets planes and culls (thesis 3.4, 3.5) from `stats` over the
/// square `p`, with the light-space `boxes` of the chunks (`chunk` triangles each, `triangles`
/// in all).
pub(super) fn make_plan(stats: TileStats, p: &Placement, boxes: &[(Vec3, Vec3)], chunk: u32, triangles: u32) -> Plan {
    let mut plan = Plan { stats, ..Default::default() };
    let mut empty: [bool; TILE_COUNT] = std::array::from_fn(|t| stats.samples[t] == 0);
    for (t, e) in empty.iter_mut().enumerate() {
        if *e {
            plan.draws.push(Vec::new());
            continue;
        }
        let (mut near, far) = (stats.depth_min[t], stats.depth_max[t]);
        // chunks over the tile that can cast onto its receivers (not wholly beyond them)
        let culled: Vec<usize> = core::cull(p, t, boxes).into_iter().filter(|&c| boxes[c].0.z <= far).collect();
        for &c in &culled {
            near = near.min(boxes[c].0.z);
        }
        let draws = core::runs(&culled).into_iter().map(|(a, b)| (a as u32 * chunk * 3, (b as u32 * chunk).min(triangles) * 3));
        *e = culled.is_empty();
        let margin = 1e-3 * (far - near).abs().max(1e-3 * p.size);
        plan.near[t] = near - margin;
        plan.far[t] = far + margin;
        plan.draws.push(if *e { Vec::new() } else { draws.collect() });
    }
    let imp: [f64; TILE_COUNT] = std::array::from_fn(|t| if empty[t] { 0.0 } else { stats.importance[t] });
    plan.order = core::rank(&imp, &empty);
    plan.res = core::assign(&plan.order, &THESIS_RESOLUTIONS);
    plan.off = core::offsets(&plan.res);
    plan.empty = empty;
    plan
}
