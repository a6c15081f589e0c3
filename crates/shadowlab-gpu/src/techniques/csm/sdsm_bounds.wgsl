// SDSM's sample reduction (Lauritzen et al. 2011): after the [min, max] view depth reduction
// (reduce.wgsl, its result bound as `depth_mm`), split that range logarithmically (the same
// formula as shadowlab_core::techniques::sdsm::sample_splits), put each evaluated G-buffer
// sample into the cascade the evaluation will pick for it (first cascade whose far split holds
// its depth, else the last), and reduce per cascade the min/max of its light-view x, y, z and
// the sample count. Min/max use order keys (order_key.wgsl, prepended): the min kept as the
// complement of its key so that every word starts at 0 and reduces with atomicMax;
// deterministic. Per thread first, then per workgroup in shared memory, then one global
// atomic per word.
//
// `out` layout (u32 words): [0] ~key(min depth), [1] key(max depth) (copied from `depth_mm`),
// [2] cascades in use, [3] 0, [4 + i] bits of split i (i <= count), then per cascade c at
// 16 + 8c: ~key(min x), ~key(min y), ~key(min z), key(max x), key(max y), key(max z),
// samples, 0. The CPU uses the splits as written here, so the evaluation's choice of cascade
// and the reduction's agree to the bit.

struct SdsmReduce {
    light_view: mat4x4<f32>,
    // the camera's near and far view depth
    near: f32,
    far: f32,
    // cascades in use
    count: f32,
    // practical split blend (1 = logarithmic)
    lambda: f32,
    // steps per doubling of the range's ends (csm's DEPTH_STEPS_PER_OCTAVE)
    steps: f32,
    pad0: f32,
    pad1: f32,
    pad2: f32,
}

@group(0) @binding(0) var<uniform> u: SdsmReduce;
// G-buffer position: xyz world, w linear view depth
@group(0) @binding(1) var src: texture_2d<f32>;
@group(0) @binding(2) var<storage, read> mask: array<u32>;
@group(0) @binding(3) var<storage, read> depth_mm: array<u32, 2>;
@group(0) @binding(4) var<storage, read_write> out: array<atomic<u32>, 80>;

// 8 cascades x 8 words, zero-initialised
var<workgroup> acc: array<atomic<u32>, 64>;

const PER_THREAD: u32 = 4u;
const HEADER: u32 = 16u;

fn finite(x: f32) -> bool {
    return x == x && abs(x) <= 3.4e38;
}

// csm's depth_range: the samples' range intersected with the camera's, ends rounded outwards
fn depth_range() -> vec2<f32> {
    var r = vec2<f32>(u.near, u.far);
    if depth_mm[1] == 0u {
        return r;
    }
    let lo = from_order_key(~depth_mm[0]);
    let hi = from_order_key(depth_mm[1]);
    if !(finite(lo) && finite(hi) && lo <= hi && hi > 0.0) {
        return r;
    }
    let k = u.steps;
    var a = u.near;
    if lo > 0.0 {
        a = min(exp2(floor(log2(lo) * k) / k), lo);
    }
    a = max(a, u.near);
    var b = max(exp2(ceil(log2(hi) * k) / k), hi);
    b = max(min(b, u.far), a * 1.0001);
    return vec2<f32>(a, b);
}

// split i of n over [lo, hi] (Zhang et al.'s practical scheme; lambda 1 = logarithmic)
fn split(i: u32, n: u32, r: vec2<f32>) -> f32 {
    if i == 0u {
        return r.x;
    }
    if i == n {
        return r.y;
    }
    let t = f32(i) / f32(n);
    var lg = 0.0;
    if u.lambda > 0.0 && r.x > 0.0 {
        lg = r.x * pow(r.y / r.x, t);
    }
    let uni = r.x + (r.y - r.x) * t;
    return u.lambda * lg + (1.0 - u.lambda) * uni;
}

// one thread's run of samples of cascade c into the workgroup's words
fn flush(c: u32, lo: vec3<u32>, hi: vec3<u32>, cnt: u32) {
    if cnt == 0u {
        return;
    }
    let w = c * 8u;
    atomicMax(&acc[w], lo.x);
    atomicMax(&acc[w + 1u], lo.y);
    atomicMax(&acc[w + 2u], lo.z);
    atomicMax(&acc[w + 3u], hi.x);
    atomicMax(&acc[w + 4u], hi.y);
    atomicMax(&acc[w + 5u], hi.z);
    atomicAdd(&acc[w + 6u], cnt);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let n = u32(u.count);
    let r = depth_range();
    var splits: array<f32, 9>;
    for (var i = 0u; i <= n; i++) {
        splits[i] = split(i, n, r);
    }
    if id.x == 0u && id.y == 0u {
        atomicStore(&out[0], depth_mm[0]);
        atomicStore(&out[1], depth_mm[1]);
        atomicStore(&out[2], n);
        for (var i = 0u; i <= n; i++) {
            atomicStore(&out[4u + i], bitcast<u32>(splits[i]));
        }
    }
    // per thread first, over runs of samples in the same cascade (neighbours mostly are; no
    // dynamically indexed per-thread arrays), then per workgroup in shared memory
    var cur = 0u;
    var lo = vec3<u32>(0u);
    var hi = vec3<u32>(0u);
    var cnt = 0u;
    let size = textureDimensions(src);
    for (var dy = 0u; dy < PER_THREAD; dy++) {
        for (var dx = 0u; dx < PER_THREAD; dx++) {
            let p = id.xy * PER_THREAD + vec2<u32>(dx, dy);
            if p.x < size.x && p.y < size.y && mask[p.y * size.x + p.x] != 0u {
                let s = textureLoad(src, p, 0);
                // the evaluation's rule (csm/eval.wgsl): first cascade whose far split holds it
                var c = 0u;
                while c + 1u < n && s.w > splits[c + 1u] {
                    c++;
                }
                if c != cur {
                    flush(cur, lo, hi, cnt);
                    cur = c;
                    lo = vec3<u32>(0u);
                    hi = vec3<u32>(0u);
                    cnt = 0u;
                }
                let q = (u.light_view * vec4<f32>(s.xyz, 1.0)).xyz;
                let k = vec3<u32>(order_key(q.x), order_key(q.y), order_key(q.z));
                lo = max(lo, ~k);
                hi = max(hi, k);
                cnt += 1u;
            }
        }
    }
    flush(cur, lo, hi, cnt);
    workgroupBarrier();
    let v = atomicLoad(&acc[li]);
    if v != 0u {
        if li % 8u == 6u {
            atomicAdd(&out[HEADER + li], v);
        } else {
            atomicMax(&out[HEADER + li], v);
        }
    }
}
