// IASM evaluation, store=buffer (the thesis's linear buffer): the depth at the lookup's texel.
// The pass itself is eval_main.wgsl.

@group(0) @binding(6) var<uniform> ip: IasmParams;
@group(0) @binding(7) var<storage, read> shadow: array<u32>;
@group(0) @binding(8) var<storage, read_write> counts: array<atomic<u32>>;

fn stored_depth(l: Lookup) -> f32 {
    return 1.0 - bitcast<f32>(shadow[buffer_index(l.uv)]);
}
