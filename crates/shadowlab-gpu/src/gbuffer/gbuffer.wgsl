// G-buffer pass: world position + linear view depth, geometric normal facing the camera,
// albedo, motion vector (pixels, current minus previous: camera motion and, for moving objects,
// the surface point's own motion, from its previous-frame position `previous_position`).
// Alpha-tested texels are discarded.

@group(0) @binding(0) var<uniform> frame: Frame;

// False where the scene has no alpha cut-outs and no single-sided material: then nothing is
// discarded, and the rasteriser may test depth before shading (no overdraw shaded).
override DISCARDS: bool = true;

// The triangle's normal and material travel as flat varyings (every vertex of a triangle
// stores the same face normal and material): read once per vertex, not once per fragment.
struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) uv: vec2<f32>,
    @location(2) @interpolate(flat) normal: vec3<f32>,
    @location(3) prev_world: vec3<f32>,
    @location(4) @interpolate(flat) base_color: vec4<f32>,
    // tex_offset, tex_width, tex_height, flags
    @location(5) @interpolate(flat) tex: vec4<u32>,
    @location(6) @interpolate(flat) alpha_cutoff: f32,
}

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> VsOut {
    let v = vertices[vi];
    var o: VsOut;
    o.clip = frame.view_proj * vec4<f32>(v.pos, 1.0);
    o.world = v.pos;
    o.uv = v.uv;
    o.normal = v.normal;
    o.prev_world = previous_position(vi);
    let m = materials[v.material];
    o.base_color = m.base_color;
    o.tex = vec4<u32>(m.tex_offset, m.tex_width, m.tex_height, m.flags);
    o.alpha_cutoff = m.alpha_cutoff;
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
    var m: Material;
    m.base_color = in.base_color;
    m.tex_offset = in.tex.x;
    m.tex_width = in.tex.y;
    m.tex_height = in.tex.z;
    m.flags = in.tex.w;
    m.alpha_cutoff = in.alpha_cutoff;
    if DISCARDS && (cut_out(m, in.uv) || (!front && (m.flags & MAT_DOUBLE_SIDED) == 0u)) {
        discard;
    }
    var n = in.normal;
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
