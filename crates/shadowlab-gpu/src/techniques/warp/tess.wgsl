// Tessellation (`tessellate`): the pieces the level queue (subdiv.wgsl) has left after its
// first levels are finished the way a hardware tessellator draws (the seeds' method), in one
// pass of levels and one of emission instead of a queue level after level. tess_levels gives
// each edge of a queued piece a level from the warp's bend along it, a function of the edge
// alone (the queue's test first: an edge the queue would leave whole gets 0), so that the two
// pieces sharing an edge agree and no crack appears; the piece's grid takes the largest (and on
// a big piece its interior's). A piece of grid level L is drawn as the 4^L triangles of a
// regular grid whose vertices on an edge of lower level snap to that edge's nearest points
// (degenerate triangles where they meet, counted). tess_args cuts as split_args does (the
// pieces of the first buckets of triangle indices that fit; the rest are drawn whole),
// tess_alloc gives each piece its run of slots and its chunks of 64 pieces, tess_emit writes a
// chunk's pieces, one invocation each (balanced however large the piece).
//
// They run with the group of the level after the queue's last (lv.v.x - 1 queue levels ran):
// q_in holds the queued pieces (counters[8 + 4 lv.v.z] of them, their split masks above the
// triangle index) and after them the chunks' piece indices (4 a vec4); q_out[i] is piece i's
// (levels, first slot, first chunk, pieces). The buffers hold the chunks' words past the
// entries the levels may fill (lv.v.w). counters as subdiv.wgsl's, with [16] the chunks,
// [13..15] the emission's groups, [22] the degenerate pieces; the buckets' words hold the
// pieces by bucket, the queued pieces by bucket and a word per bucket whose sum overflowed.

// Steps at which the level pass samples the warp along an edge, and along a big piece's box
// (a step of 8 texels of a 512 map).
const TESS_STEPS: u32 = 8u;
const BOX_STEPS: u32 = 64u;
const OVERFLOW_AT: u32 = 24u + 2u * BUCKETS;

// The levels of a root piece: edges a-b, b-c, c-a in bits 0-3, 4-7, 8-11, its grid in 12-15.
fn edge_levels(v: u32) -> vec4<u32> {
    return (vec4<u32>(v) >> vec4<u32>(0u, 4u, 8u, 12u)) & vec4<u32>(15u);
}

// The parameter range [t0, t1] of the segment ua-ub inside the cropped map (t0 >= t1: none).
fn inside_map(ua: vec2<f32>, ub: vec2<f32>) -> vec2<f32> {
    var t = vec2<f32>(0.0, 1.0);
    let d = ub - ua;
    for (var i = 0u; i < 2u; i++) {
        if abs(d[i]) < 1e-12 {
            if ua[i] < 0.0 || ua[i] > 1.0 {
                return vec2<f32>(1.0, 0.0);
            }
        } else {
            let a = -ua[i] / d[i];
            let b = (1.0 - ua[i]) / d[i];
            t = vec2<f32>(max(t.x, min(a, b)), min(t.y, max(a, b)));
        }
    }
    return t;
}

// The warped image of the point a fraction t along the edge a-b (planar: along its cropped map
// coordinates; paraboloid: along the world edge), and 0 in z where it is behind the light.
fn edge_point(a: Corner, b: Corner, t: f32, r: vec4<f32>) -> vec3<f32> {
    if !PARABOLOID {
        return vec3<f32>(warp(mix(a.u, b.u, t)), 1.0);
    }
    let c = base_clip(wp, mix(a.p, b.p, t));
    if c.w <= 1e-7 {
        return vec3<f32>(0.0);
    }
    return vec3<f32>(warp(to_dv(clip_to_map(c).xy, r)), 1.0);
}

