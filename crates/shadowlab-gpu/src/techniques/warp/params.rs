//! The parameter rows of `rtw`, `notw` and `notw-dv` and of the blocks the warped point-light
//! maps share: defaults as named constants with where they come from and what goes wrong when
//! too low or high. The typed settings declared from these rows are in settings.rs, the
//! [`Knobs`](super::Knobs) a warped map runs with in knobs.rs.

use shadowlab_core::params::family;
use shadowlab_core::params::ParamDef;

/// Smoothing window (functions averaged: [i - window/2, i + window/2]). 16 is the authors'
/// public code (GUIDE). Too low: neighbouring rows warp differently and long triangles bend
/// (wrong pixels along edges); too high: the warp tends to RTW's rectilinear grid.
pub const DEFAULT_WINDOW: f64 = 16.0;
/// RTW blur half-width (texels of the 1D importance): the same 16-wide window.
pub const DEFAULT_BLUR: f64 = 8.0;
/// NoTW blur of the counts along each function (half-width, texels); 0 = as the seeds.
/// Measured on courtyard (512 map, 512x512 view, subdiv 2): 0 needs ~10 M subdivision pieces
/// (per-texel kinks), 8 about 1.3 M with mix 2. Too high: the sampling evens out less.
pub const DEFAULT_NOTW_BLUR: f64 = 8.0;
/// NoTW uniform floor (fraction of the mean count per texel); 0 = as the seeds. Courtyard:
/// 0.5 -> 2.9 % wrong, 2 -> 2.0 % (bias 0.5); too high: CV and used texels drift to plain sm's.
pub const DEFAULT_MIX: f64 = 2.0;
/// NoTW constant bias (warped texels), for the default exact depth. 1024x1024 output, 512 map,
/// six setups (docs/bench/warp.md): bias 0.5 / 1 / 1.5 / 2 sum to 9.66 / 9.22 / 9.17 / 9.39 %
/// wrong; 1.5 beats the interpolated depth at bias 2 on all six. Low: acne on surfaces
/// grazing the light (courtyard spot 1.92 % at 0.5), high: leaks (conference sun 0.24 % at
/// 0.5, 0.63 at 2). With `exact_depth=false` the interpolated depth is off by up to the
/// subdivision threshold and 2 is better (courtyard sun 1 -> 1.78 %, 2 -> 1.25, 512 view).
/// Re-measured with `bias_mode=2` (docs/bench/warp_bias.md): 0.5 / 1 / 1.25 / 1.5 sum to
/// 6.453 / 5.558 / 5.393 / 5.303 % (subdiv 1). Since the depth is interpolated again (issue 48,
/// `DEFAULT_NOTW_EXACT_DEPTH`) the bias also covers the interpolation's error inside a piece:
/// `shadowlab tune` (`NOTW_DEPTH_TUNED`'s setups): at subdiv 0.35, bias 1.5 / 2 / 2.5 give a
/// train mean of 0.414 / 0.412 / 0.412 % wrong, at subdiv 0.5 0.438 / 0.430 / 0.429; suns alone
/// prefer 2.5-3 (acne on grazing receivers), spot lights 1.5 (leaks). docs/bench/warp.md.
pub const DEFAULT_NOTW_BIAS: f64 = 2.0;
/// Subdivision threshold (largest bend of a warped edge from its rasterised line, warped
/// texels); 0 = off. Courtyard 512 view: off -> 70 % wrong (rtw and notw: the floor is two
/// triangles); rtw 1 -> 0.58 % with 24 k pieces (crack-free subdivision); notw 2 -> 1.25 %
/// with 0.3 M pieces. Lower: more pieces (time, capacity), higher: bent depth, more bias
/// needed. See docs/bench/warp.md.
pub const DEFAULT_SUBDIV: f64 = 1.0;
/// NoTW: 1 warped texel (was 2). A piece's edges are chords of the warped triangle's curved
/// edges, up to this far off; the texels in between get another surface's depth, which shows as
/// acne where the light grazes a receiver (a thin sliver in the map). 1024x1024, 512 map
/// (docs/bench/warp.md): 2 -> 1 cuts `notw`'s false shadows on all six setups (courtyard sun
/// 0.59 -> 0.37 %, courtyard spot 0.28 -> 0.13, sponza sun 0.31 -> 0.11) for ~2x the pieces
/// (0.1-1.3 M). With the interpolated depth (issue 48) the threshold also bounds the depth's
/// error inside a piece, so it is finer: `shadowlab tune` over the suns of courtyard,
/// kinks-city and city_corner gives 0.339 / 0.349 / 0.377 % wrong at 0.25 / 0.5 / 0.75 (each at
/// its best bias), but 0.25 makes 7.9 pieces a texel on kinks-city-b and fills the piece
/// capacity there (drawn degraded). With two spot lights added to the train setups
/// (`NOTW_DEPTH_TUNED`) 0.35 beats 0.5 (0.412 against 0.429 %) and fits everywhere (at most
/// 6.6 pieces a texel, kinks-city-b). docs/bench/warp.md.
pub const DEFAULT_NOTW_SUBDIV: f64 = 0.35;
/// Subdivision levels (edge halvings) per triangle: 2^10 = 1024 pieces per edge, enough for a
/// triangle spanning the map at a 1-texel threshold. The authors' OpenGL code used a
/// tessellation factor of 16 (4 levels); measured too few for the big floor triangles here.
pub const DEFAULT_SUBDIV_LEVELS: f64 = 10.0;
/// Offsets interpolated between neighbouring functions (1) or eq. 6 as printed (0).
pub const DEFAULT_INTERP: f64 = 1.0;
/// DV margin (texels): samples moved by the bias offsets must stay inside the cropped map.
pub const DEFAULT_DV_MARGIN: f64 = 2.0;

