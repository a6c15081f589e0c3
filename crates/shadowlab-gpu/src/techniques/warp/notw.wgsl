// NoTW's warps from a count map (seed 000 section 3, steps 4-7), one map's functions for
// analyze.wgsl (one map) and analyze_layers.wgsl (every layer of a warp::Layers). The includer
// provides the map's uniform `wp`, `work` (the count map from `wbase`) and `fwork` (from
// `fbase`, layout in analyze.wgsl), `samples_total()` (the DV bounds' sample count) and
// `store_warp_x`, `store_warp_y` (the warps' texels), and runs, in order: build_function (rows),
// smooth_block (rows), rebuild_row, build_function (columns), smooth_block (columns).

// Words before this map's count map in `work` and its scratch in `fwork` (0 for one map).
var<private> wbase: u32;
var<private> fbase: u32;

fn res_u() -> u32 {
    return u32(wp.res);
}

// Index of edge k of function r: rows (axis 0) are row-major, columns (axis 1) column-major.
fn at(axis: u32, r: u32, k: u32) -> u32 {
    let w = res_u();
    return select(k * w + r, r * w + k, axis == 0u);
}

// Texel k's count along function r: the sample counts (rows) or the counts rebuilt through the
// row warps (columns).
fn count_at(axis: u32, r: u32, k: u32) -> f32 {
    if axis == 0u {
        return f32(atomicLoad(&work[wbase + at(0u, r, k)]));
    }
    return fwork[fbase + at(1u, r, k)];
}

// One warping function per invocation (eq. 4), in two sweeps along it: the counts box-blurred
// (half-width `blur`, normalised by the taps inside; a sliding sum, exact for whole counts)
// plus a uniform floor (`mix` x the mean count per texel of the whole map) and their prefix
// sums, then the offsets o = g / N - x (identity for an empty function) and the total N. The
// floor bounds the magnification where a function has few samples; without the blur the
// per-texel count noise puts a kink into the warp at every texel, which linear rasterisation
// cannot follow (docs/bench/warp.md). The same sums in the same order as core warp::notw.
fn build_function(axis: u32, r: u32) {
    let w = res_u();
    if r >= w {
        return;
    }
    let n = w * w;
    let rad = u32(wp.blur);
    let floor_density = wp.mix * f32(samples_total()) / f32(n);
    var win = 0.0;
    for (var j = 0u; j <= min(rad, w - 1u); j++) {
        win += count_at(axis, r, j);
    }
    var g = 0.0;
    for (var k = 0u; k < w; k++) {
        let a = u32(max(i32(k) - i32(rad), 0));
        let b = min(k + rad, w - 1u);
        g += win / f32(b - a + 1u) + floor_density;
        fwork[fbase + n + at(axis, r, k)] = g;
        if k + rad + 1u < w {
            win += count_at(axis, r, k + rad + 1u);
        }
        if k >= rad {
            win -= count_at(axis, r, k - rad);
        }
    }
    for (var k = 0u; k < w; k++) {
        let i = n + at(axis, r, k);
        fwork[fbase + i] = select(0.0, fwork[fbase + i] / g - f32(k + 1u) / f32(w), g > 0.0);
    }
    fwork[fbase + 3u * n + r] = g;
}

// Smoothing across neighbouring functions: the average over [r - window/2, r + window/2]
// weighted by their sample totals (seed 000 Figure 4). One invocation smooths SMOOTH_BLOCK
// consecutive functions r at one position k: it sums its first window directly, then slides
// it (adds the function that enters, removes the one that leaves), so a texel costs about
// window / SMOOTH_BLOCK + 2 reads instead of window + 1 (cube-notw's window 128 made this
// the largest stage of its frame). The totals are whole sample counts, exact in f32 below
// 2^24 samples, so only the weighted sum drifts, by rounding over at most SMOOTH_BLOCK slides.
// `window_tent`: the weights also fall off as half + 1 - |r - j| (core warp::smooth); the sum
// slides by the two half-window sums, which slide like the box's.
// Set by the pipeline (warp::SMOOTH_BLOCK, which also sizes the dispatch).
override SMOOTH_BLOCK: u32;

