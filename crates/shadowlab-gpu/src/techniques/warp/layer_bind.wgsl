// A pass over every layer of a warp::Layers (count_layers.wgsl, eval_layers.wgsl,
// subdiv_layers.wgsl): the layers' uniforms and DV bounds (bindings 6-7), and the layer at hand
// (a view sample's, a triangle's). The composing file defines `const LAYERS: u32`.

// Words between two layers' DV bounds (warp::Layers::dv_stride / 4).
override DV_STRIDE: u32;

@group(0) @binding(6) var<uniform> layer_params: array<WarpParams, LAYERS>;
@group(0) @binding(7) var<storage, read> dv_bounds: array<u32>;

// The layer at hand and its uniform.
var<private> layer: u32;
var<private> wp: WarpParams;

fn use_layer(l: u32) {
    layer = l;
    wp = layer_params[l];
}

// Whether the layer is cropped to a desired view that holds no view sample (lookup_bind.wgsl's
// rule, on the layer's bounds).
fn no_samples() -> bool {
    return wp.dv_mode > 0.5 && dv_bounds[layer * DV_STRIDE + 5u] == 0u;
}

fn dv_rect() -> vec4<f32> {
    let b = layer * DV_STRIDE;
    return dv_from_bounds(wp, vec4<u32>(dv_bounds[b], dv_bounds[b + 1u], dv_bounds[b + 2u], dv_bounds[b + 3u]));
}
