// NoTW's warps of every layer of a warp::Layers at once (cube-notw's faces, dpsm-notw's
// hemispheres), after their count maps (count_layers.wgsl): each pass of notw.wgsl dispatched
// with the layer as its third dimension, each layer reading its uniform, its slice of the count
// maps and of the scratch, writing its layer of the warps. A layer without view samples keeps
// its warps (nothing evaluates it). The includer defines `const LAYERS: u32`.

// Words between two layers' DV bounds, count maps and scratch.
override DV_STRIDE: u32;
override WORK_STRIDE: u32;
override FWORK_STRIDE: u32;

@group(0) @binding(0) var<uniform> layer_params: array<WarpParams, LAYERS>;
@group(0) @binding(1) var<storage, read> dv: array<u32>;
@group(0) @binding(2) var<storage, read_write> work: array<atomic<u32>>;
@group(0) @binding(3) var<storage, read_write> fwork: array<f32>;
@group(0) @binding(4) var warp_x_out: texture_storage_2d_array<r32float, write>;
@group(0) @binding(5) var warp_y_out: texture_storage_2d_array<r32float, write>;

var<private> wp: WarpParams;
var<private> layer: u32;

fn samples_total() -> u32 {
    return dv[layer * DV_STRIDE + 5u];
}

fn store_warp_x(t: vec2<u32>, o: f32) {
    textureStore(warp_x_out, t, layer, vec4<f32>(o, 0.0, 0.0, 0.0));
}

fn store_warp_y(t: vec2<u32>, o: f32) {
    textureStore(warp_y_out, t, layer, vec4<f32>(o, 0.0, 0.0, 0.0));
}

// Takes layer l (its uniform and slices); false when it has no view samples.
fn enter(l: u32) -> bool {
    if l >= LAYERS {
        return false;
    }
    layer = l;
    wp = layer_params[l];
    wbase = l * WORK_STRIDE;
    fbase = l * FWORK_STRIDE;
    return samples_total() > 0u;
}

@compute @workgroup_size(64)
fn functions_rows(@builtin(global_invocation_id) id: vec3<u32>) {
    if enter(id.z) {
        build_function(0u, id.x);
    }
}

@compute @workgroup_size(8, 8)
fn smooth_rows(@builtin(global_invocation_id) id: vec3<u32>) {
    if enter(id.z) {
        smooth_block(0u, id.x, id.y);
    }
}

@compute @workgroup_size(64)
fn rebuild(@builtin(global_invocation_id) id: vec3<u32>) {
    if enter(id.z) {
        rebuild_row(id.x);
    }
}

@compute @workgroup_size(64)
fn functions_cols(@builtin(global_invocation_id) id: vec3<u32>) {
    if enter(id.z) {
        build_function(1u, id.x);
    }
}

@compute @workgroup_size(8, 8)
fn smooth_cols(@builtin(global_invocation_id) id: vec3<u32>) {
    if enter(id.z) {
        smooth_block(1u, id.x, id.y);
    }
}
