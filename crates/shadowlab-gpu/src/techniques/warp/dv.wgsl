// The desired view's reduction within a workgroup (analyze.wgsl `dv_reduce` for one map,
// cube/split.wgsl for every cube face): the samples' base map coordinates in fixed point
// (min x, min y, max x, max y), the largest eye distance (RTW) and the sample count, reduced in
// shared memory; the caller's invocation 0 adds them to the map's bounds with one atomic each.
// min, max and add do not depend on the order, so the bounds are the same however the
// samples are grouped.

var<workgroup> wg_bounds: array<atomic<u32>, 6>;

// Every invocation of the workgroup calls it (barriers); `counted`: whether its sample `p`
// belongs to the map of `pw`. Returns the workgroup's six values to invocation 0 (zeros to the
// others).
fn dv_workgroup(t: u32, counted: bool, pw: WarpParams, p: vec3<f32>) -> array<u32, 6> {
    if t == 0u {
        atomicStore(&wg_bounds[0], 0xffffffffu);
        atomicStore(&wg_bounds[1], 0xffffffffu);
        atomicStore(&wg_bounds[2], 0u);
        atomicStore(&wg_bounds[3], 0u);
        atomicStore(&wg_bounds[4], 0u);
        atomicStore(&wg_bounds[5], 0u);
    }
    workgroupBarrier();
    if counted {
        let m = clamp(clip_to_map(base_clip(pw, p)).xy, vec2<f32>(0.0), vec2<f32>(1.0));
        let f = vec2<u32>(min(m * DV_SCALE, vec2<f32>(DV_SCALE)));
        atomicMin(&wg_bounds[0], f.x);
        atomicMin(&wg_bounds[1], f.y);
        atomicMax(&wg_bounds[2], f.x);
        atomicMax(&wg_bounds[3], f.y);
        atomicMax(&wg_bounds[4], bitcast<u32>(distance(p, frame.camera_pos.xyz)));
        atomicAdd(&wg_bounds[5], 1u);
    }
    workgroupBarrier();
    var b: array<u32, 6>;
    if t == 0u {
        for (var k = 0u; k < 6u; k++) {
            b[k] = atomicLoad(&wg_bounds[k]);
        }
    }
    return b;
}
