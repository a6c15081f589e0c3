// iasm:fit=view, the square's placement on the GPU: one thread after the bounds reduction
// (csm/sdsm_bounds.wgsl with one cascade) turns the samples' light-space x/y bounds into the
// square by the rule of `shadowlab_core::techniques::iasm::fit::fit_square` (the CPU half; the
// tests hold the two together). It writes the square into the frame's IasmParams (origin, side,
// and k when k follows the side), so the importance analysis that follows bins over it, and
// into the statistics' tail, read back with them: one sync a frame, as the thesis. No sample:
// the flag word is 0 and the CPU's fixed placement, already in IasmParams, stays.
// Prepended: reduce/order_key.wgsl and `const TAIL: u32` (the first tail word of the stats).

struct FitParams {
    margin: f32,
    min_side: f32,
    // the side fitted last (the snapped side's hysteresis); 0 = none
    prev: f32,
    // snap steps per side (fit.rs `snap_divisions`)
    div: f32,
    // a held side follows down once the need is below prev * shrink
    shrink: f32,
    // size steps per octave of the snapped side
    steps: f32,
    pad0: f32,
    pad1: f32,
    // 2^(r/steps), r = 0..15 (sdsm.rs `step_fractions`): the size steps in the CPU's bits
    fracs: array<vec4<f32>, 4>,
}

// The side held in sdsm's steps (with hysteresis) and the origin on whole steps.
override SNAP: bool = true;
// k of equation 3.1 is half the side (the `k` parameter 0).
override AUTO_K: bool = true;

@group(0) @binding(0) var<uniform> fp: FitParams;
@group(0) @binding(1) var<storage, read> bounds: array<u32>;
@group(0) @binding(2) var<storage, read_write> params: array<f32>;
@group(0) @binding(3) var<storage, read_write> stats: array<u32>;

// sdsm's size_step: 2^(k/steps), the CPU's fraction times the octave's power of two (exact).
fn size_step(k: i32) -> f32 {
    let n = i32(fp.steps);
    var octave = k / n;
    if k % n < 0 {
        octave -= 1;
    }
    let r = k - octave * n;
    return ldexp(fp.fracs[r / 4][r % 4], octave);
}

// sdsm's quantize_up: the smallest size step not below x (log2 only guesses the step).
fn quantize_up(x: f32) -> f32 {
    var k = i32(ceil(log2(x) * fp.steps));
    for (var i = 0; i < 4 && size_step(k - 1) >= x; i++) {
        k -= 1;
    }
    for (var i = 0; i < 4 && size_step(k) < x; i++) {
        k += 1;
    }
    return size_step(k);
}

// sdsm's held_extent: the previous side while the need is within its shrink steps.
fn held(e: f32) -> f32 {
    if fp.prev > 0.0 && e <= fp.prev && e > fp.prev * fp.shrink {
        return fp.prev;
    }
    return quantize_up(e);
}

// Rust's f32::round: halves away from zero (WGSL's round() goes to even).
fn round_away(x: f32) -> f32 {
    let t = trunc(x);
    if abs(x - t) >= 0.5 {
        return t + sign(x);
    }
    return t;
}

@compute @workgroup_size(1)
fn main() {
    // cascade 0 after the reduction's 16-word header: lo keys (inverted), hi keys, samples
    let samples = bounds[22u];
    stats[TAIL] = select(0u, 1u, samples > 0u);
    if samples == 0u {
        return;
    }
    let lo = vec2<f32>(from_order_key(~bounds[16u]), from_order_key(~bounds[17u]));
    let hi = vec2<f32>(from_order_key(bounds[19u]), from_order_key(bounds[20u]));
    let extent = max(max(hi.x - lo.x, hi.y - lo.y), 0.0);
    let need = max(extent * (1.0 + 2.0 * max(fp.margin, 0.0)) / (1.0 - 2.0 / fp.div), max(fp.min_side, 1e-6));
    var side = need;
    if SNAP {
        side = held(need);
    }
    let centre = 0.5 * (lo + hi);
    var origin = centre - vec2<f32>(0.5 * side);
    if SNAP {
        let step = side / fp.div;
        origin = vec2<f32>(round_away(origin.x / step), round_away(origin.y / step)) * step;
    }
    // IasmParams: right.w, up.w = origin; dir.w = side; imp.y = k
    params[3] = origin.x;
    params[7] = origin.y;
    params[11] = side;
    if AUTO_K {
        params[13] = 0.5 * side;
    }
    stats[TAIL + 1u] = bitcast<u32>(origin.x);
    stats[TAIL + 2u] = bitcast<u32>(origin.y);
    stats[TAIL + 3u] = bitcast<u32>(side);
    stats[TAIL + 4u] = bitcast<u32>(lo.x);
    stats[TAIL + 5u] = bitcast<u32>(lo.y);
    stats[TAIL + 6u] = bitcast<u32>(hi.x);
    stats[TAIL + 7u] = bitcast<u32>(hi.y);
    stats[TAIL + 8u] = samples;
}
