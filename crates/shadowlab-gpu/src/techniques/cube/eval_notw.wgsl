// cube-notw's layers in one evaluation (warp/eval_layers.wgsl): a view sample is evaluated by
// its face (the `split` rule), each face a spot light along its axis.

const LAYERS: u32 = 6u;

fn layer_of(p: vec3<f32>) -> u32 {
    return cube_face(p - light.position.xyz);
}

fn light_axis() -> vec3<f32> {
    return cube_basis(layer)[0];
}
