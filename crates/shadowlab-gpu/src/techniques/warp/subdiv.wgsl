// Subdivision against the bending of long warped edges (both seeds' limitation; wgpu has no
// tessellation). Per triangle: the length of each edge through the warp (a 4-piece polyline in
// warped texels); a triangle whose longest edge exceeds the threshold is cut into n x n
// sub-triangles, n = ceil(length / threshold) up to the max level. Sub-triangle 0 goes to the
// triangle's own slot; the other n^2 - 1 are appended after the triangles (atomic counter);
// when the extra capacity is full the triangle stays whole (counted as overflow).
// args: [vertex count, instances, first vertex, first instance, appended, overflow].

@group(0) @binding(10) var<storage, read_write> records: array<u32>;
@group(0) @binding(11) var<storage, read_write> args: array<atomic<u32>, 8>;

fn edge_length(a: vec4<f32>, b: vec4<f32>, r: vec4<f32>) -> f32 {
    let ma = to_dv(clip_to_map(a).xy, r);
    let mb = to_dv(clip_to_map(b).xy, r);
    var prev = warp(ma);
    var len = 0.0;
    for (var s = 1u; s <= 4u; s++) {
        let q = warp(mix(ma, mb, f32(s) / 4.0));
        len += distance(q, prev);
        prev = q;
    }
    return len * wp.texel.z;
}

fn pack(n: u32, i: u32, j: u32, down: u32) -> u32 {
    return n | (i << 8u) | (j << 16u) | (down << 24u);
}

@compute @workgroup_size(64)
fn split(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) l: u32) {
    let tri = (wg.y * 65535u + wg.x) * 64u + l;
    let tris = wp.ints.x;
    if tri >= tris {
        return;
    }
    let r = dv_rect();
    let a = base_clip(wp, vertices[3u * tri].pos);
    let b = base_clip(wp, vertices[3u * tri + 1u].pos);
    let c = base_clip(wp, vertices[3u * tri + 2u].pos);
    var n = 1u;
    if min(min(a.w, b.w), c.w) > 1e-7 {
        let u = array<vec2<f32>, 3>(to_dv(clip_to_map(a).xy, r), to_dv(clip_to_map(b).xy, r), to_dv(clip_to_map(c).xy, r));
        let lo = min(min(u[0], u[1]), u[2]);
        let hi = max(max(u[0], u[1]), u[2]);
        // triangles wholly outside the cropped map are clipped anyway
        if all(hi >= vec2<f32>(0.0)) && all(lo <= vec2<f32>(1.0)) {
            let len = max(max(edge_length(a, b, r), edge_length(b, c, r)), edge_length(c, a, r));
            n = clamp(u32(ceil(len / wp.imp.w)), 1u, wp.ints.y);
        }
    }
    records[2u * tri] = tri;
    records[2u * tri + 1u] = pack(1u, 0u, 0u, 0u);
    if n == 1u {
        return;
    }
    let extra = n * n - 1u;
    let base = atomicAdd(&args[4], extra);
    if base + extra > wp.ints.z {
        atomicAdd(&args[5], 1u);
        return;
    }
    records[2u * tri + 1u] = pack(n, 0u, 0u, 0u);
    var slot = tris + base;
    for (var i = 0u; i < n; i++) {
        for (var j = 0u; i + j < n; j++) {
            for (var down = 0u; down < 2u; down++) {
                if (down == 1u && i + j + 1u >= n) || (i == 0u && j == 0u && down == 0u) {
                    continue;
                }
                records[2u * slot] = tri;
                records[2u * slot + 1u] = pack(n, i, j, down);
                slot += 1u;
            }
        }
    }
}

@compute @workgroup_size(1)
fn split_args() {
    let appended = min(atomicLoad(&args[4]), wp.ints.z);
    atomicStore(&args[0], 3u * (wp.ints.x + appended));
    atomicStore(&args[1], 1u);
    atomicStore(&args[2], 0u);
    atomicStore(&args[3], 0u);
}
