// cube-notw: the view samples split by cube face (one dispatch per face, `sel.x`): the face's
// own mask, which the face's analysis passes read. The faces' desired views and sample counts
// (warp/dv_layers.wgsl) and the evaluation (warp/eval_layers.wgsl) find each sample's face by
// the same rule (eval_notw.wgsl `layer_of`).

// x: face index
@group(0) @binding(6) var<uniform> sel: vec4<u32>;
@group(0) @binding(7) var<storage, read_write> face_mask: array<u32>;

@compute @workgroup_size(8, 8)
fn split(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= frame.size.x || id.y >= frame.size.y {
        return;
    }
    let i = id.y * frame.size.x + id.x;
    var m = 0u;
    if mask[i] != 0u {
        let p = textureLoad(g_position, id.xy, 0).xyz;
        m = select(0u, 1u, cube_face(p - light.position.xyz) == sel.x);
    }
    face_mask[i] = m;
}
