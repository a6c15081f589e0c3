// Page rendering into the atlas: instance i draws the scene through page i's orthographic
// view-projection (the viewport and scissor are the page's atlas slot), with the hardware
// depth test; depth linear in light distance, 0 = near the light. `vs_clear` covers the
// viewport at depth 1 (depth test Always): it clears one slot inside the atlas pass.

@group(0) @binding(0) var<storage, read> page_view_proj: array<mat4x4<f32>>;

@vertex
fn vs_main(@builtin(vertex_index) vi: u32, @builtin(instance_index) ii: u32) -> DepthVsOut {
    return depth_vertex(vi, page_view_proj[ii]);
}

@fragment
fn fs_main(in: DepthVsOut) {
    if depth_cut_out(in) {
        discard;
    }
}

@vertex
fn vs_clear(@builtin(vertex_index) vi: u32) -> @builtin(position) vec4<f32> {
    let x = f32((vi << 1u) & 2u) * 2.0 - 1.0;
    let y = f32(vi & 2u) * 2.0 - 1.0;
    return vec4<f32>(x, y, 1.0, 1.0);
}
