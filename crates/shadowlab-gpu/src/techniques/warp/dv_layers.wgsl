// The desired views of every layer of a warp::Layers in one pass (cube-notw's faces,
// dpsm-notw's hemispheres): each view sample adds to the bounds of the layer that evaluates it
// (`layer_of`, the technique's file, as in eval_layers.wgsl), reduced per workgroup (dv.wgsl),
// then one atomic per value and layer into the layer's slice; the sixth word counts the samples.

const DV_SLOTS: u32 = LAYERS;

// Words between two layers' DV bounds (warp::Layers::dv_stride / 4).
override DV_STRIDE: u32;

@group(0) @binding(6) var<uniform> layer_params: array<WarpParams, LAYERS>;
@group(0) @binding(7) var<storage, read_write> dv: array<atomic<u32>>;

// The layer whose axis `light_axis` gives (not read here).
var<private> layer: u32;

@compute @workgroup_size(8, 8)
fn dv_layers(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) t: u32) {
    var s: Sample;
    let counted = load_sample(id, &s);
    var l = 0u;
    if counted {
        l = layer_of(s.p);
    }
    dv_workgroup(t, l, counted, layer_params[l], s.p);
    if t == 0u {
        for (var k = 0u; k < LAYERS; k++) {
            if dv_slot(k, 5u) == 0u {
                continue;
            }
            let o = k * DV_STRIDE;
            atomicMin(&dv[o], dv_slot(k, 0u));
            atomicMin(&dv[o + 1u], dv_slot(k, 1u));
            atomicMax(&dv[o + 2u], dv_slot(k, 2u));
            atomicMax(&dv[o + 3u], dv_slot(k, 3u));
            atomicMax(&dv[o + 4u], dv_slot(k, 4u));
            atomicAdd(&dv[o + 5u], dv_slot(k, 5u));
        }
    }
}
