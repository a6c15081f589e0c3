// IASM evaluation, store=atlas: the same lookup as eval.wgsl, the depth read from the tile's
// square in the depth atlas (corner `slot`, texel p_b of equation 3.4).

@group(0) @binding(6) var<uniform> ip: IasmParams;
@group(0) @binding(7) var atlas: texture_depth_2d;
@group(0) @binding(8) var<storage, read_write> counts: array<atomic<u32>>;

fn slot_of(t: u32) -> vec2<u32> {
    let s = ip.slot[t / 4u][t % 4u];
    return vec2<u32>(s & 0xffffu, s >> 16u);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    var s: Sample;
    if !load_sample(id, &s) {
        return;
    }
    let l = lookup(s.p, s.n);
    if !l.ok {
        visibility[s.i] = 1.0;
        return;
    }
    if inside(l.uv0) && tile_res(tile_of(l.uv0)) > 0u {
        atomicAdd(&counts[buffer_index(l.uv0)], 1u);
    }
    let stored = textureLoad(atlas, slot_of(l.t) + tile_texel(l.uv), 0);
    // a cleared texel (1: nothing between the tile's planes) is lit even for a receiver beyond
    // the far plane (delayed planes of a moving camera)
    visibility[s.i] = select(0.0, 1.0, l.z <= stored || stored >= 1.0);
}
