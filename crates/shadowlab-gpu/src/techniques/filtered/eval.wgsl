// Filtered shadow-map evaluation: each sample is offset (normal offset and constant bias in
// world units of one shadow texel), projected into the light, and its linear depth d compared
// with the map through the representation's upper bound. Full variants: the 4 texels around
// the sample are loaded and their (pre-blurred) moments interpolated bilinearly (RGBA32Float
// is not filterable in core WebGPU, so the bilinear filter is done here). Single-depth
// variants: one textureGather of 4 depths, converted and interpolated in moments.wgsl.
// Also counts the view samples per texel (sampling statistics).

struct FilteredParams {
    light_view_proj: mat4x4<f32>,
    texel: vec4<f32>,
    mode: vec4<u32>,
    shape: vec4<f32>,
    bias: vec4<f32>,
}

@group(0) @binding(6) var<uniform> fp: FilteredParams;
@group(0) @binding(7) var shadow_map: texture_2d<f32>;
@group(0) @binding(8) var gather_sampler: sampler;
@group(0) @binding(9) var<storage, read_write> counts: array<atomic<u32>>;

fn to_map(p: vec3<f32>) -> vec3<f32> {
    let c = fp.light_view_proj * vec4<f32>(p, 1.0);
    let ndc = c.xyz / c.w;
    let depth = select(c.z, c.w * fp.texel.w, fp.texel.y > 0.5);
    return vec3<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5, depth);
}

fn visibility_of(m: vec4<f32>, d: f32) -> f32 {
    switch fp.mode.x {
        case 0u: {
            return vsm_visibility(m, d, fp.shape.x);
        }
        case 1u: {
            return esm_visibility(m, d, fp.shape.y);
        }
        case 2u: {
            return evsm_visibility(m, d, fp.shape.z, fp.shape.w, fp.shape.x);
        }
        default: {
            return msm_visibility(m, d, fp.bias.x);
        }
    }
}

fn visibility_gather(z: vec4<f32>, w: vec4<f32>, d: f32) -> f32 {
    switch fp.mode.x {
        case 0u: {
            return vsm_visibility_gather(z, w, d, fp.shape.x);
        }
        case 1u: {
            return esm_visibility_gather(z, w, d, fp.shape.y);
        }
        case 2u: {
            return evsm_visibility_gather(z, w, d, fp.shape.z, fp.shape.w, fp.shape.x);
        }
        default: {
            return msm_visibility_gather(z, w, d, fp.bias.x);
        }
    }
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    var s: Sample;
    if !load_sample(id, &s) {
        return;
    }
    let res = fp.texel.z;
    let m0 = to_map(s.p);
    if all(m0.xy >= vec2<f32>(0.0)) && all(m0.xy < vec2<f32>(1.0)) {
        let t = vec2<u32>(m0.xy * res);
        atomicAdd(&counts[t.y * u32(res) + t.x], 1u);
    }
    var texel = fp.texel.x;
    if fp.texel.y > 0.5 {
        texel = fp.texel.x * max(dot(s.p - light.position.xyz, light.direction.xyz), 0.0);
    }
    let l = to_light(light, s.p);
    let q = s.p + s.n * (fp.bias.z * texel) + l * (fp.bias.y * texel);
    let m = to_map(q);
    if any(m.xy < vec2<f32>(0.0)) || any(m.xy > vec2<f32>(1.0)) || m.z > 1.0 {
        visibility[s.i] = 1.0;
        return;
    }
    let d = max(m.z, 0.0);
    let w = gather_weights(m.xy, res);
    if fp.mode.y != 0u {
        let z = textureGather(0, shadow_map, gather_sampler, m.xy);
        visibility[s.i] = visibility_gather(z, w, d);
        return;
    }
    // the same 2x2 texels and order as the gather
    let t0 = vec2<i32>(floor(m.xy * res - 0.5));
    let hi = vec2<i32>(i32(res) - 1);
    let m4 = w.x * textureLoad(shadow_map, clamp(t0 + vec2<i32>(0, 1), vec2<i32>(0), hi), 0)
        + w.y * textureLoad(shadow_map, clamp(t0 + vec2<i32>(1, 1), vec2<i32>(0), hi), 0)
        + w.z * textureLoad(shadow_map, clamp(t0 + vec2<i32>(1, 0), vec2<i32>(0), hi), 0)
        + w.w * textureLoad(shadow_map, clamp(t0, vec2<i32>(0), hi), 0);
    visibility[s.i] = visibility_of(m4, d);
}