// the shared map size, PCF and bias family (shadowlab_core::params::family), in warped texels
pub const RES: ParamDef = family::RES.with_range(16.0, 8192.0).with_doc("shadow map side (texels); warps are res x res");
pub const PCF: ParamDef = family::PCF.with_doc("PCF kernel width N in warped texels; 1 = hard test");
pub const BIAS: ParamDef = family::BIAS.with_doc("constant depth bias, warped texels; low: acne, high: peter-panning");
pub const SLOPE: ParamDef = family::SLOPE_BIAS.with_doc("slope-scaled bias, warped texels x tan(angle)");
pub const NORMAL_OFFSET: ParamDef = family::NORMAL_OFFSET
    .with_doc("offset along the normal in warped texels (local size from the warp's Jacobian); low: acne, high: shifted shadows");
pub const DV_MARGIN: ParamDef = ParamDef::number(
    "dv_margin",
    DEFAULT_DV_MARGIN,
    0.0,
    64.0,
    "texels added around the desired view; low: biased samples fall outside (lit)",
    "shadowlab: covers bias + normal offset",
);
pub const WINDOW: ParamDef = ParamDef::integer(
    "window",
    DEFAULT_WINDOW,
    0.0,
    1024.0,
    "NoTW smoothing window across rows/columns; low: bent edges, high: RTW-like",
    "authors' public code (GUIDE)",
);
pub const BLUR: ParamDef = ParamDef::integer(
    "blur",
    DEFAULT_BLUR,
    0.0,
    512.0,
    "RTW blur half-width of the 1D importance; low: abrupt warps, high: flat warps",
    "window 16 (GUIDE)",
);
pub const NOTW_BLUR: ParamDef = ParamDef::integer("blur", DEFAULT_NOTW_BLUR, 0.0, 512.0, "NoTW box blur half-width of the counts along each row/column before the prefix sums; 0 = the seeds' method; low: a kink per texel that subdivision must follow, high: less even sampling", "shadowlab measurement (docs/bench/warp.md)");
pub const MIX: ParamDef = ParamDef::number("mix", DEFAULT_MIX, 0.0, 100.0, "NoTW uniform floor added to every texel's count, as a fraction of the mean count per texel; 0 = the seeds' method; low: rows with few samples warp wildly (extreme magnification, folds), high: the warp fades to the identity", "shadowlab measurement (docs/bench/warp.md)");
pub const W_DV: ParamDef = ParamDef::number(
    "w_dv",
    1.0,
    0.0,
    100.0,
    "RTW desired-view importance (every sampled texel)",
    "GUIDE: importance = DV mask + (maxDistance - distance)",
);
pub const W_EYE: ParamDef =
    ParamDef::number("w_eye", 1.0, 0.0, 100.0, "RTW distance-to-eye importance weight, (max d - d) / max d", "GUIDE / Rosen 2012");
