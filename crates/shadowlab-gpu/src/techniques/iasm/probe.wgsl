// GPU texel index of buffer coordinates (tests: compared with iasm.rs `texel_index`).
@group(0) @binding(0) var<uniform> ip: IasmParams;
@group(0) @binding(1) var<storage, read_write> probe: array<vec4<f32>>;

@compute @workgroup_size(64)
fn probe_index(@builtin(global_invocation_id) id: vec3<u32>) {
    let n = arrayLength(&probe);
    if id.x >= n {
        return;
    }
    let uv = probe[id.x].xy;
    probe[id.x].z = bitcast<f32>(buffer_index(uv));
    probe[id.x].w = bitcast<f32>(tile_of(uv));
}
