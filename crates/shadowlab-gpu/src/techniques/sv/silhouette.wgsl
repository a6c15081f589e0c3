// sv silhouette pass (compute, two entry points). `facing_main`: per triangle, on which side of
// its winding plane the light lies (+1 / -1, 0 = in the plane or degenerate; mirrors
// shadowlab-core edges.rs `facing`), and the alpha-masked triangles (cast as solid). `edges_main`:
// per edge, the multiplicity m = sum of facing(t) * dir(t) over its triangles (edges.rs); |m|
// side records (edge index, sign bit) are appended to `sides` and counted into the indirect
// draw's vertex count.


struct Edge {
    a: u32,
    b: u32,
    first: u32,
    count: u32,
}

struct Indirect {
    vertex_count: atomic<u32>,
    instance_count: u32,
    first_vertex: u32,
    first_instance: u32,
}

const REVERSED: u32 = 0x80000000u;

@group(0) @binding(0) var<uniform> light: LightU;
@group(0) @binding(1) var<uniform> sv: SvParams;
@group(0) @binding(2) var<storage, read> edges: array<Edge>;
@group(0) @binding(3) var<storage, read> adj: array<u32>;
@group(0) @binding(4) var<storage, read_write> facing: array<i32>;
@group(0) @binding(5) var<storage, read_write> sides: array<u32>;
@group(0) @binding(6) var<storage, read_write> draw: Indirect;
// 0: alpha-masked triangles, 1: triangles casting (facing != 0), 2: silhouette edges, 3: side records
@group(0) @binding(7) var<storage, read_write> stats: array<atomic<u32>, 4>;

fn thread_index(id: vec3<u32>, groups: vec3<u32>) -> u32 {
    return id.x + id.y * groups.x * 64u;
}

@compute @workgroup_size(64)
fn facing_main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let t = thread_index(id, groups);
    if t >= sv.triangles {
        return;
    }
    let v0 = vertices[3u * t];
    let p0 = v0.pos;
    let n = cross(vertices[3u * t + 1u].pos - p0, vertices[3u * t + 2u].pos - p0);
    var to = -light.direction.xyz;
    if light.kind != LIGHT_DIRECTIONAL {
        to = light.position.xyz - p0;
    }
    let d = dot(n, to);
    let f = select(0, 1, d > 0.0) - select(0, 1, d < 0.0);
    facing[t] = f;
    if f != 0 {
        atomicAdd(&stats[1], 1u);
    }
    if (materials[v0.material].flags & MAT_MASKED) != 0u {
        atomicAdd(&stats[0], 1u);
    }
}

@compute @workgroup_size(64)
fn edges_main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let e = thread_index(id, groups);
    if e >= sv.edges {
        return;
    }
    let edge = edges[e];
    var m = 0;
    for (var k = 0u; k < edge.count; k++) {
        let h = adj[edge.first + k];
        let f = facing[h & ~REVERSED];
        m += select(f, -f, (h & REVERSED) != 0u);
    }
    if m == 0 {
        return;
    }
    let n = u32(abs(m));
    let vps = sv.side_vertices;
    let base = atomicAdd(&draw.vertex_count, n * vps) / vps;
    atomicAdd(&stats[2], 1u);
    atomicAdd(&stats[3], n);
    let rec = e | select(0u, REVERSED, m < 0);
    for (var k = 0u; k < n; k++) {
        sides[base + k] = rec;
    }
}