fn weighted(axis: u32, j: u32, k: u32) -> vec2<f32> {
    let n = res_u() * res_u();
    let tj = fwork[fbase + 3u * n + j];
    return vec2<f32>(tj * fwork[fbase + n + at(axis, j, k)], tj);
}

fn smooth_block(axis: u32, k: u32, block: u32) {
    let w = res_u();
    let half = i32(u32(wp.window) / 2u);
    let r0 = block * SMOOTH_BLOCK;
    if k >= w || r0 >= w {
        return;
    }
    let tent = wp.tent > 0.5;
    var acc = vec2<f32>(0.0);
    // tent: the sums of the functions just above r (r + 1 ..= r + half + 1) and at or below it
    // (r - half ..= r), which move the tent's weighted sum by one step
    var above = vec2<f32>(0.0);
    var below = vec2<f32>(0.0);
    for (var j = max(i32(r0) - half, 0); j <= min(i32(r0) + half + 1, i32(w) - 1); j++) {
        let x = weighted(axis, u32(j), k);
        let d = abs(j - i32(r0));
        if d <= half {
            acc += select(x, x * f32(half + 1 - d), tent);
        }
        if j > i32(r0) {
            above += x;
        } else {
            below += x;
        }
    }
    for (var r = r0; r < min(r0 + SMOOTH_BLOCK, w); r++) {
        if r > r0 && tent {
            // from r - 1 to r: sum + above - below; then the two halves move up by one
            acc += above - below;
            let p = i32(r) - 1;
            let mid = weighted(axis, u32(r), k);
            above -= mid;
            below += mid;
            if p + half + 2 < i32(w) {
                above += weighted(axis, u32(p + half + 2), k);
            }
            if p - half >= 0 {
                below -= weighted(axis, u32(p - half), k);
            }
        } else if r > r0 {
            let enter = i32(r) + half;
            let leave = i32(r) - half - 1;
            if enter < i32(w) {
                acc += weighted(axis, u32(enter), k);
            }
            if leave >= 0 {
                acc -= weighted(axis, u32(leave), k);
            }
        }
        let o = select(0.0, acc.x / acc.y, acc.y > 0.0);
        if axis == 0u {
            fwork[fbase + 2u * w * w + r * w + k] = o;
            store_warp_x(vec2<u32>(k, r), o);
        } else {
            // r = column, k = edge: stored as an image, (column, edge)
            store_warp_y(vec2<u32>(r, k), o);
        }
    }
}

// The count map rebuilt through the smoothed row warps (step 6), one row per invocation: each
// texel's count spread evenly over its image [x'(k / w), x'((k + 1) / w)] under the row's own
// warp (the function at the texel's centre), the texels it covers taking their overlap's share.
// A sweep along the row (the warp is monotonic), without atomics: the same sums on every run.
// The samples are taken as spread evenly over their texel, which is what the piecewise-linear
// warp assumes; core warp::rebuild_rows is the reference.
fn rebuild_row(i: u32) {
    let w = res_u();
    if i >= w {
        return;
    }
    for (var j = 0u; j < w; j++) {
        fwork[fbase + i * w + j] = 0.0;
    }
    let fw = f32(w);
    var x0 = 0.0;
    for (var k = 0u; k < w; k++) {
        let x1 = select(f32(k + 1u) / fw + fwork[fbase + 2u * w * w + i * w + k], 1.0, k + 1u == w);
        let c = f32(atomicLoad(&work[wbase + i * w + k]));
        if c > 0.0 {
            let ja = texel_of(x0, w);
            let jb = texel_of(x1, w);
            if ja == jb || x1 <= x0 {
                fwork[fbase + i * w + ja] += c;
            } else {
                for (var j = ja; j <= jb; j++) {
                    let part = min(x1, f32(j + 1u) / fw) - max(x0, f32(j) / fw);
                    fwork[fbase + i * w + j] += c * max(part, 0.0) / (x1 - x0);
                }
            }
        }
        x0 = x1;
    }
}
