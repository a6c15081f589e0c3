// Cascaded shadow map evaluation. Each evaluated sample picks the first cascade whose slice of
// view depths holds its linear depth; inside the blend band at the far end of a slice it mixes
// in the next cascade. Per cascade: normal offset and constant bias in texels of that cascade,
// projection into its orthographic box, NxN PCF of hardware comparisons (the receiver-plane
// kernel bias of `sm`). A sample outside the chosen box tries the next cascades, then the
// finer ones, then counts as lit. Also counts view samples per texel (all cascades) and records the cascade used.

struct Cascade {
    view_proj: mat4x4<f32>,
    // x: world size of one texel, y: slice near (view depth), z: slice far, w: unused
    info: vec4<f32>,
}

struct CsmParams {
    cascades: array<Cascade, 8>,
    // cascades in use
    count: f32,
    // map side per cascade (texels)
    res: f32,
    // PCF kernel width
    pcf: f32,
    // blend band (fraction of a slice)
    blend: f32,
    // constant bias and normal offset (texels), max slope for the kernel bias
    bias: f32,
    normal_offset: f32,
    max_slope: f32,
    pad0: f32,
}

@group(0) @binding(6) var<uniform> csm: CsmParams;
@group(0) @binding(7) var maps: texture_depth_2d_array;
@group(0) @binding(8) var cmp: sampler_comparison;
@group(0) @binding(9) var<storage, read_write> counts: array<atomic<u32>>;
// per pixel: 0 not evaluated, else 1 + cascade, + 16 when blended with the next
@group(0) @binding(10) var<storage, read_write> chosen: array<u32>;

fn to_map(c: u32, p: vec3<f32>) -> vec3<f32> {
    let q = csm.cascades[c].view_proj * vec4<f32>(p, 1.0);
    return vec3<f32>(q.x * 0.5 + 0.5, 0.5 - q.y * 0.5, q.z);
}

fn inside(m: vec3<f32>) -> bool {
    return all(m.xy >= vec2<f32>(0.0)) && all(m.xy <= vec2<f32>(1.0)) && m.z <= 1.0;
}

// Visibility of p from cascade c, or -1 when p's offset position is outside its box.
fn lookup(c: u32, p: vec3<f32>, n: vec3<f32>, l: vec3<f32>) -> f32 {
    let texel = csm.cascades[c].info.x;
    let res = csm.res;
    let k = i32(csm.pcf);
    let half = f32(k - 1) * 0.5;
    let cos_t = clamp(dot(n, l), 1e-4, 1.0);
    let tan_t = min(sqrt(1.0 - cos_t * cos_t) / cos_t, csm.max_slope);
    let q = p + n * (csm.normal_offset * texel) + l * ((csm.bias + half * tan_t) * texel);
    let m = to_map(c, q);
    if !inside(m) {
        return -1.0;
    }
    var lit = 0.0;
    for (var y = 0; y < k; y++) {
        for (var x = 0; x < k; x++) {
            let uv = m.xy + (vec2<f32>(f32(x), f32(y)) - half) / res;
            lit += textureSampleCompareLevel(maps, cmp, uv, i32(c), m.z);
        }
    }
    return lit / f32(k * k);
}

// First cascade from `first` on that covers p (-1 visibility: none), as (visibility, cascade).
fn resolve(first: u32, p: vec3<f32>, n: vec3<f32>, l: vec3<f32>) -> vec2<f32> {
    let count = u32(csm.count);
    for (var c = first; c < count; c++) {
        let v = lookup(c, p, n, l);
        if v >= 0.0 {
            return vec2<f32>(v, f32(c));
        }
    }
    // then the finer ones (a fitted box from last frame's samples can miss a sample that the
    // camera's motion moved across a split, away from the camera)
    for (var c = first; c > 0u; c--) {
        let v = lookup(c - 1u, p, n, l);
        if v >= 0.0 {
            return vec2<f32>(v, f32(c - 1u));
        }
    }
    return vec2<f32>(1.0, f32(count - 1u));
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x < frame.size.x && id.y < frame.size.y {
        chosen[id.y * frame.size.x + id.x] = 0u;
    }
    var s: Sample;
    if !load_sample(id, &s) {
        return;
    }
    let depth = textureLoad(g_position, id.xy, 0).w;
    let l = to_light(light, s.p);
    let count = u32(csm.count);
    var c = 0u;
    while c + 1u < count && depth > csm.cascades[c].info.z {
        c++;
    }

    // sampling statistics: the texel of the chosen cascade this sample lands in
    let res = u32(csm.res);
    let m0 = to_map(c, s.p);
    if COUNT_SAMPLES && all(m0.xy >= vec2<f32>(0.0)) && all(m0.xy < vec2<f32>(1.0)) {
        let t = vec2<u32>(m0.xy * f32(res));
        atomicAdd(&counts[(c * res + t.y) * res + t.x], 1u);
    }

    let a = resolve(c, s.p, s.n, l);
    var v = a.x;
    var tag = 1u + u32(a.y);
    let d0 = csm.cascades[c].info.y;
    let d1 = csm.cascades[c].info.z;
    let band = csm.blend * (d1 - d0);
    if band > 0.0 && c + 1u < count && depth > d1 - band {
        let t = clamp((depth - (d1 - band)) / band, 0.0, 1.0);
        v = mix(v, resolve(c + 1u, s.p, s.n, l).x, t);
        tag += 16u;
    }
    visibility[s.i] = v;
    chosen[s.i] = tag;
}
