// Leak tracing, the ray list (composed after reference/trace.wgsl; args.wgsl has sized the
// indirect dispatch): one shadow ray per listed pixel with the same BVH traversal as `rt` (`sample_shadowed`), writes its visibility and sets
// RS in this frame's temporal mask. Cost grows with the listed pixels, not with the screen.

struct TraceParams {
    // x: mask bits per pixel, y: list capacity (pixels), z, w: unused
    cfg: vec4<u32>,
}

const TRACE_GROUP: u32 = 64u;

@group(0) @binding(6) var<uniform> tp: TraceParams;
@group(0) @binding(7) var<storage, read> list: array<u32>;
@group(0) @binding(8) var<storage, read_write> cur_mask: array<atomic<u32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let k = gid.y * groups.x * TRACE_GROUP + gid.x;
    if k >= min(list[0], tp.cfg.y) {
        return;
    }
    let i = list[k + 1u];
    let px = vec2<u32>(i % frame.size.x, i / frame.size.x);
    let p = textureLoad(g_position, px, 0).xyz;
    let n = textureLoad(g_normal, px, 0).xyz;
    let shadowed = sample_shadowed(p, n);
    visibility[i] = select(1.0, 0.0, shadowed);
    if shadowed {
        let bits = tp.cfg.x;
        let per = 32u / bits;
        atomicOr(&cur_mask[i / per], 4u << ((i % per) * bits));
    }
}
