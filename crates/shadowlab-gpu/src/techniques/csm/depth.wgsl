// Cascade depth pass: one cascade (one layer of the map array) per render pass, depth only,
// alpha-tested texels discarded. Depth is orthographic (linear), 0 = nearest the light.

struct CsmDepth {
    view_proj: mat4x4<f32>,
}

@group(0) @binding(0) var<uniform> cascade: CsmDepth;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
    @location(1) @interpolate(flat) material: u32,
}

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> VsOut {
    let v = vertices[vi];
    var o: VsOut;
    o.clip = cascade.view_proj * vec4<f32>(v.pos, 1.0);
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
