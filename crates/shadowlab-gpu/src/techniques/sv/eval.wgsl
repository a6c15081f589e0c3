// sv evaluation: visibility = the lit flag of the stencil resolve (1: no volume contains the
// sample, 0: shadowed).

@group(0) @binding(6) var lit: texture_2d<f32>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    var s: Sample;
    if !load_sample(id, &s) {
        return;
    }
    visibility[s.i] = textureLoad(lit, id.xy, 0).r;
}
