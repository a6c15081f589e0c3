// The hidden-edge pyramid (params.wgsl `hzb_offset`): level 0 copied from the occluder pass's
// depth (occluders.wgsl), then each level the maximum of 2x2 texels of the one below (past the
// edge of an odd side the last texel repeats). Depth 1 = nothing drawn: hides nothing. The third
// dispatch dimension is the layer of the occluder maps (one map: one), its pyramid HZB_STRIDE
// floats after the previous one's.

override HZB_STRIDE: u32;

struct HzbLevel {
    // x: res (level 0 side), y: the level written (1..; 0: the copy)
    v: vec4<u32>,
}

@group(0) @binding(0) var occ_depth: texture_depth_2d_array;
@group(0) @binding(1) var<storage, read_write> hzb: array<f32>;
@group(0) @binding(2) var<uniform> hl: HzbLevel;

@compute @workgroup_size(8, 8)
fn hzb_base(@builtin(global_invocation_id) id: vec3<u32>) {
    let res = hl.v.x;
    if id.x >= res || id.y >= res {
        return;
    }
    hzb[id.z * HZB_STRIDE + id.y * res + id.x] = textureLoad(occ_depth, vec2<i32>(id.xy), i32(id.z), 0);
}

@compute @workgroup_size(8, 8)
fn hzb_reduce(@builtin(global_invocation_id) id: vec3<u32>) {
    let res = hl.v.x;
    let l = hl.v.y;
    let side = hzb_side(res, l);
    if id.x >= side || id.y >= side {
        return;
    }
    let below = hzb_side(res, l - 1u);
    let src = id.z * HZB_STRIDE + hzb_offset(res, l - 1u);
    let x = min(2u * id.xy, vec2<u32>(below - 1u));
    let y = min(2u * id.xy + 1u, vec2<u32>(below - 1u));
    let m = max(max(hzb[src + x.y * below + x.x], hzb[src + x.y * below + y.x]), max(hzb[src + y.y * below + x.x], hzb[src + y.y * below + y.x]));
    hzb[id.z * HZB_STRIDE + hzb_offset(res, l) + id.y * side + id.x] = m;
}