pub const NOTW_SUBDIV: ParamDef = SUBDIV.with_default(DEFAULT_NOTW_SUBDIV, NOTW_DEPTH_TUNED);
/// Where `notw`'s depth, subdivision and bias defaults come from (issue 48, step 1).
const NOTW_DEPTH_TUNED: &str = "shadowlab tune: trained on courtyard, kinks-city, city_corner (suns), lt-multi light 1 and sponza-peer light 1 (spots); validated on sponza, kinks-city-b lights 0 and 1, lt-multi lights 0 and 2, sibenik (docs/bench/warp.md, issue 48)";
pub const NOTW_BIAS: ParamDef = BIAS.with_default(DEFAULT_NOTW_BIAS, NOTW_DEPTH_TUNED);
pub const SUBDIV: ParamDef = ParamDef::number("subdiv", DEFAULT_SUBDIV, 0.0, 1024.0, "split triangles until the warp bends no edge (or centroid) by more than this many warped texels from the rasterised line; 0 = off; low: many pieces, high: bent edges", "shadowlab measurement (docs/bench/warp.md)");
pub const INTERP: ParamDef = ParamDef::flag("interp", DEFAULT_INTERP != 0.0, "interpolate offsets between neighbouring row/column functions (a continuous warp); false = eq. 6 as printed (one function per texel row: a sub-triangle crossing rows is rasterised across an offset jump)", "shadowlab measurement (docs/bench/warp.md): eq. 6 as printed leaves 40-65 % wrong on courtyard");
pub const SUBDIV_LEVELS: ParamDef = ParamDef::integer(
    "subdiv_levels",
    DEFAULT_SUBDIV_LEVELS,
    1.0,
    15.0,
    "max edge halvings per triangle (4^levels pieces); low: big triangles stay bent",
    "authors' tessellation factor 16 = 4 levels (GUIDE); 10 from shadowlab measurement",
);

/// Pieces the subdivision may add beyond the scene's triangles; 0 = automatic: 8 per triangle,
/// at least 2^21 (32 MiB), within the device's storage binding limit. `cube-notw` subdivides its
/// six faces at once: the capacity is all faces' (automatic: also at least 3 a texel of the six
/// faces; 20 bytes a piece with the faces' lists). When a level's pieces do not fit, that level
/// draws its inputs unsplit (coarser, the same on every run) and the result is flagged as
/// degraded. Low: bent edges on dense scenes; high: memory (16 bytes a piece).
pub const DEFAULT_SUBDIV_CAPACITY: f64 = 0.0;
pub const SUBDIV_CAPACITY: ParamDef = ParamDef::integer(
    "subdiv_capacity",
    DEFAULT_SUBDIV_CAPACITY,
    0.0,
    268435456.0,
    "pieces subdivision may add beyond the scene's triangles (16 bytes each; at least one per triangle; cube-notw: all six faces', 20 bytes each); 0 = 8 per triangle, at least 2^21 (cube-notw: and 3 a texel of the six faces), within the device limit; a level whose pieces do not fit is drawn unsplit (flagged degraded)",
    "shadowlab (deterministic capacity, issue 18)",
);

