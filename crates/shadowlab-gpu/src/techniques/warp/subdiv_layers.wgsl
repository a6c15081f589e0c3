// subdiv.wgsl over every layer of a warp::Layers at once (cube-notw's faces): the layers'
// triangles are one scene (triangle_layer.wgsl), each piece is tested with its layer's uniform,
// DV bounds, warps (layer_bind.wgsl, layer_warps.wgsl) and pyramid, and the finished pieces are
// counted per layer and, with FLAT_SPLIT, marked flat where the interpolated depth is within
// `exact_tol` (params.wgsl `flat_piece`). draw_args then gives each layer its draws (its
// triangles' own slots; its finished pieces, listed by subdiv_scatter.wgsl: the others, then
// the flat ones, drawn without the exact-depth fragment stage) and the scatter its groups.

// Floats between two layers' pyramids (`cull_hidden`; warp::Layers::hzb_stride / 4).
override HZB_STRIDE: u32;
// Exact depth with `exact_tol` (planar layers): flat pieces are listed apart.
override FLAT_SPLIT: bool;

fn enter_triangle(tri: u32) {
    use_layer(layer_of_triangle(tri));
}

fn hzb_base() -> u32 {
    return layer * HZB_STRIDE;
}

fn finished(p: vec4<u32>) -> vec4<u32> {
    atomicAdd(&counters[FINISHED_AT + layer], 1u);
    if FLAT_SPLIT && !PARABOLOID {
        let pc = array<vec4<f32>, 3>(base_clip(wp, corner_pos(p.x, p.y)), base_clip(wp, corner_pos(p.x, p.z)), base_clip(wp, corner_pos(p.x, p.w)));
        if flat_piece(wp, pc) {
            return vec4<u32>(p.x | FLAT_MARK, p.yzw);
        }
    }
    return p;
}

@compute @workgroup_size(1)
fn draw_args() {
    var offset = 0u;
    for (var l = 0u; l < LAYERS; l++) {
        use_layer(l);
        let d = DRAWS_AT + l * DRAW_WORDS;
        let n = atomicLoad(&counters[FINISHED_AT + l]);
        // a layer without view samples draws nothing (split_root left its slots as they were)
        let r = layer_range(l);
        atomicStore(&counters[d], select(3u * (r.y - r.x), 0u, no_samples()));
        atomicStore(&counters[d + 1u], 1u);
        atomicStore(&counters[d + 2u], 3u * r.x);
        atomicStore(&counters[d + 3u], 0u);
        // the list's entries come after every piece's slot (depth.wgsl `piece_at`); the
        // scatter counts them in, the flat ones from the list's end back
        let list = TRIANGLES + EXTRA_CAPACITY + offset;
        atomicStore(&counters[d + 4u], 0u);
        atomicStore(&counters[d + 5u], 1u);
        atomicStore(&counters[d + 6u], 3u * list);
        atomicStore(&counters[d + 7u], 0u);
        atomicStore(&counters[d + 8u], 0u);
        atomicStore(&counters[d + 9u], 1u);
        atomicStore(&counters[d + 10u], 3u * (list + n));
        atomicStore(&counters[d + 11u], 0u);
        atomicStore(&counters[OFFSET_AT + l], offset);
        offset += n;
    }
    let groups = (min(atomicLoad(&counters[0]), EXTRA_CAPACITY) + 63u) / 64u;
    atomicStore(&counters[SCATTER_ARGS_AT], min(groups, 65535u));
    atomicStore(&counters[SCATTER_ARGS_AT + 1u], (groups + 65534u) / 65535u);
    atomicStore(&counters[SCATTER_ARGS_AT + 2u], 1u);
}
