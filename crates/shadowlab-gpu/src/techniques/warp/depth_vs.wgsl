// The depth pass's vertex stage with a fragment stage after it (depth_plain.wgsl or
// depth_exact.wgsl).

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> VsOut {
    return depth_vertex(vi);
}
