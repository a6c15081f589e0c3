// Page marking: every evaluated view sample flags the pages it will read (Clipmap::sample_pages;
// a cube's sample, on its own face's levels only):
// at its level (or the first coarser one whose window holds them) the pages under the corners
// of the square of `reach` texels around it, and the same corners' pages of the coarsest level
// (the fallback of last resort), flag 1; the corners' pages at every level in between, flag 2:
// the candidates the allocation maps when a full pool leaves the finer page out (alloc.rs
// `with_fallbacks`), one level coarser at a time, so that a sample whose fallback page is left
// out too finds the next one instead of walking up to the coarsest level. Flags are set with
// atomicOr (skipped where already set) in bits 0-1; bits 2-31 count the samples whose own
// level's page this is (the page under the sample; alloc.rs `Demand`), with atomicAdd: the
// same flags and counts in any order.

@group(0) @binding(6) var<uniform> vp: VirtualParams;
@group(0) @binding(7) var<storage, read_write> requests: array<atomic<u32>>;

fn mark_level(k: u32, g: vec2<f32>, all_or_none: bool, flag: u32) -> bool {
    let r = vp.view.w;
    var c: array<vec2<i32>, 4>;
    c[0] = page_at(k, g + vec2<f32>(-r, -r));
    c[1] = page_at(k, g + vec2<f32>(r, -r));
    c[2] = page_at(k, g + vec2<f32>(-r, r));
    c[3] = page_at(k, g + vec2<f32>(r, r));
    var inside = true;
    for (var i = 0; i < 4; i++) {
        inside = inside && in_window(k, c[i]);
    }
    if all_or_none && !inside {
        return false;
    }
    for (var i = 0; i < 4; i++) {
        if in_window(k, c[i]) {
            let t = table_index(k, c[i]);
            // most samples of a coarse level share its pages: read before the atomic write
            if (atomicLoad(&requests[t]) & flag) == 0u {
                atomicOr(&requests[t], flag);
            }
        }
    }
    return true;
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    var s: Sample;
    if !load_sample(id, &s) {
        return;
    }
    var k = choose_level(s.p);
    let top = top_level(k);
    let step = faces();
    while k <= top {
        let g = texel_coords(k, s.p);
        if mark_level(k, g, true, 1u) {
            atomicAdd(&requests[table_index(k, page_at(k, g))], 4u);
            for (var j = k + step; j < top; j += step) {
                mark_level(j, texel_coords(j, s.p), false, 2u);
            }
            break;
        }
        k += step;
    }
    if k < top {
        mark_level(top, texel_coords(top, s.p), false, 1u);
    }
}
