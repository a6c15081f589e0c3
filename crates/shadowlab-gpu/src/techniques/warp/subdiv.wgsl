// Adaptive subdivision against the bending of long warped edges (both seeds' limitation; wgpu
// has no tessellation stage). A piece is a triangle index and three corners as barycentrics
// (b1, b2) in unorm16x2. An edge needs splitting when the warp bends it by more than the
// threshold: the distance, in warped texels, between the warped image of points on it and
// where linear rasterisation puts them. The decision depends on the edge alone and only the
// edges that need it are split (bisection patterns with 2, 3 or 4 children), so neighbours
// agree and no T-junction cracks appear (up to the level cap). split_root sorts the scene's triangles: kept whole
// in their own slot of `pieces`, or queued. Each split_level pass halves the queued pieces'
// edges (4 children), appends the finished ones after the triangles and queues the rest
// (queue in/out ping-pong, indirect dispatch). The last level finishes everything.
//
// Capacity, deterministically: which pieces an atomic append order lets through must not decide
// the map. A queued piece carries its split mask (computed once, when it was queued), so the
// pieces a level will produce are known before it runs, added up per bucket of triangle
// indices (sums: the same in any order). split_args splits the pieces of the first buckets whose
// children all fit (as finished pieces, and before the last level in the next queue) and the
// level finishes the rest unsplit (coarser, complete; counted). The set of pieces, and so the
// depth map (a minimum), is then the same on every run.
//
// counters: [appended, dropped (never: kept for the report), queue-full finishes (never), -,
// draw args (4), queue 0: count, groups x, y, z, queue 1: count, groups x, y, z, -, -, split
// limit of the running level (pieces of triangles below it split), first level cut (0: none),
// pieces finished unsplit, bent edges left unsplit as hidden (per test: an edge counts once
// per piece on it), -, -], then per queue BUCKETS children and BUCKETS pieces by
// bucket of triangle index (and over layers, subdiv_layers.wgsl's words after those).
//
// The composing file binds the map's lookup (bindings 6-9) and defines `enter_triangle` (the
// map a triangle is drawn into: one map, or a layer of a warp::Layers), `hzb_base` and
// `finished` (a finished piece as it is stored), and the draw arguments: subdiv_map.wgsl (one
// map), subdiv_layers.wgsl (every layer at once).

// Fixed at pipeline creation (subdiv.rs; PARABOLOID and WARPED in params.wgsl): `cull_hidden`,
// the triangles subdivided (their pieces' slots come first) and the pieces they may add.
override CULL_HIDDEN: bool;
override TRIANGLES: u32;
override EXTRA_CAPACITY: u32;

struct Level {
    // x: level (1..), y: 1 on the last level, z: input queue (0 or 1), w: capacity per queue
    v: vec4<u32>,
}

@group(0) @binding(10) var<storage, read_write> pieces: array<vec4<u32>>;
@group(0) @binding(11) var<storage, read_write> counters: array<atomic<u32>>;
@group(0) @binding(12) var<storage, read_write> q_in: array<vec4<u32>>;
@group(0) @binding(13) var<storage, read_write> q_out: array<vec4<u32>>;
@group(0) @binding(14) var<uniform> lv: Level;
// `cull_hidden`: the pyramid of occluder depth maxima (hzb.wgsl); one word when off
@group(0) @binding(15) var<storage, read> hzb: array<f32>;

fn corner(c: u32) -> vec2<u32> {
    return vec2<u32>(c & 0xffffu, c >> 16u);
}

fn pack_corner(b: vec2<u32>) -> u32 {
    return b.x | (b.y << 16u);
}

fn corner_pos(tri: u32, c: u32) -> vec3<f32> {
    let b = vec2<f32>(corner(c)) / 65535.0;
    let t = scene_triangle(wp, tri);
    let v0 = vertices[3u * t].pos;
    return v0 + (vertices[3u * t + 1u].pos - v0) * b.x + (vertices[3u * t + 2u].pos - v0) * b.y;
}

