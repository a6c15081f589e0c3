// Cascade depth pass: one cascade (one layer of the map array) per render pass, depth only,
// alpha-tested texels discarded. Depth is orthographic (linear), 0 = nearest the light.

struct CsmDepth {
    view_proj: mat4x4<f32>,
}

@group(0) @binding(0) var<uniform> cascade: CsmDepth;

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> DepthVsOut {
    return depth_vertex(vi, cascade.view_proj);
}

@fragment
fn fs_main(in: DepthVsOut) {
    if depth_cut_out(in) {
        discard;
    }
}
