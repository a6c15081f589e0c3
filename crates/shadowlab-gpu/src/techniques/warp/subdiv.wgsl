// Adaptive subdivision against the bending of long warped edges (both seeds' limitation; wgpu
// has no tessellation stage). A piece is a triangle index and three corners as barycentrics
// (b1, b2) in unorm16x2. A piece needs splitting when the warp bends it by more than the
// threshold: the distance, in warped texels, between the warped image of points on its edges
// (and its centroid) and where linear rasterisation puts them. split_root sorts the scene's triangles: kept whole
// in their own slot of `pieces`, or queued. Each split_level pass halves the queued pieces'
// edges (4 children), appends the finished ones after the triangles and queues the rest
// (queue in/out ping-pong, indirect dispatch). The last level finishes everything. Full
// queues finish early; a full piece list drops pieces (counted: holes in the map).
//
// counters: [appended, dropped, queue-full finishes, -, draw args (4), queue 0: count, groups
// x, y, z, queue 1: count, groups x, y, z].

struct Level {
    // x: level (1..), y: 1 on the last level, z: input queue (0 or 1), w: capacity per queue
    v: vec4<u32>,
}

@group(0) @binding(10) var<storage, read_write> pieces: array<vec4<u32>>;
@group(0) @binding(11) var<storage, read_write> counters: array<atomic<u32>, 16>;
@group(0) @binding(12) var<storage, read_write> q_in: array<vec4<u32>>;
@group(0) @binding(13) var<storage, read_write> q_out: array<vec4<u32>>;
@group(0) @binding(14) var<uniform> lv: Level;

fn corner(c: u32) -> vec2<u32> {
    return vec2<u32>(c & 0xffffu, c >> 16u);
}

fn pack_corner(b: vec2<u32>) -> u32 {
    return b.x | (b.y << 16u);
}

fn corner_pos(tri: u32, c: u32) -> vec3<f32> {
    let b = vec2<f32>(corner(c)) / 65535.0;
    let v0 = vertices[3u * tri].pos;
    return v0 + (vertices[3u * tri + 1u].pos - v0) * b.x + (vertices[3u * tri + 2u].pos - v0) * b.y;
}

// How far the warped edge strays from the straight line the rasteriser draws between its
// warped ends (warped texels), sampled at 1/4, 1/2 and 3/4.
fn edge_error(ma: vec2<f32>, mb: vec2<f32>, wa: vec2<f32>, wb: vec2<f32>) -> f32 {
    var e = 0.0;
    for (var s = 1u; s <= 3u; s++) {
        let t = f32(s) / 4.0;
        e = max(e, distance(warp(mix(ma, mb, t)), mix(wa, wb, t)));
    }
    return e * wp.texel.z;
}

// A piece needs splitting when the warp bends it by more than the threshold (warped texels)
// along an edge or at its centroid, it is in front of the light and overlaps the cropped map.
fn needs_split(p: vec4<u32>) -> bool {
    let r = dv_rect();
    let a = base_clip(wp, corner_pos(p.x, p.y));
    let b = base_clip(wp, corner_pos(p.x, p.z));
    let c = base_clip(wp, corner_pos(p.x, p.w));
    if min(min(a.w, b.w), c.w) <= 1e-7 {
        return false;
    }
    let ua = to_dv(clip_to_map(a).xy, r);
    let ub = to_dv(clip_to_map(b).xy, r);
    let uc = to_dv(clip_to_map(c).xy, r);
    let lo = min(min(ua, ub), uc);
    let hi = max(max(ua, ub), uc);
    if any(hi < vec2<f32>(0.0)) || any(lo > vec2<f32>(1.0)) {
        return false;
    }
    let wa = warp(ua);
    let wb = warp(ub);
    let wc = warp(uc);
    let centre = distance(warp((ua + ub + uc) / 3.0), (wa + wb + wc) / 3.0) * wp.texel.z;
    let e = max(max(edge_error(ua, ub, wa, wb), edge_error(ub, uc, wb, wc)), max(edge_error(uc, ua, wc, wa), centre));
    return e > wp.imp.w;
}

fn finish(p: vec4<u32>) {
    let i = atomicAdd(&counters[0], 1u);
    if i >= wp.ints.z {
        atomicAdd(&counters[1], 1u);
        return;
    }
    pieces[wp.ints.x + i] = p;
}

fn enqueue(p: vec4<u32>, q: u32) {
    let i = atomicAdd(&counters[8u + 4u * q], 1u);
    if i >= lv.v.w {
        atomicAdd(&counters[2], 1u);
        finish(p);
        return;
    }
    q_out[i] = p;
}

@compute @workgroup_size(64)
fn split_root(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) l: u32) {
    let tri = (wg.y * 65535u + wg.x) * 64u + l;
    if tri >= wp.ints.x {
        return;
    }
    let p = vec4<u32>(tri, 0u, 0xffffu, 0xffff0000u);
    if needs_split(p) {
        pieces[tri] = vec4<u32>(tri, 0u, 0u, 0u);
        enqueue(p, 0u);
    } else {
        pieces[tri] = p;
    }
}

// Before level lv.x: groups for the input queue, an empty output queue.
@compute @workgroup_size(1)
fn split_args() {
    let qi = 8u + 4u * lv.v.z;
    let qo = 8u + 4u * (1u - lv.v.z);
    let n = min(atomicLoad(&counters[qi]), lv.v.w);
    atomicStore(&counters[qi + 1u], (n + 63u) / 64u);
    atomicStore(&counters[qi + 2u], 1u);
    atomicStore(&counters[qi + 3u], 1u);
    atomicStore(&counters[qo], 0u);
}

@compute @workgroup_size(64)
fn split_level(@builtin(global_invocation_id) id: vec3<u32>) {
    let n = min(atomicLoad(&counters[8u + 4u * lv.v.z]), lv.v.w);
    if id.x >= n {
        return;
    }
    let p = q_in[id.x];
    let a = corner(p.y);
    let b = corner(p.z);
    let c = corner(p.w);
    let ab = pack_corner((a + b) / 2u);
    let bc = pack_corner((b + c) / 2u);
    let ca = pack_corner((c + a) / 2u);
    let kids = array<vec4<u32>, 4>(
        vec4<u32>(p.x, p.y, ab, ca),
        vec4<u32>(p.x, ab, p.z, bc),
        vec4<u32>(p.x, ca, bc, p.w),
        vec4<u32>(p.x, ab, bc, ca),
    );
    for (var k = 0u; k < 4u; k++) {
        if lv.v.y != 0u || !needs_split(kids[k]) {
            finish(kids[k]);
        } else {
            enqueue(kids[k], 1u - lv.v.z);
        }
    }
}

@compute @workgroup_size(1)
fn draw_args() {
    let appended = min(atomicLoad(&counters[0]), wp.ints.z);
    atomicStore(&counters[4], 3u * (wp.ints.x + appended));
    atomicStore(&counters[5], 1u);
    atomicStore(&counters[6], 0u);
    atomicStore(&counters[7], 0u);
}
