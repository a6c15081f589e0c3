// mdsm evaluation: PCF(k, n) over the n-SM. Each evaluated sample is offset exactly as in `sm`
// (normal offset, constant and slope-scaled bias in world units of one shadow texel, plus the
// receiver-plane term for the kernel), and, when the search region is covered (sel.w), by its
// half width too: the extra depths come from up to (sqrt(q)-1)/2 texels away and see a sloped
// receiver that much deeper. Then k taps on a sqrt(k) x sqrt(k) grid one texel apart, centred
// on the sample, each one RGBA32F fetch and one n-shadow test. Also counts view samples per
// texel (sampling statistics), as `sm`.

struct MdsmParams {
    light_view_proj: mat4x4<f32>,
    // world size of one texel (orthographic) or per unit of light-view depth (perspective),
    // 1 if perspective, resolution, PCF grid width sqrt(k) (sm's bias.wgsl reads it whole)
    texel: vec4<f32>,
    // constant bias, slope-scaled bias, normal offset (all in texels), max slope (sm's bias.wgsl)
    bias: vec4<f32>,
    // depths per texel
    n: u32,
    // search width sqrt(q) (1 when n = 1)
    region: u32,
    // SELECT_MINMAX or SELECT_SORT
    select: u32,
    // 1 if the slope bias covers the search region
    region_bias: u32,
}

@group(0) @binding(6) var<uniform> md: MdsmParams;
@group(0) @binding(7) var nsm: texture_2d<f32>;
@group(0) @binding(8) var<storage, read_write> counts: array<atomic<u32>>;

fn to_map(p: vec3<f32>) -> vec3<f32> {
    let c = md.light_view_proj * vec4<f32>(p, 1.0);
    let ndc = c.xyz / c.w;
    return vec3<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5, ndc.z);
}

// The n-shadow test (seed 003 section 4.2; shadowlab_core::mdsm::n_shadow_test): s = the number
// of the sorted depths Z1 >= ... >= Zn in front of d (Zj < d); coverage s/n, lit (n - s)/n.
// The CPU walks from Z1 to the first Zi < d (the paper's i, s = n - i + 1); here the same s is
// counted without branches over the first n channels (`lanes`). Core's unit tests prove walk ==
// count; tests/mdsm.rs checks this shader against the CPU pixel by pixel.
fn n_shadow_test(z: vec4<f32>, lanes: vec4<u32>, d: f32) -> u32 {
    return dot(select(vec4<u32>(0u), lanes, z < vec4<f32>(d)), vec4<u32>(1u));
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    var s: Sample;
    if !load_sample(id, &s) {
        return;
    }
    let p = s.p;
    let nrm = s.n;
    let i = s.i;
    let l = to_light(light, p);
    let res = md.texel.z;
    let ires = i32(res);

    // sampling statistics: the texel this view sample lands in
    count_sample(to_map(p), res);

    // `sm`'s bias (bias.wgsl), the kernel's and the search region's reach added
    let kw = i32(md.texel.w);
    let half = f32(kw - 1) * 0.5;
    var reach = half;
    if md.region_bias == 1u {
        reach += f32(md.region - 1u) * 0.5;
    }
    let q = biased_point(p, nrm, l, texel_at(md.texel, p), md.bias, reach);
    let m = to_map(q);
    if any(m.xy < vec2<f32>(0.0)) || any(m.xy > vec2<f32>(1.0)) || m.z > 1.0 {
        visibility[i] = 1.0;
        return;
    }
    let n = md.n;
    let lanes = vec4<u32>(vec4<u32>(0u, 1u, 2u, 3u) < vec4<u32>(n));
    var lit = 0u;
    for (var y = 0; y < kw; y++) {
        for (var x = 0; x < kw; x++) {
            let uv = m.xy + (vec2<f32>(f32(x), f32(y)) - half) / res;
            // nearest texel, clamped to the edge (what `sm`'s nearest comparison sampler reads)
            let t = clamp(vec2<i32>(floor(uv * res)), vec2<i32>(0), vec2<i32>(ires - 1));
            lit += n - n_shadow_test(textureLoad(nsm, t, 0), lanes, m.z);
        }
    }
    visibility[i] = f32(lit) / f32(n * u32(kw * kw));
}
