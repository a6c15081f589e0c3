// The layered subdivision's scene (subdiv_layers.wgsl, subdiv_scatter.wgsl): every layer's
// triangles one after another, layer l's below LAYER_END[l], and its words of the counters
// after subdiv.wgsl's 1048: per layer the pieces it finished and the offset of its list, the
// scatter's dispatch, then per layer its three indirect draws' arguments (DRAW_WORDS: its
// triangles' own slots; its list's finished pieces from the front; its flat ones, `exact_tol`,
// from the back). The lists follow the pieces' slots in the pieces' buffer, a word an entry
// (depth.wgsl `piece_at`). The composing source defines `const LAYERS: u32` and
// `const LAYER_END: array<u32, LAYERS>`.

const FINISHED_AT: u32 = 1048u;
const OFFSET_AT: u32 = FINISHED_AT + LAYERS;
const SCATTER_ARGS_AT: u32 = OFFSET_AT + LAYERS;
const DRAWS_AT: u32 = SCATTER_ARGS_AT + 3u;
// three draw_indirect's 4 words
const DRAW_WORDS: u32 = 12u;
// a finished piece's mark (above the triangle's bits): flat, drawn without exact depth
const FLAT_MARK: u32 = 0x80000000u;

fn layer_of_triangle(tri: u32) -> u32 {
    let ends = LAYER_END;
    var l = 0u;
    for (var k = 0u; k + 1u < LAYERS; k++) {
        l += select(0u, 1u, tri >= ends[k]);
    }
    return l;
}

// Layer l's triangles: [start, end).
fn layer_range(l: u32) -> vec2<u32> {
    let ends = LAYER_END;
    return vec2<u32>(select(0u, ends[max(l, 1u) - 1u], l > 0u), ends[l]);
}
