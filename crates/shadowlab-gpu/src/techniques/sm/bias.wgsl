// `sm`'s bias model and sampling statistics, shared by sm/eval.wgsl and mdsm/eval.wgsl (each
// declares its own uniform and `counts`). Bias is in units of one shadow texel: the world size
// of a texel at the sample, so it scales with the map's resolution and coverage.

// Sampling statistics: one more view sample in the texel of map position m0 (res x res map;
// positions outside the map are not counted).
fn count_sample(m0: vec3<f32>, res: f32) {
    if COUNT_SAMPLES && all(m0.xy >= vec2<f32>(0.0)) && all(m0.xy < vec2<f32>(1.0)) {
        let t = vec2<u32>(m0.xy * res);
        atomicAdd(&counts[t.y * u32(res) + t.x], 1u);
    }
}

// World size of one texel at p: texel.x (orthographic), or texel.x per unit of light-view
// depth (perspective, texel.y = 1).
fn texel_at(texel: vec4<f32>, p: vec3<f32>) -> f32 {
    var t = texel.x;
    if texel.y > 0.5 {
        t = texel.x * max(dot(p - light.position.xyz, light.direction.xyz), 0.0);
    }
    return t;
}

// The sample p (normal n, l towards the light) moved by the bias, `texel` world units a texel:
// bias.z texels along the normal, then bias.x + (bias.y + reach) x tan texels towards the
// light, tan of the angle to the light clamped at bias.w. Taps up to `reach` texels away see a
// sloped receiver `reach * tan` texels deeper: that much slope bias is added for them
// (receiver-plane bias, Isidoro 2006).
fn biased_point(p: vec3<f32>, n: vec3<f32>, l: vec3<f32>, texel: f32, bias: vec4<f32>, reach: f32) -> vec3<f32> {
    let cos_t = clamp(dot(n, l), 1e-4, 1.0);
    let tan_t = min(sqrt(1.0 - cos_t * cos_t) / cos_t, bias.w);
    return p + n * (bias.z * texel) + l * ((bias.x + (bias.y + reach) * tan_t) * texel);
}