/// Smallest piece worth splitting, in warped texels: an edge whose warped image (its ends and
/// the three points the bend is measured at) spans less than this along both map axes is not
/// split, however much the warp bends it, because the rasteriser cannot resolve a bend inside
/// it. This bounds the pieces by the texels they cover (about 2 / min_piece^2 per texel per
/// layer) instead of by the warp's magnification. 0 = no bound (the seeds' subdivision).
/// Low: pieces explode under dense geometry near a point light (issue 18: 7.8 M pieces, 68 s a
/// frame on sibenik's vault); high: bent edges of pieces up to this size.
pub const DEFAULT_MIN_PIECE: f64 = 0.0;
pub const MIN_PIECE: ParamDef = ParamDef::number(
    "min_piece",
    DEFAULT_MIN_PIECE,
    0.0,
    64.0,
    "do not split an edge whose warped image spans less than this many warped texels (the rasteriser cannot resolve its bend); bounds the pieces by the texels; 0 = no bound; high: bent edges",
    "shadowlab (bounded subdivision, issue 18)",
);

/// Planar subdivision: how a warped edge's bend is judged. The rasteriser draws a piece's edge as
/// the chord of its curved warped image: a point of the curve strays from the chord across it
/// (its coverage: shadow edges move) and along it (the depth interpolated there belongs to
/// another point of the edge). 0: the whole displacement against `subdiv` (before issue 48).
/// > 0: the perpendicular bend against `subdiv` and the displacement along the edge against
/// this many warped texels (the interpolated depth's error, in texels of the edge's own depth
/// slope), so the two can be bounded apart. `notw`, five train views (docs/bench/warp.md): the
/// across part cannot go above 0.35 (0.5: sponza-peer's spot 0.645 -> 0.746 % wrong); at subdiv
/// 0.35, depth_split 0.7 makes 26 % fewer pieces for +0.005 points, 1.4 brings acne (courtyard
/// 0.521 -> 0.874 %). Left at 0: no point was as good as the default on the train mean.
pub const DEFAULT_DEPTH_SPLIT: f64 = 0.0;
pub const DEPTH_SPLIT: ParamDef = ParamDef::number(
    "depth_split",
    DEFAULT_DEPTH_SPLIT,
    0.0,
    1024.0,
    "planar maps: split an edge whose warped image strays along itself (which moves the interpolated depth) by more than this many warped texels, and on its perpendicular bend against subdiv; 0 = the whole displacement against subdiv",
    "shadowlab measurement (docs/bench/warp.md, issue 48)",
);

/// Tessellation (tess.wgsl, issue 48 step 2; the seeds draw with hardware tessellation): after
/// this many of the level queue's levels, the pieces left are finished in two passes instead of
/// a queue level after level: each edge gets a level from the warp's bend along it (a function
/// of the edge alone: crack-free), each piece a regular grid of its largest level (4^level
/// pieces; vertices on coarser edges moved to their nearest points), emitted at once. 0: the
/// level queue alone. `notw` on courtyard, 512x512 (docs/bench/warp.md): 3 -> 22 dispatches
/// instead of 30 and two thirds of the subdivide stage, but 6x the pieces (5.2 a texel against
/// 0.84) and 2.7x the depth pass at +0.005 points wrong; 5 -> 2.2x the pieces; 7 -> 1.4x at the
/// queue's wrong %. On the CPU rasteriser the pieces cost more than the dispatches save: off by
/// default; a GPU's trade is not measured yet. Low: square grids on big pieces (many pieces,
/// past the capacity at 1); high: the queue's dispatches.
pub const DEFAULT_TESSELLATE: f64 = 0.0;
pub const TESSELLATE: ParamDef = ParamDef::integer(
    "tessellate",
    DEFAULT_TESSELLATE,
    0.0,
    15.0,
    "after this many subdivision levels, finish the pieces left as a tessellator does (a level per edge from its bend, a regular grid per piece, one emission pass: fewer dispatches, more pieces); 0 = the level queue alone",
    "seeds 000/002: hardware tessellation; shadowlab measurement (docs/bench/warp.md, issue 48 step 2)",
);

