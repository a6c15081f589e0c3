// Bounds of fixed-size chunks of triangles in vertex order (computed once at creation): per
// chunk, atomic min/max of the order-preserving keys of x, y, z (6 u32: min xyz, max xyz).
// Chunks start at triangle c.z (0 for iasm; `virtual` bounds its moving triangles per frame).

struct ChunkParams {
    // x: triangles per chunk, y: end triangle, z: first triangle
    c: vec4<u32>,
}

@group(0) @binding(0) var<uniform> cp: ChunkParams;
@group(0) @binding(1) var<storage, read_write> boxes: array<atomic<u32>>;

fn key(f: f32) -> u32 {
    let b = bitcast<u32>(f);
    if (b & 0x80000000u) != 0u {
        return ~b;
    }
    return b | 0x80000000u;
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let tri = cp.c.z + id.y * 65535u * 64u + id.x;
    if tri >= cp.c.y {
        return;
    }
    let b = ((tri - cp.c.z) / cp.c.x) * 6u;
    for (var k = 0u; k < 3u; k++) {
        let p = vertices[tri * 3u + k].pos;
        for (var a = 0u; a < 3u; a++) {
            atomicMin(&boxes[b + a], key(p[a]));
            atomicMax(&boxes[b + 3u + a], key(p[a]));
        }
    }
}
