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
// the occluder map (the unwarped DV-cropped depth), `edge_importance`; a stand-in when off
@group(0) @binding(12) var occ: texture_depth_2d;

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

// the count's occluder texel (count.wgsl)
fn occ_at(x: u32, y: u32) -> f32 {
    return textureLoad(occ, vec2<u32>(x, y), 0);
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

// The map's sample count and its warps' texels (notw.wgsl).
fn samples_total() -> u32 {
    return atomicLoad(&dv[5]);
}

fn store_warp_x(t: vec2<u32>, o: f32) {
    textureStore(warp_x_out, t, vec4<f32>(o, 0.0, 0.0, 0.0));
}

fn store_warp_y(t: vec2<u32>, o: f32) {
    textureStore(warp_y_out, t, vec4<f32>(o, 0.0, 0.0, 0.0));
}

// NoTW's passes (notw.wgsl): a function per invocation; the smoothing over (position k, block
// of SMOOTH_BLOCK functions); a row rebuilt per invocation.
@compute @workgroup_size(64)
fn functions_rows(@builtin(global_invocation_id) id: vec3<u32>) {
    build_function(0u, id.x);
}

@compute @workgroup_size(8, 8)
fn smooth_rows(@builtin(global_invocation_id) id: vec3<u32>) {
    smooth_block(0u, id.x, id.y);
}

@compute @workgroup_size(64)
fn rebuild(@builtin(global_invocation_id) id: vec3<u32>) {
    rebuild_row(id.x);
}

@compute @workgroup_size(64)
fn functions_cols(@builtin(global_invocation_id) id: vec3<u32>) {
    build_function(1u, id.x);
}

@compute @workgroup_size(8, 8)
fn smooth_cols(@builtin(global_invocation_id) id: vec3<u32>) {
    smooth_block(1u, id.x, id.y);
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