// What the edge tests need of a piece's corner, computed once per piece (each corner lies on two
// of its edges): the world point, its base clip position, its DV-cropped map coordinates and
// their warped image (both 0 behind the light, where no edge through it is tested).
struct Corner {
    p: vec3<f32>,
    clip: vec4<f32>,
    u: vec2<f32>,
    w: vec2<f32>,
}

fn piece_corner(tri: u32, c: u32, r: vec4<f32>) -> Corner {
    var k: Corner;
    k.p = corner_pos(tri, c);
    k.clip = base_clip(wp, k.p);
    if k.clip.w > 1e-7 {
        k.u = to_dv(clip_to_map(k.clip).xy, r);
        k.w = warp(k.u);
    }
    return k;
}

// Whether the warped points of an edge (its ends and the points its bend is measured at) span
// less than `min_piece` warped texels along both map axes: the rasteriser cannot resolve a bend
// inside it, so splitting it further only multiplies pieces (a function of the edge alone).
fn below_min_piece(lo: vec2<f32>, hi: vec2<f32>) -> bool {
    return max(hi.x - lo.x, hi.y - lo.y) * wp.res < wp.min_piece;
}

// How far the warped edge strays from the straight line the rasteriser draws between its
// warped ends (warped texels), sampled at 1/4, 1/2 and 3/4; 0 below `min_piece`. With
// `depth_split` > 0 the displacement along the edge counts scaled by subdiv / depth_split, so
// that the result exceeds `subdiv` when the perpendicular bend exceeds it or the along-edge
// displacement exceeds `depth_split`.
fn edge_error(ma: vec2<f32>, mb: vec2<f32>, wa: vec2<f32>, wb: vec2<f32>) -> f32 {
    var e = 0.0;
    var lo = min(wa, wb);
    var hi = max(wa, wb);
    let dir = wb - wa;
    let len2 = dot(dir, dir);
    let split = wp.depth_split > 0.0 && len2 > 1e-24;
    let inv_len = select(0.0, inverseSqrt(len2), split);
    for (var s = 1u; s <= 3u; s++) {
        let t = f32(s) / 4.0;
        let w = warp(mix(ma, mb, t));
        lo = min(lo, w);
        hi = max(hi, w);
        let d = w - mix(wa, wb, t);
        if split {
            let along = abs(dot(d, dir)) * inv_len;
            let across = abs(d.x * dir.y - d.y * dir.x) * inv_len;
            e = max(e, max(across, along * wp.subdiv / wp.depth_split));
        } else {
            e = max(e, length(d));
        }
    }
    if below_min_piece(lo, hi) {
        return 0.0;
    }
    return e * wp.res;
}

// Whether an edge must be split: both ends in front of the light, the edge overlaps the
// cropped map, and the warp bends it by more than the threshold. A function of the edge alone,
// so the two pieces sharing an edge decide alike and no T-junction (crack) appears.
fn edge_needs_split(a: Corner, b: Corner, r: vec4<f32>) -> bool {
    if min(a.clip.w, b.clip.w) <= 1e-7 {
        return false;
    }
    // paraboloid: an edge wholly behind the drawn part of the hemisphere is never drawn
    if PARABOLOID && max(hemisphere_side(wp, a.p), hemisphere_side(wp, b.p)) < -SPLIT_OVERLAP {
        return false;
    }
    let ua = a.u;
    let ub = b.u;
    if any(max(ua, ub) < vec2<f32>(0.0)) || any(min(ua, ub) > vec2<f32>(1.0)) {
        return false;
    }
    if PARABOLOID {
        return paraboloid_edge_error(a.p, b.p, a.w, b.w, r) > wp.subdiv;
    }
    let wa = a.w;
    let wb = b.w;
    let e = edge_error(ua, ub, wa, wb);
    return e > wp.subdiv && !edge_hidden(a, b, e);
}

