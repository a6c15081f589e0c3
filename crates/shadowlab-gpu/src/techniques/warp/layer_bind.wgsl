// A pass over the view for every layer of a warp::Layers (count_layers.wgsl, eval_layers.wgsl):
// the layers' uniforms and DV bounds (bindings 6-7), and the layer of the sample at hand. The
// technique's file defines `const LAYERS: u32` and `fn layer_of(p: vec3<f32>) -> u32`.

// Words between two layers' DV bounds (warp::Layers::dv_stride / 4).
override DV_STRIDE: u32;

@group(0) @binding(6) var<uniform> layer_params: array<WarpParams, LAYERS>;
@group(0) @binding(7) var<storage, read> dv_bounds: array<u32>;

// The sample's layer and its uniform.
var<private> layer: u32;
var<private> wp: WarpParams;

// Takes the layer that evaluates the sample at p.
fn enter_layer(p: vec3<f32>) {
    layer = layer_of(p);
    wp = layer_params[layer];
}

fn dv_rect() -> vec4<f32> {
    let b = layer * DV_STRIDE;
    return dv_from_bounds(wp, vec4<u32>(dv_bounds[b], dv_bounds[b + 1u], dv_bounds[b + 2u], dv_bounds[b + 3u]));
}
