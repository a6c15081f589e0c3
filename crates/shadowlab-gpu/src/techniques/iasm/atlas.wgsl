// Tile rendering, store=atlas (the conventional alternative): the tile's frustum rasterized
// into its square of a Depth32Float atlas (viewport = the square) with the hardware depth test;
// same depth z as render.wgsl, 0 = near plane. Alpha-tested texels discarded.

struct TileParams {
    view_proj: mat4x4<f32>,
    tile: vec4<u32>,
}

@group(0) @binding(0) var<uniform> tp: TileParams;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
    @location(1) @interpolate(flat) material: u32,
}

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> VsOut {
    let v = vertices[vi];
    var o: VsOut;
    o.clip = tp.view_proj * vec4<f32>(v.pos, 1.0);
    o.uv = v.uv;
    o.material = v.material;
    return o;
}

@fragment
fn fs_main(in: VsOut) {
    if cut_out(materials[in.material], in.uv) {
        discard;
    }
}
