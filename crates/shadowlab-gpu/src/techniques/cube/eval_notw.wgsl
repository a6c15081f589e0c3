// cube-notw's faces as the layers of warp::Layers (desired views, count maps, evaluation): a
// view sample belongs to its face (`cube`'s rule, faces.wgsl `cube_face`), each face a spot
// light along its axis.

const LAYERS: u32 = 6u;

fn layer_of(p: vec3<f32>) -> u32 {
    return cube_face(p - light.position.xyz);
}

fn light_axis() -> vec3<f32> {
    return cube_basis(layer)[0];
}