/// Close subdivision cracks with a 3x3 depth minimum at evaluation. See `CLOSE_CRACKS`.
pub const DEFAULT_CLOSE_CRACKS: f64 = 0.0;
pub const CLOSE_CRACKS: ParamDef = ParamDef::flag("close_cracks", DEFAULT_CLOSE_CRACKS != 0.0, "test against the nearest depth of the 3x3 warped texels: closes the cracks adaptive subdivision leaves at T-junctions (light leaks through big occluders), grows occluders by one warped texel; 9 fetches per tap", "shadowlab measurement (docs/bench/warp.md)");

/// Exact depth per fragment (the warp inverted, `exact_inverse`, the triangle's plane evaluated);
/// 0 = the rasterised depth interpolated between warped vertices. See `EXACT_DEPTH`. RTW: off;
/// its smooth warp bends little at subdiv 1, so exact depth changes wrong pixels by <= 0.01
/// points on five of six setups (sponza sun 1.18 -> 1.06 %) for 1.1-1.7x the total time.
pub const DEFAULT_EXACT_DEPTH: f64 = 0.0;
/// NoTW: off, as the seeds draw it (seed 000 Algorithm 1 warps x and y only; issue 48). Exact
/// depth was the default at subdiv 1 (fewer wrong pixels there than the interpolated depth), but
/// it costs a warp inversion per fragment and the early depth test (3.6-6 fragments a texel,
/// the depth pass 165-175 ms against `rtw`'s 9-10 on courtyard). Interpolated on pieces of
/// 0.35 warped texels with bias 2 it is better and cheaper: `shadowlab tune` (`NOTW_DEPTH_TUNED`:
/// train mean 0.492 -> 0.412 % wrong), validated on six views not used to choose (0.652 ->
/// 0.607 %, no worse on 6 of 6); docs/bench/warp.md.
pub const DEFAULT_NOTW_EXACT_DEPTH: f64 = 0.0;
pub const EXACT_DEPTH: ParamDef = ParamDef::flag("exact_depth", DEFAULT_EXACT_DEPTH != 0.0, "write the exact depth per fragment: invert the warp at the fragment (exactly with `exact_inverse`, else 3 Newton steps) and evaluate the triangle's depth plane there; false = depth interpolated between warped vertices (off by up to the subdivision bend); disables early depth test", "shadowlab experiment (docs/bench/warp.md)");

pub const NOTW_EXACT: ParamDef = EXACT_DEPTH.with_default(DEFAULT_NOTW_EXACT_DEPTH, NOTW_DEPTH_TUNED);

/// Warp strength alpha: warp(u) = u + alpha * offsets (lookup.wgsl). 1 = the seeds' warp;
/// 0 = the identity (the DV crop only, `notw-dv` through the warped pipeline). A diagnostic
/// (docs/bench/warp_bias.md); not in the seeds.
pub const DEFAULT_STRENGTH: f64 = 1.0;
pub const STRENGTH: ParamDef = ParamDef::number(
    "strength",
    DEFAULT_STRENGTH,
    0.0,
    1.0,
    "warp strength: offsets scaled by this (1 = the computed warp, 0 = identity, i.e. the DV crop only); low: less even sampling",
    "shadowlab diagnostic (docs/bench/warp_bias.md)",
);
/// `notw`'s warp strength (issue 48, step 5: the authors' OpenGL code scales its warp by a warp
/// factor). A weaker warp bends edges less, so fewer pieces pass the subdivision threshold:
/// `shadowlab tune -t 'notw:strength=0.7|0.8|0.9'` (`NOTW_DEPTH_TUNED`'s setups), train mean
/// 0.415 / 0.406 / 0.410 % wrong against 0.412 at 1 with 0.60 / 0.67 / 0.75 pieces a texel
/// against 0.83; validated: 0.606 against 0.607 %, no worse on 3 of 6, 1.86 pieces a texel
/// against 2.37 (docs/bench/warp.md). Too low: the sampling evens out less (0.4: 0.434 %).
pub const DEFAULT_NOTW_STRENGTH: f64 = 0.8;
pub const NOTW_STRENGTH: ParamDef = STRENGTH.with_default(DEFAULT_NOTW_STRENGTH, NOTW_DEPTH_TUNED);

