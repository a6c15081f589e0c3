// Shared declarations: prepended to every shader by `shaders::compose`.
// Layouts mirror Rust structs (scene.rs Vertex, scene_gpu.rs GpuMaterial, frame.rs); tests check them.

struct Vertex {
    pos: vec3<f32>,
    material: u32,
    normal: vec3<f32>,
    _pad0: f32,
    uv: vec2<f32>,
    _pad1: vec2<f32>,
}

const MAT_TEXTURED: u32 = 1u;
const MAT_MASKED: u32 = 2u;
const MAT_DOUBLE_SIDED: u32 = 4u;

struct Material {
    base_color: vec4<f32>,
    tex_offset: u32,
    tex_width: u32,
    tex_height: u32,
    flags: u32,
    alpha_cutoff: f32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

struct Frame {
    view_proj: mat4x4<f32>,
    prev_view_proj: mat4x4<f32>,
    camera_pos: vec4<f32>,
    size: vec2<u32>,
    _pad: vec2<u32>,
}

const LIGHT_DIRECTIONAL: u32 = 0u;
const LIGHT_SPOT: u32 = 1u;
const LIGHT_POINT: u32 = 2u;

struct LightU {
    position: vec4<f32>,
    direction: vec4<f32>,
    kind: u32,
    cos_cone: f32,
    eps: f32,
    _pad: u32,
}

// Unit vector from p towards the light.
fn to_light(l: LightU, p: vec3<f32>) -> vec3<f32> {
    if l.kind == LIGHT_DIRECTIONAL {
        return -l.direction.xyz;
    }
    return normalize(l.position.xyz - p);
}

// Nearest texel with repeat wrapping: the rule of scene.rs `texel_index`.
fn texel_index(w: u32, h: u32, uv: vec2<f32>) -> u32 {
    let f = uv - floor(uv);
    let x = min(u32(f.x * f32(w)), w - 1u);
    let y = min(u32(f.y * f32(h)), h - 1u);
    return y * w + x;
}
