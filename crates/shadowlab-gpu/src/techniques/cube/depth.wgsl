// Cube shadow map, one face per pass: depth = linear distance to the light / far (0 at the
// light, 1 at `far`), written per fragment, so one bias in world units behaves the same on all
// six faces. Per-face culling: a triangle whose three corners lie outside one side plane of the
// face's frustum is dropped in the vertex stage (collapsed behind the near plane).

struct CubeFace {
    view_proj: mat4x4<f32>,
    // xyz: light position, w: far (distance that maps to depth 1)
    light: vec4<f32>,
    // x: face index, y: near (f32 bits; depth=hardware)
    face: vec4<u32>,
}

@group(0) @binding(0) var<uniform> cf: CubeFace;

// False for the static triangles, drawn from per-face lists culled once on the CPU
// (`cube::outside_face`); true for the moving ones, drawn whole into every face.
override CULL_IN_VS: bool = true;
// `depth=hardware`: no distance written per fragment; the rasteriser's depth is reversed,
// near / z (z = the distance along the face's axis; face.y holds `near` as bits), so that the
// evaluation recovers the distance along the texel's centre ray.
override HW_DEPTH: bool = false;

struct CubeVsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
    @location(1) @interpolate(flat) material: u32,
    @location(2) world: vec3<f32>,
}

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> CubeVsOut {
    let o = depth_vertex(vi, cf.view_proj);
    var out: CubeVsOut;
    out.clip = o.clip;
    out.uv = o.uv;
    out.material = o.material;
    out.world = vertices[vi].pos;
    if HW_DEPTH {
        // clip.w is the distance along the face axis: NDC depth = near / w
        out.clip.z = bitcast<f32>(cf.face.y);
    }
    if !CULL_IN_VS {
        return out;
    }
    let b = cube_basis(cf.face.x);
    let first = vi - vi % 3u;
    var outside = vec4<bool>(true);
    for (var k = 0u; k < 3u; k++) {
        let d = vertices[first + k].pos - cf.light.xyz;
        let z = dot(d, b[0]);
        let s = dot(d, b[1]);
        let t = dot(d, b[2]);
        outside = outside & vec4<bool>(s > z, -s > z, t > z, -t > z);
    }
    if any(outside) {
        out.clip = vec4<f32>(0.0, 0.0, -1.0, 1.0);
    }
    return out;
}

@fragment
fn fs_main(in: CubeVsOut) -> @builtin(frag_depth) f32 {
    if cut_out(materials[in.material], in.uv) {
        discard;
    }
    return length(in.world - cf.light.xyz) / cf.light.w;
}

// `depth=hardware` on scenes with cut-outs: the test alone, the rasteriser writes the depth.
@fragment
fn fs_cut_out(in: CubeVsOut) {
    if cut_out(materials[in.material], in.uv) {
        discard;
    }
}