// Whether a bent edge (e warped texels) lies behind nearer occluders (`cull_hidden`; counted):
// its unsplit chord strays up to e warped texels from the curve, which is about
// e * (base length / warped length) cropped texels; twice that plus HIDDEN_MARGIN.
fn edge_hidden(a: Corner, b: Corner, e: f32) -> bool {
    if !CULL_HIDDEN || PARABOLOID {
        return false;
    }
    let rho = length(b.u - a.u) / max(length(b.w - a.w), 1e-12);
    let m = (HIDDEN_MARGIN + 2.0 * e * rho) / wp.res;
    if hidden(min(a.u, b.u) - m, max(a.u, b.u) + m, min(clip_to_map(a.clip).z, clip_to_map(b.clip).z)) {
        atomicAdd(&counters[21], 1u);
        return true;
    }
    return false;
}

// Whether every point of the DV-cropped rectangle [lo, hi] holds an occluder nearer than z (the
// pyramid's maximum over the texels it touches, at the level where they are at most 2x2).
// Outside the crop: unknown, not hidden. Point-sampled maps can miss gaps below a texel; an
// edge judged hidden there is only drawn coarser (unsplit), never dropped.
fn hidden(lo: vec2<f32>, hi: vec2<f32>, z: f32) -> bool {
    if !CULL_HIDDEN {
        return false;
    }
    let res = u32(wp.res);
    let a = floor(lo * wp.res);
    let b = floor(hi * wp.res);
    if any(a < vec2<f32>(0.0)) || any(b > vec2<f32>(wp.res - 1.0)) {
        return false;
    }
    let ia = vec2<u32>(a);
    let ib = vec2<u32>(b);
    // 2^l > the extent in texels: the rectangle touches at most 2x2 texels of level l
    let l = 32u - countLeadingZeros(max(ib.x - ia.x, ib.y - ia.y));
    let side = hzb_side(res, l);
    let pa = min(ia >> vec2<u32>(l), vec2<u32>(side - 1u));
    let pb = min(ib >> vec2<u32>(l), vec2<u32>(side - 1u));
    let o = hzb_base() + hzb_offset(res, l);
    let m = max(max(hzb[o + pa.y * side + pa.x], hzb[o + pa.y * side + pb.x]), max(hzb[o + pb.y * side + pa.x], hzb[o + pb.y * side + pb.x]));
    return z > m + HIDDEN_EPS;
}

// Cropped texels added around a hidden-edge test (the point-sampled occluders' reach).
const HIDDEN_MARGIN: f32 = 2.0;
// Depth step (post-projective) an edge must lie behind its occluders by.
const HIDDEN_EPS: f32 = 1e-6;

// The paraboloid mapping bends straight world edges (seed 002 section 3.3.2: "the rendered scene
// needs to be finely tessellated"): distance (warped texels) of the images of the world points
// at 1/4, 1/2, 3/4 of the edge from the straight line the rasteriser draws between its warped
// ends (the line, not the point at the same parameter: only coverage matters here).
fn paraboloid_edge_error(pa: vec3<f32>, pb: vec3<f32>, wa: vec2<f32>, wb: vec2<f32>, r: vec4<f32>) -> f32 {
    let dir = wb - wa;
    let len = length(dir);
    var e = 0.0;
    var lo = min(wa, wb);
    var hi = max(wa, wb);
    for (var s = 1u; s <= 3u; s++) {
        let c = base_clip(wp, mix(pa, pb, f32(s) / 4.0));
        if c.w <= 1e-7 {
            return 1e30;
        }
        let w = warp(to_dv(clip_to_map(c).xy, r));
        lo = min(lo, w);
        hi = max(hi, w);
        let m = w - wa;
        var d = length(m);
        if len > 1e-12 {
            d = abs(m.x * dir.y - m.y * dir.x) / len;
        }
        e = max(e, d);
    }
    if below_min_piece(lo, hi) {
        return 0.0;
    }
    return e * wp.res;
}

