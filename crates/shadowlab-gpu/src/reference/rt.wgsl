// `rt`: exact hard-shadow visibility for every evaluated G-buffer sample, one shadow ray per
// pixel through `trace.wgsl`.

@group(0) @binding(6) var<storage, read_write> rays: atomic<u32>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    var s: Sample;
    if !load_sample(id, &s) {
        return;
    }
    atomicAdd(&rays, 1u);
    visibility[s.i] = select(1.0, 0.0, sample_shadowed(s.p, s.n));
}
