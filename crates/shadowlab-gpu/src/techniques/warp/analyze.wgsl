// Building the warp from the view samples (seed 000 section 3, steps 2-7; RTW: seed 002
// Algorithm 1). Entry points run in this order: dv_reduce, count, then for NoTW
// functions_rows, smooth_rows, rebuild, functions_cols, smooth_cols; for RTW rtw_collapse,
// rtw_blur, (prefix sums) rtw_offsets. A paraboloid map analyses only the view samples of its
// hemisphere (`owns_sample`).
//
// NoTW: work (u32): counts [0,n).  fwork (f32): counts rebuilt through the row warps [0,n) |
// prefix sums, then unsmoothed offsets [n,2n) | smoothed row offsets [2n,3n) | totals [3n,3n+w).
// RTW: work (u32): counts [0,n) | importance as f32 bits [n,2n) | blurred 1D importance as f32
// bits [2n,2n+2w).  fwork (f32): prefix sums [0,2w) | collapsed importance [2w,4w).  n = w*w.

@group(0) @binding(6) var<uniform> wp: WarpParams;
@group(0) @binding(7) var<storage, read_write> dv: array<atomic<u32>, 8>;
@group(0) @binding(8) var<storage, read_write> work: array<atomic<u32>>;
@group(0) @binding(9) var<storage, read_write> fwork: array<f32>;
@group(0) @binding(10) var warp_x_out: texture_storage_2d<r32float, write>;
@group(0) @binding(11) var warp_y_out: texture_storage_2d<r32float, write>;
// the occluder map's pyramid (level 0 first: the unwarped DV-cropped depth), `edge_importance`
@group(0) @binding(12) var<storage, read> occ: array<f32>;

fn res_u() -> u32 {
    return u32(wp.res);
}

fn dv_now() -> vec4<f32> {
    return dv_from_bounds(wp, vec4<u32>(atomicLoad(&dv[0]), atomicLoad(&dv[1]), atomicLoad(&dv[2]), atomicLoad(&dv[3])));
}

// DV: parallel min/max of the samples' map coordinates (fixed point), per workgroup in shared
// memory (dv.wgsl), then one global atomic per workgroup; also the largest eye distance (RTW)
// and the sample count.
const DV_SLOTS: u32 = 1u;

@compute @workgroup_size(8, 8)
fn dv_reduce(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) t: u32) {
    var s: Sample;
    let counted = load_sample(id, &s) && owns_sample(wp, s.p);
    dv_workgroup(t, 0u, counted, wp, s.p);
    if t == 0u {
        atomicMin(&dv[0], dv_slot(0u, 0u));
        atomicMin(&dv[1], dv_slot(0u, 1u));
        atomicMax(&dv[2], dv_slot(0u, 2u));
        atomicMax(&dv[3], dv_slot(0u, 3u));
        atomicMax(&dv[4], dv_slot(0u, 4u));
        atomicAdd(&dv[5], dv_slot(0u, 5u));
    }
}

// the count's occluder texel (count.wgsl): level 0 of the pyramid
fn occ_at(x: u32, y: u32) -> f32 {
    return occ[y * res_u() + x];
}

// Count map (NoTW importance) by atomic adds (a shadow-edge sample counts 1 + edge_importance,
// count.wgsl); RTW: importance map, maximum per texel. Maps of a warp::Layers whose owner reads
// the view are counted by count_layers.wgsl instead.
@compute @workgroup_size(8, 8)
fn count(@builtin(global_invocation_id) id: vec3<u32>) {
    var s: Sample;
    if !load_sample(id, &s) || !owns_sample(wp, s.p) {
        return;
    }
    let u = map_coords(s.p, dv_now());
    if !inside(u) {
        return;
    }
    let t = count_index(u);
    atomicAdd(&work[t], sample_weight(s.p, u));
    if wp.rtw_importance != 0u {
        let w = res_u();
        let maxd = bitcast<f32>(atomicLoad(&dv[4]));
        let d = distance(s.p, frame.camera_pos.xyz);
        let imp = wp.w_dv + wp.w_eye * clamp((maxd - d) / max(maxd, 1e-20), 0.0, 1.0);
        atomicMax(&work[w * w + t], bitcast<u32>(imp));
    }
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
        return f32(atomicLoad(&work[at(0u, r, k)]));
    }
    return fwork[at(1u, r, k)];
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
    let floor_density = wp.mix * f32(atomicLoad(&dv[5])) / f32(n);
    var win = 0.0;
    for (var j = 0u; j <= min(rad, w - 1u); j++) {
        win += count_at(axis, r, j);
    }
    var g = 0.0;
    for (var k = 0u; k < w; k++) {
        let a = u32(max(i32(k) - i32(rad), 0));
        let b = min(k + rad, w - 1u);
        g += win / f32(b - a + 1u) + floor_density;
        fwork[n + at(axis, r, k)] = g;
        if k + rad + 1u < w {
            win += count_at(axis, r, k + rad + 1u);
        }
        if k >= rad {
            win -= count_at(axis, r, k - rad);
        }
    }
    for (var k = 0u; k < w; k++) {
        let i = n + at(axis, r, k);
        fwork[i] = select(0.0, fwork[i] / g - f32(k + 1u) / f32(w), g > 0.0);
    }
    fwork[3u * n + r] = g;
}

