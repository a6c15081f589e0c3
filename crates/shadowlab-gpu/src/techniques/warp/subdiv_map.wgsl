// subdiv.wgsl for one map (its lookup bindings: lookup_bind.wgsl): every triangle is the map's,
// the pyramid (`cull_hidden`) is the map's own, and the finished pieces follow the triangles'
// slots in one indirect draw.

fn enter_triangle(tri: u32) {}

fn hzb_base() -> u32 {
    return 0u;
}

fn finished(p: vec4<u32>) -> vec4<u32> {
    return p;
}

@compute @workgroup_size(1)
fn draw_args() {
    let appended = min(atomicLoad(&counters[0]), EXTRA_CAPACITY);
    // a map without view samples draws nothing (split_root left its slots as they were)
    atomicStore(&counters[4], select(3u * (TRIANGLES + appended), 0u, no_samples()));
    atomicStore(&counters[5], 1u);
    atomicStore(&counters[6], 0u);
    atomicStore(&counters[7], 0u);
}