/// Bias footprint: how one warped texel's world size, which scales the constant bias and the
/// normal offset, is taken from the warp's Jacobian J at the sample (eval.wgsl). 0: cropped
/// texel / smallest singular value of J (isotropic, the largest footprint); 1: cropped texel,
/// divided only by a smallest singular value above 1; 2: the footprint along the receiver's
/// depth-gradient direction, |J^-T A^-T m| (capped by `footprint_cap`). notw: 2. 1024x1024,
/// 512 map, six setups, bias 1.5 (docs/bench/warp_bias.md): wrong % sum 7.042 (mode 0) ->
/// 5.303 (mode 2), lower on every setup (conference sun 0.437 -> 0.282, sponza sun 1.717 ->
/// 1.166); mode 1 sits between. Mode 0 leaks: where the warp compresses one direction its
/// bias grows in all directions, up to 8 cropped texels (the ceiling/wall line and the
/// whiteboard streaks of conference sun). `cube-notw`/`dpsm-notw` keep mode 0: mode 2 brings
/// acne to them (docs/bench/point_quality.md).
pub const DEFAULT_BIAS_MODE: f64 = 2.0;
pub const BIAS_MODE: ParamDef = ParamDef::integer("bias_mode", DEFAULT_BIAS_MODE, 0.0, 4.0, "world size of a warped texel for the bias and normal offset: 0 = cropped texel / smallest singular value of the warp's Jacobian (isotropic), 1 = cropped texel shrunk only where the warp magnifies in every direction, 2 = footprint along the receiver's depth gradient |J^-T A^-T m|, capped, 3 = the largest of mode 2's at the sample and one texel to each side, 4 = mode 2 with J the secant Jacobian of the warped texel the sample falls in (its corners pulled back exactly; bounded across the warp's kinks)", "shadowlab measurement (docs/bench/warp_bias.md)");
/// Cap of bias mode 2's footprint, in cropped texels; 0 = 1 / MIN_WARP_SCALE (8, as mode 0).
pub const DEFAULT_FOOTPRINT_CAP: f64 = 0.0;
pub const FOOTPRINT_CAP: ParamDef = ParamDef::number(
    "footprint_cap",
    DEFAULT_FOOTPRINT_CAP,
    0.0,
    64.0,
    "bias_mode 2: largest footprint in cropped texels (0 = 8); high: leaks under contacts where the warp compresses, low: acne there",
    "shadowlab measurement (docs/bench/warp_bias.md)",
);

/// Exact depth clamp: 0 = the piece's corner depths, 1 = the whole triangle's. A piece's edges
/// are chords of its curved warped edges, so it rasterises fragments up to `subdiv` warped
/// texels inside its neighbours, whose exact (plane) depth may lie outside the piece's own range.
pub const DEFAULT_DEPTH_CLAMP: f64 = 0.0;
pub const DEPTH_CLAMP: ParamDef = ParamDef::integer(
    "depth_clamp",
    DEFAULT_DEPTH_CLAMP,
    0.0,
    1.0,
    "exact_depth: clamp the plane depth to the corner depths of 0 = the piece, 1 = the whole triangle",
    "shadowlab measurement (docs/bench/warp_bias.md)",
);

