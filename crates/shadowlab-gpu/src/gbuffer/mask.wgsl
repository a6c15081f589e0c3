// Evaluation mask: 1 where geometry is present, faces the light, and lies inside a spot cone.
// Every technique and the reference evaluate exactly these samples (light.rs `evaluated`).

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<uniform> light: LightU;
@group(0) @binding(2) var g_position: texture_2d<f32>;
@group(0) @binding(3) var g_normal: texture_2d<f32>;
@group(0) @binding(4) var<storage, read_write> mask: array<u32>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= frame.size.x || id.y >= frame.size.y {
        return;
    }
    let pos = textureLoad(g_position, id.xy, 0);
    let n = textureLoad(g_normal, id.xy, 0).xyz;
    var m = 0u;
    if pos.w > 0.0 && dot(n, to_light(light, pos.xyz)) > 0.0 {
        m = 1u;
        if light.kind == LIGHT_SPOT && dot(normalize(pos.xyz - light.position.xyz), light.direction.xyz) <= light.cos_cone {
            m = 0u;
        }
    }
    mask[id.y * frame.size.x + id.x] = m;
}
