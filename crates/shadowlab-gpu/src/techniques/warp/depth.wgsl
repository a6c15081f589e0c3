// Warped shadow-map pass (seed 000 Algorithm 1 in the vertex stage): each vertex is projected,
// cropped to the desired view and moved by the warp textures; depth stays the base projection's
// post-projective depth (0 = near the light). With subdivision on, the vertices come from the
// sub-triangle records of subdiv.wgsl (triangle index, level n, grid cell, orientation).

@group(0) @binding(10) var<storage, read> records: array<u32>;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
    @location(1) @interpolate(flat) material: u32,
}

// Corner c of sub-triangle `packed` of triangle `tri`: barycentrics on an n x n grid.
fn sub_vertex(tri: u32, packed: u32, c: u32) -> Vertex {
    let n = packed & 0xffu;
    var v = vertices[3u * tri];
    if n == 0u {
        // an unwritten slot: degenerate, rasterises nothing
        v.pos = vec3<f32>(0.0);
        return v;
    }
    let i = (packed >> 8u) & 0xffu;
    let j = (packed >> 16u) & 0xffu;
    let down = (packed >> 24u) != 0u;
    var g = vec2<u32>(i, j);
    if down {
        g = array<vec2<u32>, 3>(vec2<u32>(i + 1u, j), vec2<u32>(i + 1u, j + 1u), vec2<u32>(i, j + 1u))[c];
    } else {
        g = array<vec2<u32>, 3>(vec2<u32>(i, j), vec2<u32>(i + 1u, j), vec2<u32>(i, j + 1u))[c];
    }
    let b1 = f32(g.x) / f32(n);
    let b2 = f32(g.y) / f32(n);
    let b0 = 1.0 - b1 - b2;
    let v1 = vertices[3u * tri + 1u];
    let v2 = vertices[3u * tri + 2u];
    v.pos = v.pos * b0 + v1.pos * b1 + v2.pos * b2;
    v.uv = v.uv * b0 + v1.uv * b1 + v2.uv * b2;
    return v;
}

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> VsOut {
    var v: Vertex;
    if wp.imp.w > 0.0 {
        let s = vi / 3u;
        v = sub_vertex(records[2u * s], records[2u * s + 1u], vi % 3u);
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