// A displacement d of a warped point against the chord's direction dir, judged as edge_error
// and paraboloid_edge_error judge it (warped map units).
fn displacement(d: vec2<f32>, dir: vec2<f32>) -> f32 {
    let len2 = dot(dir, dir);
    if len2 <= 1e-24 {
        return length(d);
    }
    let across = abs(d.x * dir.y - d.y * dir.x) * inverseSqrt(len2);
    if PARABOLOID {
        return across;
    }
    if wp.depth_split > 0.0 {
        let along = abs(dot(d, dir)) * inverseSqrt(len2);
        return max(across, along * wp.subdiv / wp.depth_split);
    }
    return length(d);
}

// Segments the part [t0, t1] of edge a-b needs, per unit of t, sampled at `steps` equal steps,
// and the warped extent of the points sampled (texels): the largest second difference D of the
// warped points (warped texels) bounds the bend of a chord over h steps by D h^2 / 8, so a
// chord may span sqrt(8 subdiv / D) steps.
fn bend_segments(a: Corner, b: Corner, t0: f32, t1: f32, steps: u32, r: vec4<f32>) -> vec2<f32> {
    var lo = vec2<f32>(1e30);
    var hi = vec2<f32>(-1e30);
    let dir = b.w - a.w;
    var d = 0.0;
    // the last two points (z: in front of the light)
    var w0 = vec3<f32>(0.0);
    var w1 = vec3<f32>(0.0);
    for (var j = 0u; j <= steps; j++) {
        let w = edge_point(a, b, mix(t0, t1, f32(j) / f32(steps)), r);
        if w.z > 0.0 {
            lo = min(lo, w.xy);
            hi = max(hi, w.xy);
        }
        if j >= 2u && min(min(w0.z, w1.z), w.z) > 0.0 {
            d = max(d, displacement(w0.xy - 2.0 * w1.xy + w.xy, dir));
        }
        w0 = w1;
        w1 = w;
    }
    let n = sqrt(d * wp.res / (8.0 * wp.subdiv)) * f32(steps) / max(t1 - t0, 1e-6);
    return vec2<f32>(n, max(hi.x - lo.x, hi.y - lo.y) * wp.res);
}

// The level (log2 of the segments; 0: whole) of the edge a-b: 0 where subdiv.wgsl's tests
// leave it unsplit (behind the light or the drawn hemisphere, outside the cropped map, bent by
// at most `subdiv` as a whole, hidden); else enough segments for the bend sampled along its
// part in the cropped map and for its whole bend (a parabola's: e / n^2 with n segments),
// bounded by `min_piece` and the levels.
fn edge_level(a0: Corner, b0: Corner, r: vec4<f32>) -> u32 {
    // the same ends in the same order from both pieces on the edge
    var a = a0;
    var b = b0;
    if b0.u.x < a0.u.x || (b0.u.x == a0.u.x && b0.u.y < a0.u.y) {
        a = b0;
        b = a0;
    }
    if min(a.clip.w, b.clip.w) <= 1e-7 {
        return 0u;
    }
    if PARABOLOID && max(hemisphere_side(wp, a.p), hemisphere_side(wp, b.p)) < -SPLIT_OVERLAP {
        return 0u;
    }
    if any(max(a.u, b.u) < vec2<f32>(0.0)) || any(min(a.u, b.u) > vec2<f32>(1.0)) {
        return 0u;
    }
    var e: f32;
    var t = vec2<f32>(0.0, 1.0);
    if PARABOLOID {
        e = paraboloid_edge_error(a.p, b.p, a.w, b.w, r);
    } else {
        e = edge_error(a.u, b.u, a.w, b.w);
        t = inside_map(a.u, b.u);
    }
    if e <= wp.subdiv || edge_hidden(a, b, e) || t.x >= t.y {
        return 0u;
    }
    let s = bend_segments(a, b, t.x, t.y, TESS_STEPS, r);
    // (a sample behind the light: the whole bend is unknown, the sampled one decides)
    var n = max(select(sqrt(e / wp.subdiv), 1.0, e >= 1e29), s.x);
    if wp.min_piece > 0.0 {
        let extent = max(s.y, max(abs(b.w.x - a.w.x), abs(b.w.y - a.w.y)) * wp.res);
        n = min(n, 2.0 * extent / wp.min_piece);
    }
    return level_of(n);
}

