// dpsm's two hemispheres in one evaluation (warp/eval_layers.wgsl): a view sample is evaluated
// by the hemisphere that owns it (the front's side test; the back's is its exact negation, so
// each sample has exactly one, as when each map evaluated its own).

const LAYERS: u32 = 2u;

fn layer_of(p: vec3<f32>) -> u32 {
    return select(1u, 0u, owns_sample(layer_params[0], p));
}

// Paraboloid maps are not perspective (the axis is never read).
fn light_axis() -> vec3<f32> {
    return vec3<f32>(0.0, 0.0, 1.0);
}
