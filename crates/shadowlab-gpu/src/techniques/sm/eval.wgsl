// Shadow-map evaluation: each evaluated sample is offset (normal offset, constant and
// slope-scaled bias, in world units of one shadow texel), projected into the light, and
// compared with an NxN kernel of single-texel hardware comparisons (PCF). Also counts how many
// view samples land in each texel (sampling statistics).

struct SmParams {
    light_view_proj: mat4x4<f32>,
    texel: vec4<f32>,
    bias: vec4<f32>,
}

@group(0) @binding(6) var<uniform> sm: SmParams;
// The PCF kernel width (= sm.texel.w), fixed at pipeline creation (pass.rs): a constant loop
// bound is unrolled; lavapipe runs a loop bounded by a uniform value with masked lanes.
override PCF: u32;
@group(0) @binding(7) var shadow_map: texture_depth_2d;
@group(0) @binding(8) var cmp: sampler_comparison;
@group(0) @binding(9) var<storage, read_write> counts: array<atomic<u32>>;

fn to_map(p: vec3<f32>) -> vec3<f32> {
    let c = sm.light_view_proj * vec4<f32>(p, 1.0);
    let ndc = c.xyz / c.w;
    return vec3<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5, ndc.z);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    var s: Sample;
    if !load_sample(id, &s) {
        return;
    }
    let p = s.p;
    let n = s.n;
    let i = s.i;
    let l = to_light(light, p);
    let res = sm.texel.z;

    // sampling statistics: the texel this view sample lands in
    count_sample(to_map(p), res);

    // the PCF kernel reaches `half` texels from the sample (bias.wgsl)
    let k = i32(PCF);
    let half = f32(k - 1) * 0.5;
    let q = biased_point(p, n, l, texel_at(sm.texel, p), sm.bias, half);
    let m = to_map(q);
    if any(m.xy < vec2<f32>(0.0)) || any(m.xy > vec2<f32>(1.0)) || m.z > 1.0 {
        visibility[i] = 1.0;
        return;
    }
    var lit = 0.0;
    for (var y = 0; y < k; y++) {
        for (var x = 0; x < k; x++) {
            let uv = m.xy + (vec2<f32>(f32(x), f32(y)) - half) / res;
            lit += textureSampleCompareLevel(shadow_map, cmp, uv, m.z);
        }
    }
    visibility[i] = lit / f32(k * k);
}
