// Min and max of one channel of a float texture over the pixels whose mask word is non-zero
// (e.g. the G-buffer's linear view depth over the evaluated pixels). Each thread folds a
// PER_THREAD x PER_THREAD block of pixels (a workgroup covers 32 x 32), then a workgroup tree
// reduction in shared memory, then two atomics per workgroup on keys that
// order like the floats (`order_key`, order_key.wgsl, prepended). The min is kept as the complement of its key so that
// both words start at 0 (`clear_buffer`) and both reduce with atomicMax.

struct ReduceParams {
    // which channel of `src` (0-3)
    channel: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(0) @binding(0) var<uniform> params: ReduceParams;
@group(0) @binding(1) var src: texture_2d<f32>;
@group(0) @binding(2) var<storage, read> mask: array<u32>;
// [0]: max of ~key (the min), [1]: max of key; 0 and 0 = no pixel
@group(0) @binding(3) var<storage, read_write> result: array<atomic<u32>, 2>;

var<workgroup> lo: array<u32, 64>;
var<workgroup> hi: array<u32, 64>;

const PER_THREAD: u32 = 4u;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let size = textureDimensions(src);
    // neutral elements: ~key = 0 (min) and key = 0 (max)
    var a = 0u;
    var b = 0u;
    for (var dy = 0u; dy < PER_THREAD; dy++) {
        for (var dx = 0u; dx < PER_THREAD; dx++) {
            let p = id.xy * PER_THREAD + vec2<u32>(dx, dy);
            if p.x < size.x && p.y < size.y && mask[p.y * size.x + p.x] != 0u {
                let k = order_key(textureLoad(src, p, 0)[params.channel]);
                a = max(a, ~k);
                b = max(b, k);
            }
        }
    }
    lo[li] = a;
    hi[li] = b;
    workgroupBarrier();
    for (var s = 32u; s > 0u; s = s >> 1u) {
        if li < s {
            lo[li] = max(lo[li], lo[li + s]);
            hi[li] = max(hi[li], hi[li + s]);
        }
        workgroupBarrier();
    }
    if li == 0u && hi[0] != 0u {
        atomicMax(&result[0], lo[0]);
        atomicMax(&result[1], hi[0]);
    }
}
