// mdsm selection pass: for every texel of the base depth map, the n depths of the n-SM from its
// sqrt(q) x sqrt(q) search region (clamped at the border), sorted Z1 >= ... >= Zn into one
// RGBA32F texel; the unused channels repeat Zn. Mirrors shadowlab_core::mdsm::select exactly
// (only sample values are stored, so CPU and GPU agree bit for bit; tests/mdsm.rs checks it).

struct MdsmParams {
    light_view_proj: mat4x4<f32>,
    // world size of one texel (orthographic) or per unit of light-view depth (perspective),
    // 1 if perspective, resolution, PCF grid width sqrt(k) (sm's bias.wgsl reads it whole)
    texel: vec4<f32>,
    // constant bias, slope-scaled bias, normal offset (all in texels), max slope (sm's bias.wgsl)
    bias: vec4<f32>,
    // depths per texel
    n: u32,
    // search width sqrt(q) (1 when n = 1)
    region: u32,
    // SELECT_MINMAX or SELECT_SORT
    select: u32,
    // 1 if the slope bias covers the search region
    region_bias: u32,
}

// Largest search region (SEARCH_SIZES in shadowlab_core::mdsm): 9x9.
const MAX_Q: u32 = 81u;
const SELECT_MINMAX: u32 = 0u;
const BIG: f32 = 3.0e38;

@group(0) @binding(0) var<uniform> md: MdsmParams;
@group(0) @binding(1) var base_map: texture_depth_2d;
@group(0) @binding(2) var nsm: texture_storage_2d<rgba32float, write>;

var<private> s: array<f32, MAX_Q>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let res = u32(md.texel.z);
    if id.x >= res || id.y >= res {
        return;
    }
    let w = i32(md.region);
    let r = (w - 1) / 2;
    let q = u32(w * w);
    var j = 0u;
    for (var dy = -r; dy <= r; dy++) {
        for (var dx = -r; dx <= r; dx++) {
            let c = clamp(vec2<i32>(id.xy) + vec2<i32>(dx, dy), vec2<i32>(0), vec2<i32>(i32(res) - 1));
            s[j] = textureLoad(base_map, c, 0);
            j++;
        }
    }
    let n = md.n;
    let b = s[q / 2u];
    var z = array<f32, 4>(b, b, b, b);
    if n > 1u {
        if md.select == SELECT_MINMAX {
            // O(q): the two smallest and the two largest, with multiplicity
            var lo = BIG;
            var lo2 = BIG;
            var hi = -BIG;
            var hi2 = -BIG;
            for (var i = 0u; i < q; i++) {
                let v = s[i];
                if v < lo {
                    lo2 = lo;
                    lo = v;
                } else if v < lo2 {
                    lo2 = v;
                }
                if v > hi {
                    hi2 = hi;
                    hi = v;
                } else if v > hi2 {
                    hi2 = v;
                }
            }
            let max_farther = hi - b > b - lo;
            if n == 2u {
                z[1] = select(lo, hi, max_farther);
            } else {
                z[1] = lo;
                z[2] = hi;
                if n == 4u {
                    z[3] = select(lo2, hi2, max_farther);
                }
            }
        } else {
            // sort descending (insertion sort: q <= 81), n groups of equal count; the base
            // depth's group (middle of its run of equal values) keeps the base depth, the others
            // give their (lower) median
            for (var i = 1u; i < q; i++) {
                let v = s[i];
                var k = i;
                while k > 0u && s[k - 1u] < v {
                    s[k] = s[k - 1u];
                    k--;
                }
                s[k] = v;
            }
            var first = q;
            var last = 0u;
            for (var i = 0u; i < q; i++) {
                if s[i] == b {
                    first = min(first, i);
                    last = i;
                }
            }
            let rank = (first + last) / 2u;
            var m = 1u;
            for (var g = 0u; g < n; g++) {
                let lo = g * q / n;
                let hi = (g + 1u) * q / n;
                if rank < lo || rank >= hi {
                    z[m] = s[(lo + hi - 1u) / 2u];
                    m++;
                }
            }
        }
        // sort the n depths descending
        for (var i = 1u; i < n; i++) {
            let v = z[i];
            var k = i;
            while k > 0u && z[k - 1u] < v {
                z[k] = z[k - 1u];
                k--;
            }
            z[k] = v;
        }
        for (var i = n; i < 4u; i++) {
            z[i] = z[n - 1u];
        }
    }
    textureStore(nsm, vec2<i32>(id.xy), vec4<f32>(z[0], z[1], z[2], z[3]));
}
