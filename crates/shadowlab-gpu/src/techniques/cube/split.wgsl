// cube-notw: the view samples split by cube face (one dispatch per face, `sel.x`): the face's
// own mask, and the face's desired view reduced from its samples (warp/dv.wgsl) into its slice
// of the layers' DV bounds, whose sixth word counts the samples. The evaluation
// (eval_notw.wgsl) finds each sample's face by the same rule.

// Words between two faces' DV bounds (warp::Layers::dv_stride / 4).
override DV_STRIDE: u32;

// x: face index
@group(0) @binding(6) var<uniform> sel: vec4<u32>;
@group(0) @binding(7) var<storage, read_write> face_mask: array<u32>;
@group(0) @binding(8) var<storage, read_write> dv: array<atomic<u32>>;
@group(0) @binding(9) var<uniform> faces: array<WarpParams, 6>;

@compute @workgroup_size(8, 8)
fn split(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) t: u32) {
    let f = sel.x;
    let inside = id.x < frame.size.x && id.y < frame.size.y;
    let i = id.y * frame.size.x + id.x;
    var mine = false;
    var p = vec3<f32>(0.0);
    if inside && mask[i] != 0u {
        p = textureLoad(g_position, id.xy, 0).xyz;
        mine = cube_face(p - light.position.xyz) == f;
    }
    if inside {
        face_mask[i] = select(0u, 1u, mine);
    }
    // every invocation takes part in the workgroup's reduction (barriers)
    let b = dv_workgroup(t, mine, faces[f], p);
    if t == 0u {
        let o = f * DV_STRIDE;
        atomicMin(&dv[o], b[0]);
        atomicMin(&dv[o + 1u], b[1]);
        atomicMax(&dv[o + 2u], b[2]);
        atomicMax(&dv[o + 3u], b[3]);
        atomicMax(&dv[o + 4u], b[4]);
        atomicAdd(&dv[o + 5u], b[5]);
    }
}