// A piece larger than BIG_PIECE of the cropped map that overlaps it splits all three edges even when
// they are straight (the courtyard floor: two triangles whose edges lie outside the map). Its
// neighbours may not split the shared edge: a possible crack, on such big pieces only.
// (Testing interior points as well brought the cracks back: conference sun 0.37 -> 1.36 %.)
fn interior_needs_split(k: array<Corner, 3>) -> bool {
    if min(min(k[0].clip.w, k[1].clip.w), k[2].clip.w) <= 1e-7 {
        return false;
    }
    if PARABOLOID {
        let side = max(max(hemisphere_side(wp, k[0].p), hemisphere_side(wp, k[1].p)), hemisphere_side(wp, k[2].p));
        if side < -SPLIT_OVERLAP {
            return false;
        }
    }
    let lo = min(min(k[0].u, k[1].u), k[2].u);
    let hi = max(max(k[0].u, k[1].u), k[2].u);
    if any(hi < vec2<f32>(0.0)) || any(lo > vec2<f32>(1.0)) {
        return false;
    }
    return max(hi.x - lo.x, hi.y - lo.y) > BIG_PIECE;
}

// Bit 0: edge a-b, bit 1: b-c, bit 2: c-a.
fn split_mask(p: vec4<u32>) -> u32 {
    let r = dv_rect();
    let k = array<Corner, 3>(piece_corner(p.x, p.y, r), piece_corner(p.x, p.z, r), piece_corner(p.x, p.w, r));
    let m = select(0u, 1u, edge_needs_split(k[0], k[1], r)) | select(0u, 2u, edge_needs_split(k[1], k[2], r))
        | select(0u, 4u, edge_needs_split(k[2], k[0], r));
    if m != 7u && interior_needs_split(k) {
        return 7u;
    }
    return m;
}

fn finish(p: vec4<u32>) {
    let i = atomicAdd(&counters[0], 1u);
    if i >= EXTRA_CAPACITY {
        atomicAdd(&counters[1], 1u);
        return;
    }
    pieces[TRIANGLES + i] = finished(p);
}

// Queue entries carry their split mask above the triangle index.
const MASK_SHIFT: u32 = 29u;
const TRI_BITS: u32 = 0x1fffffffu;

// Pieces a split by `mask` makes (0: the piece itself, finished).
fn children_of(mask: u32) -> u32 {
    switch mask {
        case 0u {
            return 1u;
        }
        case 1u, 2u, 4u {
            return 2u;
        }
        case 7u {
            return 4u;
        }
        default {
            return 3u;
        }
    }
}

const BUCKETS: u32 = 256u;

fn bucket_of(tri: u32) -> u32 {
    // (at least 1: a scene without triangles still makes its pipelines)
    return tri / max((TRIANGLES + BUCKETS - 1u) / BUCKETS, 1u);
}

fn enqueue(p: vec4<u32>, mask: u32, q: u32) {
    let i = atomicAdd(&counters[8u + 4u * q], 1u);
    if i >= lv.v.w {
        // not reached: the root's queue holds two pieces per triangle, and a level splits
        // only when its children fit (split_args)
        atomicAdd(&counters[2], 1u);
        finish(p);
        return;
    }
    let b = 24u + q * 2u * BUCKETS + bucket_of(p.x);
    atomicAdd(&counters[b], children_of(mask));
    atomicAdd(&counters[b + BUCKETS], 1u);
    q_out[i] = vec4<u32>(p.x | (mask << MASK_SHIFT), p.y, p.z, p.w);
}

// A root piece in the triangle's own slot: kept, or queued (the slot then holds nothing).
fn place_root(tri: u32, p: vec4<u32>) {
    let m = split_mask(p);
    if m != 0u {
        pieces[tri] = vec4<u32>(tri, 0u, 0u, 0u);
        enqueue(p, m, 0u);
    } else {
        pieces[tri] = p;
    }
}