fn level_of(n: f32) -> u32 {
    if n <= 1.0 {
        return 0u;
    }
    return min(u32(ceil(log2(n))), grid_levels());
}

// A corner at world point p (a piece_corner not on a piece's corners).
fn corner_at(p: vec3<f32>, r: vec4<f32>) -> Corner {
    var k: Corner;
    k.p = p;
    k.clip = base_clip(wp, p);
    if k.clip.w > 1e-7 {
        k.u = to_dv(clip_to_map(k.clip).xy, r);
        k.w = warp(k.u);
    }
    return k;
}

// A root piece's levels (edge_levels' layout). The grid follows the edges' largest level; a
// piece larger than BIG_PIECE of the cropped map (its edges may lie outside it, as the
// courtyard floor's do) also follows its midlines (a grid of level l + 1 has a midline's
// level l) and, planar, the warp's bend along the diagonals of its box within the map.
fn root_levels(p: vec4<u32>) -> u32 {
    let r = dv_rect();
    let k = array<Corner, 3>(piece_corner(p.x, p.y, r), piece_corner(p.x, p.z, r), piece_corner(p.x, p.w, r));
    let e = vec3<u32>(edge_level(k[0], k[1], r), edge_level(k[1], k[2], r), edge_level(k[2], k[0], r));
    var grid = max(max(e.x, e.y), e.z);
    if interior_needs_split(k) {
        let m = array<Corner, 3>(
            corner_at(0.5 * (k[0].p + k[1].p), r),
            corner_at(0.5 * (k[1].p + k[2].p), r),
            corner_at(0.5 * (k[2].p + k[0].p), r),
        );
        let mid = max(max(edge_level(m[0], m[1], r), edge_level(m[1], m[2], r)), edge_level(m[2], m[0], r));
        grid = max(grid, min(mid + 1u, grid_levels()));
        if !PARABOLOID {
            grid = max(grid, box_level(k, r));
        }
        grid = max(grid, 1u);
    }
    return e.x | (e.y << 4u) | (e.z << 8u) | (grid << 12u);
}

// Planar: the grid level that follows the warp's bend along the two diagonals of the piece's
// bounding box within the cropped map, for a grid spanning the piece's whole extent.
fn box_level(k: array<Corner, 3>, r: vec4<f32>) -> u32 {
    let lo = min(min(k[0].u, k[1].u), k[2].u);
    let hi = max(max(k[0].u, k[1].u), k[2].u);
    let a = clamp(lo, vec2<f32>(0.0), vec2<f32>(1.0));
    let b = clamp(hi, vec2<f32>(0.0), vec2<f32>(1.0));
    var c0: Corner;
    var c1: Corner;
    var n = 0.0;
    for (var d = 0u; d < 2u; d++) {
        c0.u = select(a, vec2<f32>(a.x, b.y), d == 1u);
        c1.u = select(b, vec2<f32>(b.x, a.y), d == 1u);
        c0.w = warp(c0.u);
        c1.w = warp(c1.u);
        let len = max(length(c1.u - c0.u), 1e-6);
        // segments per diagonal, scaled to the piece's extent
        n = max(n, bend_segments(c0, c1, 0.0, 1.0, BOX_STEPS, r).x * max(hi.x - lo.x, hi.y - lo.y) / len);
    }
    return level_of(n);
}

// Levels left to the grid after the queue's (lv.v.x - 1 ran).
fn grid_levels() -> u32 {
    return wp.subdiv_levels - min(lv.v.x - 1u, wp.subdiv_levels);
}

fn queued() -> u32 {
    return min(atomicLoad(&counters[8u + 4u * lv.v.z]), lv.v.w);
}

