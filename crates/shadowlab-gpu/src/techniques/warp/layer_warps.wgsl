// The warps of every layer of a warp::Layers as lookup.wgsl reads them (bindings 8-9, array
// textures), at the layer at hand (layer_bind.wgsl): the evaluation and the subdivision over
// all layers.

@group(0) @binding(8) var warp_x: texture_2d_array<f32>;
@group(0) @binding(9) var warp_y: texture_2d_array<f32>;

fn warp_x_size() -> vec2<u32> {
    return textureDimensions(warp_x);
}

fn warp_y_size() -> vec2<u32> {
    return textureDimensions(warp_y);
}

fn warp_x_at(k: u32, row: u32) -> f32 {
    return textureLoad(warp_x, vec2<u32>(k, row), layer, 0).x;
}

fn warp_y_at(col: u32, k: u32) -> f32 {
    return textureLoad(warp_y, vec2<u32>(col, k), layer, 0).x;
}
