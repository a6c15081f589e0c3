// Every layer of a warp::Layers evaluated in one pass (cube-notw's faces, dpsm's hemispheres):
// each view sample takes its layer (`layer_of`), that layer's uniform, DV bounds, warps and map,
// and is evaluated by the warped map's own code (eval.wgsl `eval_sample`, through lookup.wgsl);
// the counts of the analysis variant go to the layer's slice. The technique's file defines
// `const LAYERS: u32`, `fn layer_of(p: vec3<f32>) -> u32` and `fn light_axis() -> vec3<f32>`
// (a perspective layer's axis, read while `layer` is set).

// (The uniforms and DV bounds, bindings 6-7, and the sample's layer: layer_bind.wgsl; the warps,
// bindings 8-9: layer_warps.wgsl.)
@group(0) @binding(10) var shadow_map: texture_depth_2d_array;
@group(0) @binding(11) var cmp: sampler_comparison;
@group(0) @binding(12) var<storage, read_write> counts: array<atomic<u32>>;

fn map_texel(t: vec2<i32>) -> f32 {
    return textureLoad(shadow_map, t, layer, 0);
}

fn map_compare(uv: vec2<f32>, z: f32) -> f32 {
    return textureSampleCompareLevel(shadow_map, cmp, uv, layer, z);
}

fn count_texel(t: u32) {
    let res = u32(wp.res);
    atomicAdd(&counts[layer * res * res + t], 1u);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    var s: Sample;
    if !load_sample(id, &s) {
        return;
    }
    use_layer(layer_of(s.p));
    eval_sample(s);
}
