// Scene analysis (thesis 3.3 and the deferred near/far planes of 3.5): every evaluated view
// sample adds its importance p = 1 + m clamp(1 - w/k, 0, 1) (equation 3.1, w = clip w = view
// depth) to its tile in 1/64 fixed point, and the tile's min/max light depth is updated with
// atomic min/max on order-preserving u32 keys. A workgroup first reduces into shared memory,
// then one thread per tile adds to the global stats (64-bit sum: low word + carry).
// Stats per tile (8 u32): imp_lo, imp_hi, samples, depth_min key, depth_max key, 3 unused.

@group(0) @binding(6) var<uniform> ip: IasmParams;
@group(0) @binding(7) var<storage, read_write> stats: array<atomic<u32>>;
@group(0) @binding(8) var<storage, read_write> camera: array<vec4<f32>, 5>;

const FIXED: f32 = 64.0;

var<workgroup> wg_imp: array<atomic<u32>, 16>;
var<workgroup> wg_cnt: array<atomic<u32>, 16>;
var<workgroup> wg_min: array<atomic<u32>, 16>;
var<workgroup> wg_max: array<atomic<u32>, 16>;

// Order-preserving key of a float (total order of finite values).
fn key(f: f32) -> u32 {
    let b = bitcast<u32>(f);
    if (b & 0x80000000u) != 0u {
        return ~b;
    }
    return b | 0x80000000u;
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    if li < 16u {
        atomicStore(&wg_imp[li], 0u);
        atomicStore(&wg_cnt[li], 0u);
        atomicStore(&wg_min[li], 0xffffffffu);
        atomicStore(&wg_max[li], 0u);
    }
    workgroupBarrier();
    if id.x < frame.size.x && id.y < frame.size.y {
        let i = id.y * frame.size.x + id.x;
        if mask[i] != 0u {
            let p = textureLoad(g_position, id.xy, 0).xyz;
            let uv = buffer_uv(ip, p);
            if inside(uv) {
                let t = tile_of(uv);
                let w = (frame.view_proj * vec4<f32>(p, 1.0)).w;
                let imp = 1.0 + ip.imp.x * clamp(1.0 - w / ip.imp.y, 0.0, 1.0);
                atomicAdd(&wg_imp[t], u32(round(imp * FIXED)));
                atomicAdd(&wg_cnt[t], 1u);
                let k = key(dot(p, ip.dir.xyz));
                atomicMin(&wg_min[t], k);
                atomicMax(&wg_max[t], k);
            }
        }
    }
    workgroupBarrier();
    if li < 16u {
        let c = atomicLoad(&wg_cnt[li]);
        if c > 0u {
            let b = li * 8u;
            let v = atomicLoad(&wg_imp[li]);
            let old = atomicAdd(&stats[b], v);
            if old + v < old {
                atomicAdd(&stats[b + 1u], 1u);
            }
            atomicAdd(&stats[b + 2u], c);
            atomicMin(&stats[b + 3u], atomicLoad(&wg_min[li]));
            atomicMax(&stats[b + 4u], atomicLoad(&wg_max[li]));
        }
    }
}

// Copies the camera of this view (the lab hands techniques the frame uniform only): view_proj
// columns, then camera_pos.
@compute @workgroup_size(1)
fn copy_camera() {
    for (var c = 0; c < 4; c++) {
        camera[c] = frame.view_proj[c];
    }
    camera[4] = frame.camera_pos;
}
