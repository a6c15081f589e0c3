// Shadow-map pass: depth only, alpha-tested texels discarded. Depth is post-projective
// (orthographic: linear in light-space distance; spot: perspective), 0 = near the light.

struct SmParams {
    light_view_proj: mat4x4<f32>,
    // x: world size of one texel (orthographic) or per unit of light-view depth (perspective)
    // y: 1 if perspective; z: resolution; w: pcf kernel width
    texel: vec4<f32>,
    // x: constant bias, y: slope-scaled bias, z: normal offset (all in texels), w: max slope
    bias: vec4<f32>,
}

@group(0) @binding(0) var<uniform> sm: SmParams;

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> DepthVsOut {
    return depth_vertex(vi, sm.light_view_proj);
}

@fragment
fn fs_main(in: DepthVsOut) {
    if depth_cut_out(in) {
        discard;
    }
}