fn queued_piece(i: u32) -> vec4<u32> {
    let q = q_in[i];
    return vec4<u32>(q.x & TRI_BITS, q.yzw);
}

// Clears the buckets (the queue's sums are spent) and sets the groups over the queued pieces.
@compute @workgroup_size(1)
fn tess_begin() {
    for (var b = 24u; b < 24u + 4u * BUCKETS; b++) {
        atomicStore(&counters[b], 0u);
    }
    let g = (queued() + 63u) / 64u;
    let at = 8u + 4u * lv.v.z;
    atomicStore(&counters[at + 1u], min(g, 65535u));
    atomicStore(&counters[at + 2u], (g + 65534u) / 65535u);
    atomicStore(&counters[at + 3u], 1u);
}

// A queued piece: finished whole, or given its levels and its pieces added to its bucket's sum.
@compute @workgroup_size(64)
fn tess_levels(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) l: u32) {
    let i = (wg.y * 65535u + wg.x) * 64u + l;
    if i >= queued() {
        return;
    }
    let p = queued_piece(i);
    enter_triangle(p.x);
    let levels = root_levels(p);
    let grid = levels >> 12u;
    q_out[i] = vec4<u32>(levels, 0u, 0u, 0u);
    if grid == 0u {
        finish(p);
        return;
    }
    let b = bucket_of(p.x);
    let n = 1u << (2u * grid);
    let old = atomicAdd(&counters[24u + b], n);
    if old + n < old {
        atomicStore(&counters[OVERFLOW_AT + b], 1u);
    }
    atomicAdd(&counters[24u + BUCKETS + b], 1u);
}

// The first buckets whose pieces are all emitted within the capacity (counting every piece of
// the others as one, drawn whole): counters[18] the first triangle drawn whole, counters[19]
// the queue levels + 1 where some are (0: none).
@compute @workgroup_size(1)
fn tess_args() {
    var total = atomicLoad(&counters[0]);
    for (var b = 0u; b < BUCKETS; b++) {
        total += atomicLoad(&counters[24u + BUCKETS + b]);
    }
    var k = 0u;
    for (; k < BUCKETS; k++) {
        let grow = atomicLoad(&counters[24u + k]) - atomicLoad(&counters[24u + BUCKETS + k]);
        if atomicLoad(&counters[OVERFLOW_AT + k]) != 0u || total + grow > EXTRA_CAPACITY || total + grow < total {
            break;
        }
        total += grow;
    }
    let size = (TRIANGLES + BUCKETS - 1u) / BUCKETS;
    atomicStore(&counters[18], select(k * size, 0xffffffffu, k == BUCKETS));
    if k < BUCKETS && atomicLoad(&counters[19]) == 0u {
        atomicStore(&counters[19], lv.v.x);
    }
    atomicStore(&counters[16], 0u);
}

// Chunk c's piece index: a word after the queued pieces.
fn chunk_slot(c: u32) -> vec2<u32> {
    return vec2<u32>(queued() + c / 4u, c % 4u);
}

@compute @workgroup_size(64)
fn tess_alloc(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) l: u32) {
    let i = (wg.y * 65535u + wg.x) * 64u + l;
    if i >= queued() {
        return;
    }
    let levels = q_out[i].x;
    if (levels >> 12u) == 0u {
        return;
    }
    let p = queued_piece(i);
    enter_triangle(p.x);
    if p.x >= atomicLoad(&counters[18]) {
        // its bucket's pieces do not fit: drawn whole
        atomicAdd(&counters[20], 1u);
        finish(p);
        return;
    }
    let n = 1u << (2u * (levels >> 12u));
    let first = atomicAdd(&counters[0], n);
    let chunks = (n + 63u) / 64u;
    let c0 = atomicAdd(&counters[16], chunks);
    q_out[i] = vec4<u32>(levels, first, c0, n);
    for (var c = c0; c < c0 + chunks; c++) {
        let s = chunk_slot(c);
        if s.x >= arrayLength(&q_in) {
            // not reached: the queue's buffer holds the chunks past its entries (subdiv.rs
            // queue_bytes)
            atomicAdd(&counters[1], 1u);
            return;
        }
        q_in[s.x][s.y] = i;
    }
}

