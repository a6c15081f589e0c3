// Shadow-ray library shared by `rt` and every technique that traces rays (leak tracing,
// hybrid classifiers): any-hit traversal of the scene BVH with early exit, alpha cut-outs
// honoured. Two trees: the static one (root 0) and the dynamic one over the moving objects
// (root `scene_info.dynamic_root`, rebuilt every frame); `occluded` sees both,
// `occluded_static` / `occluded_dynamic` one each. Needs `scene.wgsl` and the light uniform. Mirrors shadowlab-core/src/bvh.rs
// (`shadow_ray`, `intersect_triangle`, `occluded`).

const MAX_DEPTH: u32 = 64u;

fn safe_inv(x: f32) -> f32 {
    if abs(x) < 1e-20 {
        return select(-1e20, 1e20, x >= 0.0);
    }
    return 1.0 / x;
}

fn hits_box(n: BvhNode, o: vec3<f32>, inv: vec3<f32>, tmax: f32) -> bool {
    let t0 = (n.min - o) * inv;
    let t1 = (n.max - o) * inv;
    let lo = min(t0, t1);
    let hi = max(t0, t1);
    let tn = max(max(max(lo.x, lo.y), lo.z), 0.0);
    let tf = min(min(min(hi.x, hi.y), hi.z), tmax);
    return tn <= tf;
}

// Returns (hit, u, v) as vec3 with x = 1 on a hit.
fn intersect(o: vec3<f32>, d: vec3<f32>, tmax: f32, a: vec3<f32>, b: vec3<f32>, c: vec3<f32>) -> vec3<f32> {
    let e1 = b - a;
    let e2 = c - a;
    let p = cross(d, e2);
    let det = dot(e1, p);
    if abs(det) < 1e-12 {
        return vec3<f32>(0.0);
    }
    let inv = 1.0 / det;
    let s = o - a;
    let u = dot(s, p) * inv;
    if u < 0.0 || u > 1.0 {
        return vec3<f32>(0.0);
    }
    let q = cross(s, e1);
    let v = dot(d, q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return vec3<f32>(0.0);
    }
    let t = dot(e2, q) * inv;
    if t > 0.0 && t < tmax {
        return vec3<f32>(1.0, u, v);
    }
    return vec3<f32>(0.0);
}

fn passes_cutout(prim: u32, u: f32, v: f32) -> bool {
    let v0 = vertices[3u * prim];
    let m = materials[v0.material];
    if (m.flags & MAT_MASKED) == 0u {
        return false;
    }
    let uv = v0.uv * (1.0 - u - v) + vertices[3u * prim + 1u].uv * u + vertices[3u * prim + 2u].uv * v;
    return cut_out(m, uv);
}

// Any-hit traversal of the tree rooted at node `root`.
fn occluded_tree(root: u32, o: vec3<f32>, d: vec3<f32>, tmax: f32) -> bool {
    let inv = vec3<f32>(safe_inv(d.x), safe_inv(d.y), safe_inv(d.z));
    var stack: array<u32, MAX_DEPTH>;
    var sp = 1u;
    stack[0] = root;
    while sp > 0u {
        sp -= 1u;
        let n = bvh_nodes[stack[sp]];
        if !hits_box(n, o, inv, tmax) {
            continue;
        }
        if n.prim_count == 0u {
            stack[sp] = n.first_index;
            stack[sp + 1u] = n.first_index + 1u;
            sp += 2u;
            continue;
        }
        for (var k = 0u; k < n.prim_count; k++) {
            let prim = prim_indices[n.first_index + k];
            let h = intersect(o, d, tmax, vertices[3u * prim].pos, vertices[3u * prim + 1u].pos, vertices[3u * prim + 2u].pos);
            if h.x > 0.0 && !passes_cutout(prim, h.y, h.z) {
                return true;
            }
        }
    }
    return false;
}

// Blocked by static geometry (triangles 0..dynamic_first).
fn occluded_static(o: vec3<f32>, d: vec3<f32>, tmax: f32) -> bool {
    return scene_info.dynamic_first > 0u && occluded_tree(0u, o, d, tmax);
}

// Blocked by moving objects (triangles dynamic_first..triangle_count, where they are this frame).
fn occluded_dynamic(o: vec3<f32>, d: vec3<f32>, tmax: f32) -> bool {
    return scene_info.dynamic_first < scene_info.triangle_count && occluded_tree(scene_info.dynamic_root, o, d, tmax);
}

fn occluded(o: vec3<f32>, d: vec3<f32>, tmax: f32) -> bool {
    return occluded_static(o, d, tmax) || occluded_dynamic(o, d, tmax);
}

struct ShadowRay {
    o: vec3<f32>,
    d: vec3<f32>,
    tmax: f32,
}

// The shadow ray of a surface point `p` with geometric normal `n`: it starts `light.eps` off the
// surface and ends at the light (as `shadowlab_core::bvh::shadow_ray`).
fn shadow_ray(p: vec3<f32>, n: vec3<f32>) -> ShadowRay {
    var r: ShadowRay;
    r.o = p + n * light.eps;
    r.d = -light.direction.xyz;
    r.tmax = 1e30;
    if light.kind != LIGHT_DIRECTIONAL {
        let to = light.position.xyz - r.o;
        r.tmax = length(to);
        r.d = to / r.tmax;
    }
    return r;
}

// True where the light is blocked for a surface point `p` with geometric normal `n`.
fn sample_shadowed(p: vec3<f32>, n: vec3<f32>) -> bool {
    let r = shadow_ray(p, n);
    return occluded(r.o, r.d, r.tmax);
}
