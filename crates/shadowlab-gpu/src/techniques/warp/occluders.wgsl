// The occluder pass before subdivision (`cull_hidden`, planar maps): the scene drawn into the
// DV-cropped map without the warp, res x res, as a plain shadow map. hzb.wgsl turns it into a
// pyramid of maxima, and subdiv.wgsl leaves an edge unsplit when all of it lies behind that.

struct OccOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
    @location(1) @interpolate(flat) material: u32,
}

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> OccOut {
    let v = vertices[vi];
    var o: OccOut;
    o.clip = dv_clip(v.pos, dv_rect(), false);
    o.uv = v.uv;
    o.material = v.material;
    return o;
}

@fragment
fn fs_main(in: OccOut) {
    if cut_out(materials[in.material], in.uv) {
        discard;
    }
}