// The emission's groups, one per chunk.
@compute @workgroup_size(1)
fn tess_emit_args() {
    let chunks = atomicLoad(&counters[16]);
    atomicStore(&counters[13], min(chunks, 65535u));
    atomicStore(&counters[14], (chunks + 65534u) / 65535u);
    atomicStore(&counters[15], 1u);
}

// Grid vertex v = (s, c) of a piece of grid level L: s steps from corner a towards the edge
// b-c, c of them towards c. On an edge (b-c: s = N, a-b: c = 0, c-a: c = s) it moves to the
// nearest of the edge's own points (its level e; half-way: the farther from a or b), which its
// neighbour has too. To the nearest, not down: a corner where two coarser edges meet would fold
// (a vertex of c-a near c moved towards a past the grid next to it; tests/warp.rs).
fn snap(v: vec2<u32>, e: vec4<u32>) -> vec2<u32> {
    let n = 1u << e.w;
    if v.x == n {
        return vec2<u32>(n, nearest(v.y, e.w - e.y));
    }
    if v.y == 0u {
        return vec2<u32>(nearest(v.x, e.w - e.x), 0u);
    }
    if v.y == v.x {
        let s = nearest(v.x, e.w - e.z);
        return vec2<u32>(s, s);
    }
    return v;
}

// The multiple of 2^l nearest to x (half-way: up).
fn nearest(x: u32, l: u32) -> u32 {
    let q = 1u << l;
    return (x + q / 2u) / q * q;
}

// The packed barycentrics of grid vertex v of piece p (exact integers: a point of an edge is
// the same from both pieces on it).
fn grid_corner(p: vec4<u32>, v: vec2<u32>, n: u32) -> u32 {
    let b = corner(p.y) * (n - v.x) + corner(p.z) * (v.x - v.y) + corner(p.w) * v.y;
    return pack_corner(b / n);
}

@compute @workgroup_size(64)
fn tess_emit(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) l: u32) {
    let g = wg.y * 65535u + wg.x;
    if g >= atomicLoad(&counters[16]) {
        return;
    }
    let s = chunk_slot(g);
    let i = q_in[s.x][s.y];
    let rec = q_out[i];
    let k = (g - rec.z) * 64u + l;
    if k >= rec.w {
        return;
    }
    let p = queued_piece(i);
    enter_triangle(p.x);
    let e = edge_levels(rec.x);
    // row j from corner a holds 2j + 1 pieces: pointing to a (even), then away
    var j = u32(sqrt(f32(k)));
    j = select(j, j - 1u, j * j > k);
    j = select(j, j + 1u, (j + 1u) * (j + 1u) <= k);
    let m = k - j * j;
    let c = m / 2u;
    var v = array<vec2<u32>, 3>(vec2<u32>(j, c), vec2<u32>(j + 1u, c), vec2<u32>(j + 1u, c + 1u));
    if m % 2u == 1u {
        v = array<vec2<u32>, 3>(vec2<u32>(j, c), vec2<u32>(j + 1u, c + 1u), vec2<u32>(j, c + 1u));
    }
    let n = 1u << e.w;
    for (var t = 0u; t < 3u; t++) {
        v[t] = snap(v[t], e);
    }
    if all(v[0] == v[1]) || all(v[1] == v[2]) || all(v[2] == v[0]) {
        atomicAdd(&counters[22], 1u);
    }
    pieces[TRIANGLES + rec.y + k] = finished(vec4<u32>(p.x, grid_corner(p, v[0], n), grid_corner(p, v[1], n), grid_corner(p, v[2], n)));
}
