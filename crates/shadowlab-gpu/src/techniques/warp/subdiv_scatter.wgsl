// The finished pieces of the layered subdivision (subdiv_layers.wgsl) listed by layer: each
// takes the next entry of its layer's list, from the front or, flat, from the back, writes its
// index there and counts itself into that draw's arguments (draw_args set their starts); the
// lists follow the pieces' slots in their buffer (here as words), so that each layer draws its
// own (depth.wgsl `piece_at`; the order within a list is the append order, which the depth
// test's minimum does not see).

override TRIANGLES: u32;
override EXTRA_CAPACITY: u32;

@group(0) @binding(0) var<storage, read_write> words: array<u32>;
@group(0) @binding(1) var<storage, read_write> counters: array<atomic<u32>>;

@compute @workgroup_size(64)
fn scatter(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) i: u32) {
    let k = (wg.y * 65535u + wg.x) * 64u + i;
    if k >= min(atomicLoad(&counters[0]), EXTRA_CAPACITY) {
        return;
    }
    let piece = TRIANGLES + k;
    let tri = words[4u * piece];
    let l = layer_of_triangle(tri & ~FLAT_MARK);
    let d = DRAWS_AT + l * DRAW_WORDS;
    var entry = atomicLoad(&counters[OFFSET_AT + l]);
    if (tri & FLAT_MARK) != 0u {
        // from the back: the flat draw grows downwards
        entry += atomicLoad(&counters[FINISHED_AT + l]) - 1u - atomicAdd(&counters[d + 8u], 3u) / 3u;
        atomicSub(&counters[d + 10u], 3u);
    } else {
        entry += atomicAdd(&counters[d + 4u], 3u) / 3u;
    }
    words[4u * (TRIANGLES + EXTRA_CAPACITY) + entry] = piece;
}
