// The desired view's reduction within a workgroup (analyze.wgsl `dv_reduce` for one map,
// dv_layers.wgsl for every layer of a warp::Layers): per map slot, the samples' base map
// coordinates in fixed point (min x, min y, max x, max y), the largest eye distance (RTW) and the
// sample count, reduced in shared memory; the caller's invocation 0 adds them to the maps'
// bounds with one atomic each. min, max and add do not depend on the order, so the bounds are
// the same however the samples are grouped. The includer defines `const DV_SLOTS: u32`.

var<workgroup> wg_bounds: array<atomic<u32>, 6 * DV_SLOTS>;

// Every invocation of the workgroup calls it (barriers); `counted`: whether its sample `p`
// belongs to the map of slot `slot`, whose uniform is `pw`. Afterwards `dv_slot` reads the
// workgroup's values.
fn dv_workgroup(t: u32, slot: u32, counted: bool, pw: WarpParams, p: vec3<f32>) {
    if t < DV_SLOTS {
        atomicStore(&wg_bounds[6u * t], 0xffffffffu);
        atomicStore(&wg_bounds[6u * t + 1u], 0xffffffffu);
        atomicStore(&wg_bounds[6u * t + 2u], 0u);
        atomicStore(&wg_bounds[6u * t + 3u], 0u);
        atomicStore(&wg_bounds[6u * t + 4u], 0u);
        atomicStore(&wg_bounds[6u * t + 5u], 0u);
    }
    workgroupBarrier();
    if counted {
        let m = clamp(clip_to_map(base_clip(pw, p)).xy, vec2<f32>(0.0), vec2<f32>(1.0));
        let f = vec2<u32>(min(m * DV_SCALE, vec2<f32>(DV_SCALE)));
        let o = 6u * slot;
        atomicMin(&wg_bounds[o], f.x);
        atomicMin(&wg_bounds[o + 1u], f.y);
        atomicMax(&wg_bounds[o + 2u], f.x);
        atomicMax(&wg_bounds[o + 3u], f.y);
        atomicMax(&wg_bounds[o + 4u], bitcast<u32>(distance(p, frame.camera_pos.xyz)));
        atomicAdd(&wg_bounds[o + 5u], 1u);
    }
    workgroupBarrier();
}

// Value k of slot `slot` (after `dv_workgroup`).
fn dv_slot(slot: u32, k: u32) -> u32 {
    return atomicLoad(&wg_bounds[6u * slot + k]);
}
