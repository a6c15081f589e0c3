// Tile rendering, store=atlas (the conventional alternative): the tile's frustum rasterized
// into its square of a Depth32Float atlas (viewport = the square) with the hardware depth test;
// same depth z as render.wgsl, 0 = near plane. Alpha-tested texels discarded.

struct TileParams {
    view_proj: mat4x4<f32>,
    tile: vec4<u32>,
}

@group(0) @binding(0) var<uniform> tp: TileParams;

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> DepthVsOut {
    return depth_vertex(vi, tp.view_proj);
}

@fragment
fn fs_main(in: DepthVsOut) {
    if depth_cut_out(in) {
        discard;
    }
}
