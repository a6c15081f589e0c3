// G-buffer pass: world position + linear view depth, geometric normal facing the camera,
// albedo, motion vector (pixels, current minus previous: camera motion and, for moving objects,
// the surface point's own motion, from its previous-frame position `previous_position`).
// Alpha-tested texels are discarded.

@group(0) @binding(0) var<uniform> frame: Frame;

// False where the scene has no alpha cut-outs and no single-sided material: then nothing is
// discarded, and the rasteriser may test depth before shading (no overdraw shaded).
override DISCARDS: bool = true;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) uv: vec2<f32>,
    @location(2) @interpolate(flat) tri: u32,
    @location(3) prev_world: vec3<f32>,
}

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> VsOut {
    let v = vertices[vi];
    var o: VsOut;
    o.clip = frame.view_proj * vec4<f32>(v.pos, 1.0);
    o.world = v.pos;
    o.uv = v.uv;
    o.tri = vi / 3u;
    o.prev_world = previous_position(vi);
    return o;
}

struct GOut {
    @location(0) position: vec4<f32>,
    @location(1) normal: vec4<f32>,
    @location(2) albedo: vec4<f32>,
    @location(3) motion: vec2<f32>,
}

@fragment
fn fs_main(in: VsOut, @builtin(front_facing) front: bool) -> GOut {
    let v = vertices[in.tri * 3u];
    let m = materials[v.material];
    if DISCARDS && (cut_out(m, in.uv) || (!front && (m.flags & MAT_DOUBLE_SIDED) == 0u)) {
        discard;
    }
    var n = v.normal;
    if dot(n, frame.camera_pos.xyz - in.world) < 0.0 {
        n = -n;
    }
    let cur = frame.view_proj * vec4<f32>(in.world, 1.0);
    let prev = frame.prev_view_proj * vec4<f32>(in.prev_world, 1.0);
    let size = vec2<f32>(frame.size);
    let motion = (cur.xy / cur.w - prev.xy / prev.w) * vec2<f32>(0.5, -0.5) * size;
    var o: GOut;
    o.position = vec4<f32>(in.world, cur.w);
    o.normal = vec4<f32>(n, 1.0);
    o.albedo = vec4<f32>(material_color(m, in.uv).rgb, 1.0);
    o.motion = motion;
    return o;
}
