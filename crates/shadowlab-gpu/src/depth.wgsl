// Depth-only scene raster from a light, shared by the shadow passes (sm, csm, iasm tiles and
// atlas): the vertex fetch through a view-projection and the alpha cut-out test. Composed
// after scene.wgsl by `shaders::compose_depth`; each pass keeps its own uniform and entry points.

struct DepthVsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
    @location(1) @interpolate(flat) material: u32,
}

// Scene vertex `vi` through `view_proj`, with what the cut-out test needs.
fn depth_vertex(vi: u32, view_proj: mat4x4<f32>) -> DepthVsOut {
    let v = vertices[vi];
    var o: DepthVsOut;
    o.clip = view_proj * vec4<f32>(v.pos, 1.0);
    o.uv = v.uv;
    o.material = v.material;
    return o;
}

// True where the fragment's alpha-tested material is cut out (the pass discards it: it casts
// no shadow).
fn depth_cut_out(in: DepthVsOut) -> bool {
    return cut_out(materials[in.material], in.uv);
}