// The corner a fraction t of the way from corner a to corner b.
fn mix_corner(a: u32, b: u32, t: f32) -> u32 {
    return pack_corner(vec2<u32>(round(mix(vec2<f32>(corner(a)), vec2<f32>(corner(b)), t))));
}

// A whole triangle's corners as packed barycentrics: (0, 0), (1, 0), (0, 1).
const ROOT_CORNERS = array<u32, 3>(0u, 0xffffu, 0xffff0000u);

// A triangle's root pieces: the whole triangle, or for planar projections the triangle
// clipped to the light's near plane (clip z >= 0) before any warping, because the warp of a
// vertex behind a spot light is meaningless (its projection flips) and one such vertex spreads
// its triangle across the whole map. Clip space is affine in world space, so the cut corners are
// exact barycentric mixes. Wholly behind: none; a cut leaving a quad: two.
struct Roots {
    n: u32,
    p: array<vec4<u32>, 2>,
}

fn root_pieces(tri: u32) -> Roots {
    let c = ROOT_CORNERS;
    var r: Roots;
    r.p[0] = vec4<u32>(tri, c[0], c[1], c[2]);
    r.n = 1u;
    if PARABOLOID {
        return r;
    }
    var z: array<f32, 3>;
    for (var i = 0u; i < 3u; i++) {
        z[i] = base_clip(wp, corner_pos(tri, c[i])).z;
    }
    if min(min(z[0], z[1]), z[2]) >= 0.0 {
        return r;
    }
    var poly: array<u32, 4>;
    var n = 0u;
    for (var i = 0u; i < 3u; i++) {
        let j = (i + 1u) % 3u;
        if z[i] >= 0.0 {
            poly[n] = c[i];
            n += 1u;
        }
        if (z[i] >= 0.0) != (z[j] >= 0.0) {
            poly[n] = mix_corner(c[i], c[j], z[i] / (z[i] - z[j]));
            n += 1u;
        }
    }
    r.n = select(n - 2u, 0u, n < 3u);
    r.p[0] = vec4<u32>(tri, poly[0], poly[1], poly[2]);
    r.p[1] = vec4<u32>(tri, poly[0], poly[2], poly[3]);
    return r;
}

