// One warped map's lookup bindings (lookup.wgsl reads the warp through these): the uniform, the
// reduced DV bounds and the two R32Float warp textures, bindings 6-9 of group 0.

@group(0) @binding(6) var<uniform> wp: WarpParams;
@group(0) @binding(7) var<storage, read> dv_bounds: array<u32>;
@group(0) @binding(8) var warp_x: texture_2d<f32>;
@group(0) @binding(9) var warp_y: texture_2d<f32>;

// Whether the map is cropped to a desired view that holds no view sample: nothing evaluates it
// (an uncropped map, `dpsm`, reduces no desired view).
fn no_samples() -> bool {
    return wp.dv_mode > 0.5 && dv_bounds[5] == 0u;
}

fn dv_rect() -> vec4<f32> {
    return dv_from_bounds(wp, vec4<u32>(dv_bounds[0], dv_bounds[1], dv_bounds[2], dv_bounds[3]));
}

fn warp_x_size() -> vec2<u32> {
    return textureDimensions(warp_x);
}

fn warp_y_size() -> vec2<u32> {
    return textureDimensions(warp_y);
}

fn warp_x_at(k: u32, row: u32) -> f32 {
    return textureLoad(warp_x, vec2<u32>(k, row), 0).x;
}

fn warp_y_at(col: u32, k: u32) -> f32 {
    return textureLoad(warp_y, vec2<u32>(col, k), 0).x;
}
