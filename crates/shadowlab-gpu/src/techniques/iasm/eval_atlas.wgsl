// IASM evaluation, store=atlas: the depth read from the tile's square in the depth atlas
// (corner `slot`, texel p_b of equation 3.4). The pass itself is eval_main.wgsl.

@group(0) @binding(6) var<uniform> ip: IasmParams;
@group(0) @binding(7) var atlas: texture_depth_2d;
@group(0) @binding(8) var<storage, read_write> counts: array<atomic<u32>>;

fn slot_of(t: u32) -> vec2<u32> {
    let s = ip.slot[t / 4u][t % 4u];
    return vec2<u32>(s & 0xffffu, s >> 16u);
}

fn stored_depth(l: Lookup) -> f32 {
    return textureLoad(atlas, slot_of(l.t) + tile_texel(l.uv), 0);
}
