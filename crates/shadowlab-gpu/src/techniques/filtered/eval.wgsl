// Filtered shadow-map evaluation: each sample is offset (normal offset and constant bias in
// world units of one shadow texel), projected into the light, and its linear depth d compared
// with the map through the representation's upper bound. Full variants: the 4 texels around
// the sample are loaded and their (pre-blurred) moments interpolated bilinearly (RGBA32Float
// is not filterable in core WebGPU, so the bilinear filter is done here). Single-depth
// variants: one textureGather of 4 depths, converted and interpolated in moments.wgsl.
// With mips (mode.z = levels > 1) the moments are read trilinearly at the level matching the
// pixel's footprint. Also counts the view samples per texel (sampling statistics).


@group(0) @binding(6) var<uniform> fp: FilteredParams;
// The uniform's `kind`, `single_depth != 0`, `mip_levels > 1` and `perspective`, fixed at
// pipeline creation (eval.rs): lavapipe runs every side of a branch on a value it reads from a
// buffer, so the four representations' tests and the trilinear path cost every variant.
override KIND: u32;
override SINGLE_DEPTH: bool;
override MIPPED: bool;
override PERSPECTIVE: bool;
@group(0) @binding(7) var shadow_map: texture_2d<f32>;
@group(0) @binding(8) var gather_sampler: sampler;
@group(0) @binding(9) var<storage, read_write> counts: array<atomic<u32>>;

fn to_map(p: vec3<f32>) -> vec3<f32> {
    let c = fp.light_view_proj * vec4<f32>(p, 1.0);
    let ndc = c.xyz / c.w;
    let depth = select(c.z, c.w * fp.inv_far, PERSPECTIVE);
    return vec3<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5, depth);
}

fn visibility_of(m: vec4<f32>, d: f32) -> f32 {
    switch KIND {
        case 0u: {
            return vsm_visibility(m, d, fp.min_variance);
        }
        case 1u: {
            return esm_visibility(m, d, fp.esm_c);
        }
        case 2u: {
            return evsm_visibility(m, d, fp.evsm_c_pos, fp.evsm_c_neg, fp.min_variance);
        }
        default: {
            return msm_visibility(m, d, fp.moment_bias);
        }
    }
}

fn visibility_gather(z: vec4<f32>, w: vec4<f32>, d: f32) -> f32 {
    return visibility_gather_of(KIND, z, w, d, vec4<f32>(fp.min_variance, fp.esm_c, fp.evsm_c_pos, fp.evsm_c_neg), fp.moment_bias);
}

// The 2x2 texels around uv on mip `level`, interpolated bilinearly (same texels and weights
// as the single-depth gather on level 0).
fn bilinear_moments(uv: vec2<f32>, level: i32) -> vec4<f32> {
    let r = max(i32(fp.res) >> u32(level), 1);
    let w = gather_weights(uv, f32(r));
    let t0 = vec2<i32>(floor(uv * f32(r) - 0.5));
    let lo = vec2<i32>(0);
    let hi = vec2<i32>(r - 1);
    return w.x * textureLoad(shadow_map, clamp(t0 + vec2<i32>(0, 1), lo, hi), level)
        + w.y * textureLoad(shadow_map, clamp(t0 + vec2<i32>(1, 1), lo, hi), level)
        + w.z * textureLoad(shadow_map, clamp(t0 + vec2<i32>(1, 0), lo, hi), level)
        + w.w * textureLoad(shadow_map, clamp(t0, lo, hi), level);
}

// Map distance (texels of level 0) from m0 to the sample of view pixel j; 1e9 if none.
fn neighbour_distance(j: vec2<i32>, m0: vec2<f32>) -> f32 {
    if any(j < vec2<i32>(0)) || any(j >= vec2<i32>(frame.size)) {
        return 1e9;
    }
    let pn = textureLoad(g_position, j, 0);
    if pn.w <= 0.0 {
        return 1e9;
    }
    return length((to_map(pn.xyz).xy - m0) * fp.res);
}

// Texels of the map covered by one view pixel (no derivatives in compute): per axis the nearer
// of the two neighbours (one-sided at silhouettes), then the larger axis.
fn footprint(id: vec2<i32>, m0: vec2<f32>) -> f32 {
    var fx = min(neighbour_distance(id + vec2<i32>(1, 0), m0), neighbour_distance(id - vec2<i32>(1, 0), m0));
    var fy = min(neighbour_distance(id + vec2<i32>(0, 1), m0), neighbour_distance(id - vec2<i32>(0, 1), m0));
    fx = select(fx, 1.0, fx > 1e8);
    fy = select(fy, 1.0, fy > 1e8);
    return max(fx, fy);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    var s: Sample;
    if !load_sample(id, &s) {
        return;
    }
    let res = fp.res;
    let m0 = to_map(s.p);
    if COUNT_SAMPLES && all(m0.xy >= vec2<f32>(0.0)) && all(m0.xy < vec2<f32>(1.0)) {
        let t = vec2<u32>(m0.xy * res);
        atomicAdd(&counts[t.y * u32(res) + t.x], 1u);
    }
    var texel = fp.texel_world;
    if PERSPECTIVE {
        texel = fp.texel_world * max(dot(s.p - light.position.xyz, light.direction.xyz), 0.0);
    }
    let l = to_light(light, s.p);
    let q = s.p + s.n * (fp.normal_offset * texel) + l * (fp.depth_bias * texel);
    let m = to_map(q);
    if any(m.xy < vec2<f32>(0.0)) || any(m.xy > vec2<f32>(1.0)) || m.z > 1.0 {
        visibility[s.i] = 1.0;
        return;
    }
    let d = max(m.z, 0.0);
    let w = gather_weights(m.xy, res);
    if SINGLE_DEPTH {
        let z = textureGather(0, shadow_map, gather_sampler, m.xy);
        visibility[s.i] = visibility_gather(z, w, d);
        return;
    }
    if MIPPED {
        // trilinear: the level whose texels match the pixel's footprint in the map
        let top = f32(fp.mip_levels - 1u);
        let lod = clamp(log2(max(footprint(vec2<i32>(id.xy), m0.xy), 1.0)), 0.0, top);
        let l0 = floor(lod);
        let mt = mix(bilinear_moments(m.xy, i32(l0)), bilinear_moments(m.xy, i32(min(l0 + 1.0, top))), lod - l0);
        visibility[s.i] = visibility_of(mt, d);
        return;
    }
    visibility[s.i] = visibility_of(bilinear_moments(m.xy, 0), d);
}
