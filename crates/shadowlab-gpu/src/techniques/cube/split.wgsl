// cube-notw: the view samples split by cube face (`split`, one dispatch per face: the face's
// own mask, the samples counted per face), and the six faces' visibility merged back
// (`merge`: each evaluated pixel takes the visibility of its face's warped map).

// x: face index
@group(0) @binding(6) var<uniform> sel: vec4<u32>;
@group(0) @binding(7) var<storage, read_write> face_mask: array<u32>;
@group(0) @binding(8) var<storage, read_write> face_vis: array<f32>;
@group(0) @binding(9) var<storage, read_write> face_samples: array<atomic<u32>>;

fn pixel(id: vec3<u32>) -> i32 {
    if id.x >= frame.size.x || id.y >= frame.size.y {
        return -1;
    }
    return i32(id.y * frame.size.x + id.x);
}

@compute @workgroup_size(8, 8)
fn split(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = pixel(id);
    if i < 0 {
        return;
    }
    var m = 0u;
    if mask[i] != 0u {
        let p = textureLoad(g_position, id.xy, 0).xyz;
        if cube_face(p - light.position.xyz) == sel.x {
            m = 1u;
            atomicAdd(&face_samples[sel.x], 1u);
        }
    }
    face_mask[i] = m;
}

@compute @workgroup_size(8, 8)
fn merge(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = pixel(id);
    if i < 0 {
        return;
    }
    if face_mask[i] != 0u {
        visibility[i] = face_vis[i];
    } else if mask[i] == 0u {
        visibility[i] = 0.0;
    }
}
