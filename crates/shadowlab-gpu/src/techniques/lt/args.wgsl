// Leak tracing: the ray list's count (list[0]) as indirect dispatch arguments for trace.wgsl,
// 64-thread groups, rows of at most 65535 groups (WebGPU's per-dimension limit).

struct TraceParams {
    // x: mask bits per pixel, y: list capacity (pixels), z, w: unused
    cfg: vec4<u32>,
}

const TRACE_GROUP: u32 = 64u;
const MAX_GROUPS: u32 = 65535u;

@group(0) @binding(0) var<uniform> tp: TraceParams;
@group(0) @binding(1) var<storage, read> list: array<u32>;
@group(0) @binding(2) var<storage, read_write> args: array<u32>;

@compute @workgroup_size(1)
fn main() {
    let groups = (min(list[0], tp.cfg.y) + TRACE_GROUP - 1u) / TRACE_GROUP;
    args[0] = min(groups, MAX_GROUPS);
    args[1] = (groups + MAX_GROUPS - 1u) / MAX_GROUPS;
    args[2] = 1u;
}
