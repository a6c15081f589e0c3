// Shading: albedo x (ambient + (1 - ambient) N.L x visibility), sRGB-encoded RGBA8; a sky
// colour where there is no geometry. Pixels outside the mask get ambient only.

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<uniform> light: LightU;
@group(0) @binding(2) var g_position: texture_2d<f32>;
@group(0) @binding(3) var g_normal: texture_2d<f32>;
@group(0) @binding(4) var g_albedo: texture_2d<f32>;
@group(0) @binding(5) var<storage, read> mask: array<u32>;
@group(0) @binding(6) var<storage, read> visibility: array<f32>;
@group(0) @binding(7) var<storage, read_write> color: array<u32>;

const AMBIENT: f32 = 0.18;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= frame.size.x || id.y >= frame.size.y {
        return;
    }
    let i = id.y * frame.size.x + id.x;
    let pos = textureLoad(g_position, id.xy, 0);
    var c = vec3<f32>(0.55, 0.68, 0.85);
    if pos.w > 0.0 {
        let a = textureLoad(g_albedo, id.xy, 0).rgb;
        var direct = 0.0;
        if mask[i] != 0u {
            let n = textureLoad(g_normal, id.xy, 0).xyz;
            direct = max(dot(n, to_light(light, pos.xyz)), 0.0) * clamp(visibility[i], 0.0, 1.0);
        }
        c = a * (AMBIENT + (1.0 - AMBIENT) * direct);
    }
    color[i] = pack4x8unorm(vec4<f32>(pow(clamp(c, vec3<f32>(0.0), vec3<f32>(1.0)), vec3<f32>(1.0 / 2.2)), 1.0));
}