// Each triangle's first root piece is kept in its own slot or queued; the second half of a quad
// is finished like a piece or queued; a triangle wholly behind the light leaves its slot empty.
@compute @workgroup_size(64)
fn split_root(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) l: u32) {
    let tri = (wg.y * 65535u + wg.x) * 64u + l;
    if tri >= TRIANGLES {
        return;
    }
    enter_triangle(tri);
    if no_samples() {
        // no view sample on the map (an empty cube face): nothing evaluates it, nothing is drawn
        return;
    }
    let r = root_pieces(tri);
    if r.n == 0u {
        pieces[tri] = vec4<u32>(tri, 0u, 0u, 0u);
        return;
    }
    place_root(tri, r.p[0]);
    if r.n == 2u {
        let q = r.p[1];
        let mq = split_mask(q);
        if mq != 0u {
            enqueue(q, mq, 0u);
        } else {
            finish(q);
        }
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
    let out = 24u + (1u - lv.v.z) * 2u * BUCKETS;
    for (var b = 0u; b < 2u * BUCKETS; b++) {
        atomicStore(&counters[out + b], 0u);
    }
    // the first buckets whose pieces split: each split piece's children must fit as finished
    // pieces and (before the last level) in the next queue; the rest finish as one piece each
    // (a level's inputs always fit so: the level before checked)
    let inp = 24u + lv.v.z * 2u * BUCKETS;
    var total = atomicLoad(&counters[0]);
    for (var b = 0u; b < BUCKETS; b++) {
        total += atomicLoad(&counters[inp + BUCKETS + b]);
    }
    var queued = 0u;
    var k = 0u;
    for (; k < BUCKETS; k++) {
        let kids = atomicLoad(&counters[inp + k]);
        let grow = kids - atomicLoad(&counters[inp + BUCKETS + k]);
        if total + grow > EXTRA_CAPACITY || (lv.v.y == 0u && queued + kids > lv.v.w) {
            break;
        }
        total += grow;
        queued += kids;
    }
    let size = (TRIANGLES + BUCKETS - 1u) / BUCKETS;
    atomicStore(&counters[18], select(k * size, 0xffffffffu, k == BUCKETS));
    if k < BUCKETS && atomicLoad(&counters[19]) == 0u {
        atomicStore(&counters[19], lv.v.x);
    }
}

fn place(p: vec4<u32>) {
    if lv.v.y != 0u {
        finish(p);
        return;
    }
    let m = split_mask(p);
    if m == 0u {
        finish(p);
    } else {
        enqueue(p, m, 1u - lv.v.z);
    }
}

// Splits the edges that need it (1, 2 or 3 of them: 2, 3 or 4 children); the children are
// finished or queued again.
@compute @workgroup_size(64)
fn split_level(@builtin(global_invocation_id) id: vec3<u32>) {
    let n = min(atomicLoad(&counters[8u + 4u * lv.v.z]), lv.v.w);
    if id.x >= n {
        return;
    }
    let queued = q_in[id.x];
    let mask = queued.x >> MASK_SHIFT;
    let p = vec4<u32>(queued.x & TRI_BITS, queued.y, queued.z, queued.w);
    enter_triangle(p.x);
    if p.x >= atomicLoad(&counters[18]) {
        // this piece's children do not fit (its bucket is past the level's split limit): drawn unsplit
        atomicAdd(&counters[20], 1u);
        finish(p);
        return;
    }
    let t = p.x;
    let a = p.y;
    let b = p.z;
    let c = p.w;
    let ab = pack_corner((corner(a) + corner(b)) / 2u);
    let bc = pack_corner((corner(b) + corner(c)) / 2u);
    let ca = pack_corner((corner(c) + corner(a)) / 2u);
    // the children as corner triples (one place() loop: cheap on SIMD software rasterisers)
    var kids: array<vec3<u32>, 4>;
    var count = 0u;
    switch mask {
        case 1u {
            kids[0] = vec3<u32>(a, ab, c);
            kids[1] = vec3<u32>(ab, b, c);
            count = 2u;
        }
        case 2u {
            kids[0] = vec3<u32>(a, b, bc);
            kids[1] = vec3<u32>(a, bc, c);
            count = 2u;
        }
        case 4u {
            kids[0] = vec3<u32>(a, b, ca);
            kids[1] = vec3<u32>(ca, b, c);
            count = 2u;
        }
        case 3u {
            kids[0] = vec3<u32>(ab, b, bc);
            kids[1] = vec3<u32>(a, ab, bc);
            kids[2] = vec3<u32>(a, bc, c);
            count = 3u;
        }
        case 6u {
            kids[0] = vec3<u32>(ca, bc, c);
            kids[1] = vec3<u32>(a, b, bc);
            kids[2] = vec3<u32>(a, bc, ca);
            count = 3u;
        }
        case 5u {
            kids[0] = vec3<u32>(a, ab, ca);
            kids[1] = vec3<u32>(ab, b, c);
            kids[2] = vec3<u32>(ab, c, ca);
            count = 3u;
        }
        case 7u {
            kids[0] = vec3<u32>(a, ab, ca);
            kids[1] = vec3<u32>(ab, b, bc);
            kids[2] = vec3<u32>(ca, bc, c);
            kids[3] = vec3<u32>(ab, bc, ca);
            count = 4u;
        }
        default {
            finish(p);
        }
    }
    for (var i = 0u; i < count; i++) {
        place(vec4<u32>(t, kids[i]));
    }
}

// Pieces wider than this fraction of the cropped map split all edges (see interior_needs_split).
const BIG_PIECE: f32 = 0.125;
