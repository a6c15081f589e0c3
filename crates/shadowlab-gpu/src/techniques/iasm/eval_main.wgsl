// IASM evaluation (thesis 3.6), shared by both stores: the offset sample's tile and texel
// (equations 3.2-3.5, `lookup` in params.wgsl); lit when its depth in the tile's frustum is not
// beyond the stored one (`stored_depth`, from eval.wgsl or eval_atlas.wgsl). Samples outside
// the square or in an empty tile are lit. Counts view samples per buffer texel for the sampling
// statistics.

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    var s: Sample;
    if !load_sample(id, &s) {
        return;
    }
    let l = lookup(s.p, s.n);
    if !l.ok {
        visibility[s.i] = 1.0;
        return;
    }
    if COUNT_SAMPLES && inside(l.uv0) && tile_res(tile_of(l.uv0)) > 0u {
        atomicAdd(&counts[buffer_index(l.uv0)], 1u);
    }
    let stored = stored_depth(l);
    // a cleared texel (1: nothing between the tile's planes) is lit even for a receiver beyond
    // the far plane (delayed planes of a moving camera)
    visibility[s.i] = select(0.0, 1.0, l.z <= stored || stored >= 1.0);
}
