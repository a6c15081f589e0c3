// One warped map's evaluation (eval.wgsl's `eval_sample` over the view): the map, its
// comparison sampler and the counts of the analysis variant, bindings 10-12.

@group(0) @binding(10) var shadow_map: texture_depth_2d;
@group(0) @binding(11) var cmp: sampler_comparison;
@group(0) @binding(12) var<storage, read_write> counts: array<atomic<u32>>;

fn map_texel(t: vec2<i32>) -> f32 {
    return textureLoad(shadow_map, t, 0);
}

fn map_compare(uv: vec2<f32>, z: f32) -> f32 {
    return textureSampleCompareLevel(shadow_map, cmp, uv, z);
}

fn count_texel(t: u32) {
    atomicAdd(&counts[t], 1u);
}

// The spot light's axis (a perspective map's texel grows with the depth along it).
fn light_axis() -> vec3<f32> {
    return light.direction.xyz;
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    var s: Sample;
    // a paraboloid map writes only its hemisphere's samples; the other map writes the rest
    if !load_sample(id, &s) || !owns_sample(wp, s.p) {
        return;
    }
    eval_sample(s);
}
