// The count maps of every layer of a warp::Layers in one pass (cube-notw's faces, dpsm-notw's
// hemispheres), after their desired views (dv_layers.wgsl): each view sample adds its weight
// (count.wgsl) to the count map of the layer that evaluates it (`layer_of`, the technique's
// file, as in eval_layers.wgsl), inside that layer's DV crop. The sums do not depend on the
// order, so each layer's map is the one its own pass over its samples made.

// Words between two layers' count maps (the uniforms and DV bounds: layer_bind.wgsl).
override WORK_STRIDE: u32;

@group(0) @binding(8) var<storage, read_write> work: array<atomic<u32>>;
// each layer's occluder map (`edge_importance`; a stand-in when off)
@group(0) @binding(9) var occ: texture_depth_2d_array;

fn occ_at(x: u32, y: u32) -> f32 {
    return textureLoad(occ, vec2<u32>(x, y), layer, 0);
}

@compute @workgroup_size(8, 8)
fn count_layers(@builtin(global_invocation_id) id: vec3<u32>) {
    var s: Sample;
    if !load_sample(id, &s) {
        return;
    }
    use_layer(layer_of(s.p));
    let u = map_coords(s.p, dv_rect());
    if !inside(u) {
        return;
    }
    atomicAdd(&work[layer * WORK_STRIDE + count_index(u)], sample_weight(s.p, u));
}
