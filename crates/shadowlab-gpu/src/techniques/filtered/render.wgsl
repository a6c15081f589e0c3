// Moments pass: the scene from the light (orthographic or perspective, like `sm`), each
// fragment writing b(z) of its linear light-space depth z in [0, 1] (0 = near the light) into
// the colour target (R32Float depth for sd and ESM, RG32Float VSM, RGBA32Float EVSM/MSM).
// Alpha-tested texels are discarded; a Depth32Float attachment keeps the nearest surface.


@group(0) @binding(0) var<uniform> fp: FilteredParams;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
    @location(1) depth: f32,
    @location(2) @interpolate(flat) material: u32,
}

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> VsOut {
    let v = vertices[vi];
    var o: VsOut;
    o.clip = fp.light_view_proj * vec4<f32>(v.pos, 1.0);
    // orthographic: clip z is linear; perspective: clip w is the view depth
    o.depth = select(o.clip.z, o.clip.w * fp.inv_far, fp.perspective > 0.5);
    o.uv = v.uv;
    o.material = v.material;
    return o;
}

@fragment
fn fs_main(in: VsOut) -> @location(0) vec4<f32> {
    if cut_out(materials[in.material], in.uv) {
        discard;
    }
    let z = clamp(in.depth, 0.0, 1.0);
    if fp.single_depth != 0u {
        return vec4<f32>(z, 0.0, 0.0, 0.0);
    }
    switch fp.kind {
        case 0u: {
            return vsm_encode(z);
        }
        case 1u: {
            return esm_encode(z, fp.esm_c);
        }
        case 2u: {
            return evsm_encode(z, fp.evsm_c_pos, fp.evsm_c_neg);
        }
        default: {
            return msm_encode(z);
        }
    }
}
