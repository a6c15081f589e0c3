// Warped shadow-map pass (seed 000 Algorithm 1 in the vertex stage): each vertex is projected,
// cropped to the desired view and moved by the warp textures; depth stays the base projection's
// post-projective depth (0 = near the light). With subdivision on, the vertices come from the
// pieces of subdiv.wgsl.

@group(0) @binding(10) var<storage, read> pieces: array<vec4<u32>>;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
    @location(1) @interpolate(flat) material: u32,
}

// Corner c of a subdivision piece (triangle, three unorm16x2 barycentrics; subdiv.wgsl).
fn piece_vertex(p: vec4<u32>, c: u32) -> Vertex {
    let b = unpack2x16unorm(array<u32, 3>(p.y, p.z, p.w)[c]);
    var v = vertices[3u * p.x];
    let v1 = vertices[3u * p.x + 1u];
    let v2 = vertices[3u * p.x + 2u];
    let b0 = 1.0 - b.x - b.y;
    v.pos = v.pos * b0 + v1.pos * b.x + v2.pos * b.y;
    v.uv = v.uv * b0 + v1.uv * b.x + v2.uv * b.y;
    return v;
}

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> VsOut {
    var v: Vertex;
    if wp.imp.w > 0.0 {
        v = piece_vertex(pieces[vi / 3u], vi % 3u);
    } else {
        v = vertices[vi];
    }
    var o: VsOut;
    o.clip = warped_clip(v.pos, dv_rect());
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
