// sv full-screen passes. `fs_depth`: the G-buffer's depth copied into the depth-stencil target,
// moved `counts.w` float ulps towards the camera (0 = the exact copy), so that a receiver's own
// light cap, rasterised at the same depth, fails the less-than test (it lies behind). `fs_lit`:
// drawn with the stencil test "equal 0": writes 1 where no volume contains the sample.


@group(0) @binding(0) var g_depth: texture_depth_2d;
@group(0) @binding(1) var<uniform> sv: SvParams;

@vertex
fn vs_full(@builtin(vertex_index) vi: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((vi << 1u) & 2u), f32(vi & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn fs_depth(@builtin(position) p: vec4<f32>) -> @builtin(frag_depth) f32 {
    let d = textureLoad(g_depth, vec2<i32>(p.xy), 0);
    if d >= 1.0 || d <= 0.0 {
        return d;
    }
    let u = bitcast<u32>(d);
    return bitcast<f32>(u - min(u, sv.depth_offset));
}

@fragment
fn fs_lit() -> @location(0) vec4<f32> {
    return vec4<f32>(1.0);
}
