// Evaluation through the page table: the sample's level (choose_level), the `sm` bias family
// in texels of that level (a spot's texel at the sample's light depth), then each of the NxN PCF taps looked up through the page table
// (a tap across a page border reads the neighbouring page: no guard band needed) and compared
// with its atlas texel (lit where depth <= stored, as the comparison sampler of `sm`). Where a
// tap's page is not mapped (fallen back) the whole kernel moves to the next coarser level
// (of the sample's face, for a cube).
// No mapped level: lit (the allocation counts those pages; the report says so). With
// COUNT_SAMPLES the samples are counted per level used (lab only).

@group(0) @binding(6) var<uniform> vp: VirtualParams;
@group(0) @binding(7) var<storage, read> page_table: array<u32>;
@group(0) @binding(8) var atlas: texture_depth_2d;
@group(0) @binding(9) var<storage, read_write> counts: array<atomic<u32>>;

// Visibility of p from level k, or -1 where a tap's page is not mapped at k.
fn lookup(k: u32, p: vec3<f32>, n: vec3<f32>, l: vec3<f32>) -> f32 {
    let kw = i32(vp.pcf.x);
    let half = f32(kw - 1) * 0.5;
    let q = biased_point(p, n, l, texel_world(k, p), vp.bias, half);
    let g = texel_coords(k, q);
    let z = light_depth(k, q);
    if z > 1.0 {
        return 1.0;
    }
    let pr = i32(vp.dims.z);
    let cols = i32(vp.dims.w);
    // a spot map clamps taps to its edge (sm's clamp-to-edge sampler)
    let edge = select(vec2<i32>(i32(0x7fffffff)), vec2<i32>(side(k) * pr - 1), is_spot());
    let lo = select(vec2<i32>(i32(-0x7fffffff)), vec2<i32>(0), is_spot());
    var lit = 0.0;
    for (var y = 0; y < kw; y++) {
        for (var x = 0; x < kw; x++) {
            let tap = clamp(vec2<i32>(floor(g + vec2<f32>(f32(x), f32(y)) - half)), lo, edge);
            let pg = vec2<i32>(floor(vec2<f32>(tap) * (1.0 / f32(pr))));
            if !in_window(k, pg) {
                return -1.0;
            }
            let e = page_table[table_index(k, pg)];
            if e == 0u {
                return -1.0;
            }
            let slot = i32(e - 1u);
            let texel = vec2<i32>(slot % cols, slot / cols) * pr + (tap - pg * pr);
            let d = textureLoad(atlas, texel, 0);
            lit += select(0.0, 1.0, z <= d);
        }
    }
    return lit / f32(kw * kw);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    var s: Sample;
    if !load_sample(id, &s) {
        return;
    }
    let l = to_light(light, s.p);
    var v = 1.0;
    // counts: per mip; the last entry (24) for samples without a mapped level
    var used = 24u;
    let k0 = choose_level(s.p);
    let top = top_level(k0);
    for (var k = k0; k <= top; k += faces()) {
        let r = lookup(k, s.p, s.n, l);
        if r >= 0.0 {
            v = r;
            used = mip_of(k);
            break;
        }
    }
    if COUNT_SAMPLES {
        atomicAdd(&counts[used], 1u);
    }
    visibility[s.i] = v;
}
