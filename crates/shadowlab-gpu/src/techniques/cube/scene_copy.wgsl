// cube-notw: copies the scene's triangles, materials and texels out of its bind group (the
// scene buffers are not copyable), so that each face can draw its own clipped triangles with
// the scene's materials (alpha cut-outs included). `lengths` first, then `copy` over the
// largest of the three arrays.

@group(0) @binding(0) var<storage, read_write> out_len: array<u32, 4>;
@group(0) @binding(1) var<storage, read_write> out_vertices: array<Vertex>;
@group(0) @binding(2) var<storage, read_write> out_materials: array<Material>;
@group(0) @binding(3) var<storage, read_write> out_texels: array<u32>;

@compute @workgroup_size(1)
fn lengths() {
    out_len[0] = arrayLength(&vertices);
    out_len[1] = arrayLength(&materials);
    out_len[2] = arrayLength(&texels);
}

@compute @workgroup_size(64)
fn copy(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let i = (wg.y * 65535u + wg.x) * 64u + li;
    if i < arrayLength(&out_vertices) && i < arrayLength(&vertices) {
        out_vertices[i] = vertices[i];
    }
    if i < arrayLength(&out_materials) && i < arrayLength(&materials) {
        out_materials[i] = materials[i];
    }
    if i < arrayLength(&out_texels) && i < arrayLength(&texels) {
        out_texels[i] = texels[i];
    }
}