/// Exact depth: invert the warp at each fragment exactly (1D bisections over the texel edges,
/// lookup.wgsl `unwarp_exact`) instead of 3 Newton steps, whose forward-difference Jacobian
/// straddles the warp's kinks (a residual above 0.25 warped texels falls back to the
/// interpolated depth, off by up to the subdivision bend). Off: the Newton steps.
pub const DEFAULT_EXACT_INVERSE: f64 = 0.0;
/// `notw`'s window and inversion, chosen on the quality/cost front (issue 31; `shadowlab tune`,
/// 1024x1024, docs/bench/lean.md): trained on warp-courtyard, warp-sponza and kinks-city, where
/// window 16 / 64 / 128 / 256 give a mean 0.872 / 0.688 / 0.632 / 0.648 % wrong; validated on
/// courtyard, sponza, warp-conference and kinks-city-b (not used to choose): 0.690 -> 0.539 %
/// mean, no worse on any, with 5.3x fewer subdivision pieces on courtyard (594 k -> 111 k) and
/// 5.6x on sponza. A wide window smooths the warp, so fewer edges bend past `subdiv`; the exact
/// inversion is as good or better than the Newton steps and cheaper on lavapipe. Too low: a
/// kink per function, millions of pieces; too high: RTW-like, less even sampling.
pub const DEFAULT_NOTW_WINDOW: f64 = 128.0;
pub const DEFAULT_NOTW_EXACT_INVERSE: f64 = 1.0;
const NOTW_TUNED: &str = "shadowlab tune: trained on warp-courtyard, warp-sponza, kinks-city; validated on courtyard, sponza, warp-conference, kinks-city-b (docs/bench/lean.md)";
pub const NOTW_WINDOW: ParamDef = WINDOW.with_default(DEFAULT_NOTW_WINDOW, NOTW_TUNED);
pub const EXACT_INVERSE: ParamDef = ParamDef::flag(
    "exact_inverse",
    DEFAULT_EXACT_INVERSE != 0.0,
    "exact_depth: pull fragments back through the warp exactly (bisection over the texel edges of the two 1D passes) instead of 3 Newton steps; no fallback to the interpolated depth",
    "shadowlab (NoTW kinks, issue 18; docs/bench/warp_kinks.md)",
);
pub const NOTW_EXACT_INVERSE: ParamDef = EXACT_INVERSE.with_default(DEFAULT_NOTW_EXACT_INVERSE, NOTW_TUNED);

/// Exact depth only where it changes the map (`exact_tol`, issue 48 step 1): a piece's
/// interpolated depth and its exact (plane) depth both lie within its corners' depth range, so
/// they differ by at most the corners' spread along the light's axis. A piece whose corners
/// spread less than `exact_tol` texels of world size there (`texel_world`; perspective maps: at
/// the piece's distance) keeps the interpolated depth, and its fragments invert nothing: the
/// faces and walls that face the light, leaving the inversion to grazing receivers. 0: every
/// fragment inverts the warp. Planar maps; `cube-notw` draws its flat pieces without the
/// exact-depth fragment stage (subdiv_layers.rs). Default 0: by the tune's rule on `cube-notw`
/// (train room light 1, point-courtyard; validate conference light 1, sponza-peer; 512x512) no
/// tolerance beat the exact depth on train; 1 ties on three views and costs sponza-peer 0.0006
/// points at 0.77x the frame (docs/bench/warp.md, issue 48).
pub const DEFAULT_EXACT_TOL: f64 = 0.0;
pub const EXACT_TOL: ParamDef = ParamDef::number(
    "exact_tol",
    DEFAULT_EXACT_TOL,
    0.0,
    64.0,
    "exact_depth: a piece whose corners spread less than this along the light's axis (texels of world size) keeps the interpolated depth, off by at most that spread; 0 = every fragment inverts the warp",
    "shadowlab (issue 48, step 1: exact depth only where the interpolated one is off)",
);

/// Subdivision leaves an edge unsplit when an unwarped occluder map (the scene drawn into the
/// DV-cropped map, res x res, then a pyramid of maxima) is nearer than the edge all around it:
/// the bend of a hidden edge cannot show. Planar maps (`notw`, `cube-notw`'s faces); see
/// warp/occluders.rs and docs/bench/stress.md (bounded cost). Off: the occluder map is
/// point-sampled at res, and where the warp magnifies a grazing wall that is a sliver of base
/// texels its edges look hidden: `notw` on the built-in city went 1.138 -> 2.251 % wrong (false
/// shadows on lit walls); cube-notw kept its quality on five point-light views (38-40 % fewer
/// pieces on room and the lantern).
pub const DEFAULT_CULL_HIDDEN: f64 = 0.0;
pub const CULL_HIDDEN: ParamDef = ParamDef::flag(
    "cull_hidden",
    DEFAULT_CULL_HIDDEN != 0.0,
    "do not split edges that lie behind nearer geometry (an unwarped occluder map and its pyramid of maxima, drawn first): fewer pieces on layered scenes; an edge judged hidden is drawn unsplit, never dropped",
    "shadowlab measurement (bounded cost, issue 18; BENCHMARKS.md)",
);