@compute @workgroup_size(64)
fn functions_rows(@builtin(global_invocation_id) id: vec3<u32>) {
    build_function(0u, id.x);
}

@compute @workgroup_size(64)
fn functions_cols(@builtin(global_invocation_id) id: vec3<u32>) {
    build_function(1u, id.x);
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
    let tj = fwork[3u * n + j];
    return vec2<f32>(tj * fwork[n + at(axis, j, k)], tj);
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
            fwork[2u * w * w + r * w + k] = o;
            textureStore(warp_x_out, vec2<u32>(k, r), vec4<f32>(o, 0.0, 0.0, 0.0));
        } else {
            // r = column, k = edge: stored as an image, (column, edge)
            textureStore(warp_y_out, vec2<u32>(r, k), vec4<f32>(o, 0.0, 0.0, 0.0));
        }
    }
}

// Dispatched over (position k, block of SMOOTH_BLOCK functions).
@compute @workgroup_size(8, 8)
fn smooth_rows(@builtin(global_invocation_id) id: vec3<u32>) {
    smooth_block(0u, id.x, id.y);
}

@compute @workgroup_size(8, 8)
fn smooth_cols(@builtin(global_invocation_id) id: vec3<u32>) {
    smooth_block(1u, id.x, id.y);
}

// The count map rebuilt through the smoothed row warps (step 6), one row per invocation: each
// texel's count spread evenly over its image [x'(k / w), x'((k + 1) / w)] under the row's own
// warp (the function at the texel's centre), the texels it covers taking their overlap's share.
// A sweep along the row (the warp is monotonic), without atomics: the same sums on every run.
// The samples are taken as spread evenly over their texel, which is what the piecewise-linear
// warp assumes; core warp::rebuild_rows is the reference.
@compute @workgroup_size(64)
fn rebuild(@builtin(global_invocation_id) id: vec3<u32>) {
    let w = res_u();
    let i = id.x;
    if i >= w {
        return;
    }
    for (var j = 0u; j < w; j++) {
        fwork[i * w + j] = 0.0;
    }
    let fw = f32(w);
    var x0 = 0.0;
    for (var k = 0u; k < w; k++) {
        let x1 = select(f32(k + 1u) / fw + fwork[2u * w * w + i * w + k], 1.0, k + 1u == w);
        let c = f32(atomicLoad(&work[i * w + k]));
        if c > 0.0 {
            let ja = texel_of(x0, w);
            let jb = texel_of(x1, w);
            if ja == jb || x1 <= x0 {
                fwork[i * w + ja] += c;
            } else {
                for (var j = ja; j <= jb; j++) {
                    let part = min(x1, f32(j + 1u) / fw) - max(x0, f32(j) / fw);
                    fwork[i * w + j] += c * max(part, 0.0) / (x1 - x0);
                }
            }
        }
        x0 = x1;
    }
}

// RTW: importance collapsed by maximum per column (t < w: the density of x) and per row
// (t >= w: the density of y).
@compute @workgroup_size(64)
fn rtw_collapse(@builtin(global_invocation_id) id: vec3<u32>) {
    let w = res_u();
    let t = id.x;
    if t >= 2u * w {
        return;
    }
    let base = w * w;
    var m = 0.0;
    for (var j = 0u; j < w; j++) {
        let idx = select(base + j * w + t, base + (t - w) * w + j, t >= w);
        m = max(m, bitcast<f32>(atomicLoad(&work[idx])));
    }
    fwork[2u * w + t] = m;
}

// Box blur of half-width imp.z (normalised by the taps inside), into work as f32 bits.
@compute @workgroup_size(64)
fn rtw_blur(@builtin(global_invocation_id) id: vec3<u32>) {
    let w = res_u();
    let t = id.x;
    if t >= 2u * w {
        return;
    }
    let k = t % w;
    let first = t - k;
    let rad = u32(wp.blur);
    let a = max(i32(k) - i32(rad), 0);
    let b = min(k + rad, w - 1u);
    var sum = 0.0;
    for (var j = u32(a); j <= b; j++) {
        sum += fwork[2u * w + first + j];
    }
    atomicStore(&work[2u * w * w + t], bitcast<u32>(sum / f32(b - u32(a) + 1u)));
}

// RTW's two 1D warps from the prefix sums of the blurred importance (runs 0: x, 1: y).
@compute @workgroup_size(64)
fn rtw_offsets(@builtin(global_invocation_id) id: vec3<u32>) {
    let w = res_u();
    let t = id.x;
    if t >= 2u * w {
        return;
    }
    let k = t % w;
    let first = t - k;
    let total = fwork[first + w - 1u];
    var o = 0.0;
    if total > 0.0 {
        o = fwork[t] / total - f32(k + 1u) / f32(w);
    }
    if t < w {
        textureStore(warp_x_out, vec2<u32>(k, 0u), vec4<f32>(o, 0.0, 0.0, 0.0));
    } else {
        textureStore(warp_y_out, vec2<u32>(0u, k), vec4<f32>(o, 0.0, 0.0, 0.0));
    }
}
