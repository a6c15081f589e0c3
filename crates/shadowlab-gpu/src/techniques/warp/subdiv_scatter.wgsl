// The finished pieces of the layered subdivision (subdiv_layers.wgsl) listed by layer: each
// takes the next entry of its layer's list, whose offset draw_args set, and writes its index
// there; the lists follow the pieces' slots in their buffer (here as words), so that each layer
// draws its own (depth.wgsl `piece_at`; the order within a list is the append order, which the
// depth test's minimum does not see).

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
    let l = layer_of_triangle(words[4u * piece]);
    let slot = atomicLoad(&counters[OFFSET_AT + l]) + atomicAdd(&counters[CURSOR_AT + l], 1u);
    words[4u * (TRIANGLES + EXTRA_CAPACITY) + slot] = piece;
}
