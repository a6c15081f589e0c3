// sv set-up: the scene's vertex positions copied out for the CPU edge list (edges.rs).

@group(0) @binding(0) var<storage, read_write> positions: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let i = id.x + id.y * groups.x * 64u;
    if i >= arrayLength(&positions) {
        return;
    }
    positions[i] = vec4<f32>(vertices[i].pos, 1.0);
}
