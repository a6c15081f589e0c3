// Tile rendering (thesis 3.5, Listing 3.1): the scene rasterized with one tile's orthographic
// frustum into a viewport of r x r pixels; each fragment writes its depth into the linear
// shadow buffer at i0 + floor(y) r + floor(x) by atomic max on the inverted depth 1 - z
// (positive floats order like their bits), so the buffer holds the depth nearest the light.
// z = (light depth - near) / (far - near); cleared texels (0) read as z = 1 (nothing).
// The colour target is a dummy (no writes): wgpu needs one attachment per render pass.

struct TileParams {
    view_proj: mat4x4<f32>,
    // x: r, y: i0
    tile: vec4<u32>,
}

@group(0) @binding(0) var<uniform> tp: TileParams;
@group(0) @binding(1) var<storage, read_write> shadow: array<atomic<u32>>;

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> DepthVsOut {
    return depth_vertex(vi, tp.view_proj);
}

@fragment
fn fs_main(in: DepthVsOut) -> @location(0) vec4<f32> {
    if depth_cut_out(in) {
        discard;
    }
    let r = tp.tile.x;
    let xy = min(vec2<u32>(in.clip.xy), vec2<u32>(r - 1u));
    let idx = tp.tile.y + xy.y * r + xy.x;
    atomicMax(&shadow[idx], bitcast<u32>(1.0 - in.clip.z));
    return vec4<f32>(0.0);
}