/// Smoothing across functions with a tent instead of the seeds' box: each function's weight
/// also falls off linearly with its distance, so one with many samples enters the average
/// gradually. With the box, sparse samples (far fewer than texels: a cube face few view samples
/// fall on) leave steps between neighbouring functions, edges crossing them bend by the step
/// however short they are, and subdivision splits them to its last level. See BENCHMARKS.md
/// (bounded cost, issue 18). Off here (`notw`, `dpsm-notw`): the seeds' box; `cube-notw` turns
/// it on (cube::DEFAULT_NOTW_WINDOW_TENT: better and 1.4-3.4x fewer pieces on the four held-out
/// point views at 512x512). Held-out views at 512x512, wrong % box -> tent: `notw` warp-courtyard 0.785 -> 0.950,
/// warp-sponza 1.266 -> 1.262, warp-conference 0.559 -> 0.526, city 1.089 -> 0.961, eaves sun
/// 1.174 -> 1.232 (mixed: kept off); `dpsm-notw` room 0.376 -> 0.355, lantern 0.302 -> 0.275,
/// conference 0.474 -> 0.501, eaves 0.654 -> 0.598 (three of four: kept off).
pub const DEFAULT_WINDOW_TENT: f64 = 0.0;
pub const WINDOW_TENT: ParamDef = ParamDef::flag(
    "window_tent",
    DEFAULT_WINDOW_TENT != 0.0,
    "smooth across functions with tent weights (window/2 + 1 - distance) x samples instead of the seeds' box: no steps between neighbouring functions where a function with many samples enters the window",
    "seed 000 section 3.1 (the box); tent: shadowlab (bounded cost, issue 18; BENCHMARKS.md)",
);

/// Importance that follows shadow edges: a view sample whose 3x3 texels of the unwarped
/// occluder map (`cull_hidden`'s pass, drawn before the count map when this is on) hold both an
/// occluder clearly nearer than the sample and none (its own surface) lies on a shadow edge,
/// and counts `1 + edge_importance` in the count map instead of 1, so the warp gives edges
/// more texels (RTW's edge term, after Rosen 2012, on NoTW's count map). Planar maps (`notw`,
/// `cube-notw`'s faces). 0 here: the seeds' count of samples only; `cube-notw` uses 8
/// (cube::DEFAULT_NOTW_EDGE_IMPORTANCE: 0.57-0.86x its wrong pixels on five point views). Under
/// a sun it is worse (512x512, k = 0 / 8 / 16: city 1.089 / 1.973 / 2.348, warp-courtyard
/// 0.785 / 2.056 / 4.915): the orthographic test's fixed gap (0.5 % of the depth range) flags
/// ground seen at a low sun, whose depth steps more than that per texel, as edges everywhere;
/// a gap from the receiver's slope is the next step.
pub const DEFAULT_EDGE_IMPORTANCE: f64 = 0.0;
pub const EDGE_IMPORTANCE: ParamDef = ParamDef::integer(
    "edge_importance",
    DEFAULT_EDGE_IMPORTANCE,
    0.0,
    256.0,
    "extra count of a view sample on a shadow edge of the unwarped occluder map (0 = samples only): more texels for shadow edges",
    "shadowlab (point-light importance, issue 18); edge term: Rosen 2012 (RTW)",
);

/// `bias_mode` at 0 (isotropic footprint): what rtw, notw-dv, dpsm and the point-light NoTWs
/// run with; the gradient footprint (2) was measured for `notw` only.
pub const BIAS_MODE_ISOTROPIC: ParamDef =
    BIAS_MODE.with_default(0.0, "the isotropic footprint the gradient footprint was measured against (docs/bench/warp_bias.md)");
