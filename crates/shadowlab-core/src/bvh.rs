//! The reference's acceleration structure: a binary BVH built on the CPU with `obvhs`
//! (PLOC build, SAH-cost reinsertion and leaf collapse), flattened into the 32-byte node layout
//! that `rt.wgsl` traverses, plus the CPU traversal of the same nodes that cross-checks the GPU.

use bytemuck::{Pod, Zeroable};
use glam::{Vec2, Vec3, Vec3A};
use obvhs::{bvh2::builder::build_bvh2_from_tris, triangle::Triangle, BvhBuildParams};
use rayon::prelude::*;

use crate::light::Light;
use crate::scene::Scene;

/// Traversal stack depth of both traversals; the build fails if the tree is deeper.
pub const MAX_DEPTH: usize = 64;

/// WGSL: `struct BvhNode { min: vec3<f32>, prim_count: u32, max: vec3<f32>, first_index: u32 }`.
/// Inner node: `prim_count == 0`, children at `first_index` and `first_index + 1`.
/// Leaf: primitives `prim_indices[first_index .. first_index + prim_count]`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct BvhNode {
    pub min: [f32; 3],
    pub prim_count: u32,
    pub max: [f32; 3],
    pub first_index: u32,
}

pub struct Bvh {
    pub nodes: Vec<BvhNode>,
    pub prim_indices: Vec<u32>,
    pub depth: usize,
    pub build_ms: f64,
}

impl Bvh {
    /// BVH over every triangle of `scene` (as stored: moving objects at t = 0).
    pub fn build(scene: &Scene) -> Result<Bvh, String> {
        Bvh::build_range(scene, 0..scene.triangle_count())
    }

    /// BVH over triangles `range` of `scene`; primitive indices are scene triangle indices.
    pub fn build_range(scene: &Scene, range: std::ops::Range<usize>) -> Result<Bvh, String> {
        let first = range.start as u32;
        let tris: Vec<[Vec3; 3]> = range.map(|i| scene.triangle(i)).collect();
        Bvh::from_triangles(&tris, first)
    }

    /// BVH over `tris`; triangle `k` gets primitive index `first + k`.
    pub fn from_triangles(tris: &[[Vec3; 3]], first: u32) -> Result<Bvh, String> {
        let t0 = std::time::Instant::now();
        let tris: Vec<Triangle> =
            tris.iter().map(|[a, b, c]| Triangle { v0: Vec3A::from(*a), v1: Vec3A::from(*b), v2: Vec3A::from(*c) }).collect();
        if tris.is_empty() {
            return Err("scene has no triangles".into());
        }
        let mut core = std::time::Duration::ZERO;
        let b = build_bvh2_from_tris(&tris, BvhBuildParams::medium_build(), &mut core);
        let nodes: Vec<BvhNode> = b
            .nodes
            .iter()
            .map(|n| BvhNode {
                min: Vec3::from(n.aabb.min).into(),
                prim_count: n.prim_count,
                max: Vec3::from(n.aabb.max).into(),
                first_index: n.first_index,
            })
            .collect();
        let depth = tree_depth(&nodes);
        if depth >= MAX_DEPTH {
            return Err(format!("BVH depth {depth} exceeds the traversal stack ({MAX_DEPTH})"));
        }
        let prim_indices = b.primitive_indices.iter().map(|i| i + first).collect();
        Ok(Bvh { nodes, prim_indices, depth, build_ms: t0.elapsed().as_secs_f64() * 1e3 })
    }

    /// The nodes as they read when stored at `node_base` in a node array whose primitive
    /// indices are stored at `prim_base` (children and leaf ranges shifted; the GPU keeps the
    /// static and the dynamic BVH in one buffer each).
    pub fn relocated_nodes(&self, node_base: u32, prim_base: u32) -> Vec<BvhNode> {
        self.nodes
            .iter()
            .map(|n| BvhNode { first_index: n.first_index + if n.prim_count == 0 { node_base } else { prim_base }, ..*n })
            .collect()
    }

    /// Placeholder static tree of a scene where everything moves (`GpuScene` never traverses it:
    /// the static tree is skipped when `dynamic_first == 0`). Not for the CPU traversal.
    pub fn empty() -> Bvh {
        Bvh {
            nodes: vec![BvhNode { min: [f32::MAX; 3], max: [f32::MIN; 3], prim_count: 1, first_index: 0 }],
            prim_indices: vec![],
            depth: 1,
            build_ms: 0.0,
        }
    }

    /// Most nodes a binary BVH over `triangles` can have (every leaf holds at least one).
    pub fn max_nodes(triangles: usize) -> usize {
        (2 * triangles).saturating_sub(1).max(1)
    }

    pub fn bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<BvhNode>() + self.prim_indices.len() * 4
    }
}

fn tree_depth(nodes: &[BvhNode]) -> usize {
    let mut stack = vec![(0u32, 1usize)];
    let mut depth = 0;
    while let Some((i, d)) = stack.pop() {
        depth = depth.max(d);
        let n = nodes[i as usize];
        if n.prim_count == 0 {
            stack.push((n.first_index, d + 1));
            stack.push((n.first_index + 1, d + 1));
        }
    }
    depth
}

/// A shadow ray: origin offset along the normal by `eps`, towards the light, up to `tmax`.
#[derive(Clone, Copy, Debug)]
pub struct ShadowRay {
    pub origin: Vec3,
    pub dir: Vec3,
    pub tmax: f32,
}

/// The same construction as `shadow_ray` in `rt.wgsl`.
pub fn shadow_ray(light: &Light, pos: Vec3, normal: Vec3, eps: f32) -> ShadowRay {
    let origin = pos + normal * eps;
    match *light {
        Light::Directional { direction } => ShadowRay { origin, dir: -direction.normalize(), tmax: 1e30 },
        Light::Spot { position, .. } | Light::Point { position } => {
            let d = position - origin;
            let dist = d.length();
            ShadowRay { origin, dir: d / dist, tmax: dist }
        }
    }
}

/// Möller–Trumbore; returns (t, u, v) for a hit with t in (0, tmax). Mirrors `rt.wgsl`.
pub fn intersect_triangle(r: &ShadowRay, a: Vec3, b: Vec3, c: Vec3) -> Option<(f32, f32, f32)> {
    let e1 = b - a;
    let e2 = c - a;
    let p = r.dir.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-12 {
        return None;
    }
    let inv = 1.0 / det;
    let s = r.origin - a;
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = r.dir.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = e2.dot(q) * inv;
    (t > 0.0 && t < r.tmax).then_some((t, u, v))
}

/// Direction with zero components nudged so the slab test never computes 0 * inf.
pub fn safe_inverse(d: Vec3) -> Vec3 {
    let f = |x: f32| if x.abs() < 1e-20 { 1e20f32.copysign(x) } else { 1.0 / x };
    Vec3::new(f(d.x), f(d.y), f(d.z))
}

fn hits_box(n: &BvhNode, o: Vec3, inv: Vec3, tmax: f32) -> bool {
    let t0 = (Vec3::from(n.min) - o) * inv;
    let t1 = (Vec3::from(n.max) - o) * inv;
    let tn = t0.min(t1).max_element().max(0.0);
    let tf = t0.max(t1).min_element().min(tmax);
    tn <= tf
}

/// Whether the triangle `prim` lets the ray through at barycentrics (u, v) (alpha cut-out).
fn passes_cutout(scene: &Scene, prim: usize, u: f32, v: f32) -> bool {
    let vs = &scene.vertices[3 * prim..3 * prim + 3];
    let m = &scene.materials[vs[0].material as usize];
    let Some(cutoff) = m.alpha_cutoff else { return false };
    let uv = Vec2::from(vs[0].uv) * (1.0 - u - v) + Vec2::from(vs[1].uv) * u + Vec2::from(vs[2].uv) * v;
    let tex_alpha = match m.texture {
        Some(t) => scene.textures[t as usize].alpha_at(uv) as f32 / 255.0,
        None => 1.0,
    };
    tex_alpha * m.base_color[3] < cutoff
}

/// Any-hit occlusion test with early exit, honouring alpha cut-outs.
pub fn occluded(bvh: &Bvh, scene: &Scene, r: &ShadowRay) -> bool {
    occluded_from(&bvh.nodes, &bvh.prim_indices, 0, scene, r)
}

/// [`occluded`] over node/primitive arrays from the node `root` (the GPU's layout: static and
/// dynamic trees in one array, see [`Bvh::relocated_nodes`]).
pub fn occluded_from(nodes: &[BvhNode], prims: &[u32], root: u32, scene: &Scene, r: &ShadowRay) -> bool {
    let inv = safe_inverse(r.dir);
    let mut stack = [0u32; MAX_DEPTH];
    stack[0] = root;
    let mut sp = 1;
    while sp > 0 {
        sp -= 1;
        let n = &nodes[stack[sp] as usize];
        if !hits_box(n, r.origin, inv, r.tmax) {
            continue;
        }
        if n.prim_count == 0 {
            stack[sp] = n.first_index;
            stack[sp + 1] = n.first_index + 1;
            sp += 2;
            continue;
        }
        for k in 0..n.prim_count {
            let prim = prims[(n.first_index + k) as usize] as usize;
            let [a, b, c] = scene.triangle(prim);
            if let Some((_, u, v)) = intersect_triangle(r, a, b, c) {
                if !passes_cutout(scene, prim, u, v) {
                    return true;
                }
            }
        }
    }
    false
}

/// CPU reference visibility for G-buffer samples (`position`/`normal` xyz per pixel, `mask` 1 =
/// evaluated). Non-evaluated pixels get 0. Runs on all cores with rayon.
pub fn cpu_visibility(
    bvh: &Bvh,
    scene: &Scene,
    light: &Light,
    position: &[[f32; 4]],
    normal: &[[f32; 4]],
    mask: &[u32],
    eps: f32,
) -> Vec<f32> {
    (0..mask.len())
        .into_par_iter()
        .map(|i| {
            if mask[i] == 0 {
                return 0.0;
            }
            let p = Vec3::from_slice(&position[i][..3]);
            let n = Vec3::from_slice(&normal[i][..3]);
            if occluded(bvh, scene, &shadow_ray(light, p, n, eps)) {
                0.0
            } else {
                1.0
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::builtin::builtin;

    #[test]
    fn planebox_shadow_is_exact() {
        let s = builtin("planebox").unwrap();
        let bvh = Bvh::build(&s).unwrap();
        let l = Light::Directional { direction: Vec3::new(0.0, -1.0, 0.0) };
        let eps = s.ray_epsilon();
        // under the box: shadowed; beside it: lit; on top of the box: lit
        assert!(occluded(&bvh, &s, &shadow_ray(&l, Vec3::new(0.2, 0.0, 0.1), Vec3::Y, eps)));
        assert!(!occluded(&bvh, &s, &shadow_ray(&l, Vec3::new(0.7, 0.0, 0.1), Vec3::Y, eps)));
        assert!(!occluded(&bvh, &s, &shadow_ray(&l, Vec3::new(0.2, 1.0, 0.1), Vec3::Y, eps)));
        // oblique light: the shadow is displaced by the box height times the slope
        let l2 = Light::Directional { direction: Vec3::new(1.0, -1.0, 0.0) };
        assert!(occluded(&bvh, &s, &shadow_ray(&l2, Vec3::new(1.4, 0.0, 0.0), Vec3::Y, eps)));
        assert!(!occluded(&bvh, &s, &shadow_ray(&l2, Vec3::new(1.6, 0.0, 0.0), Vec3::Y, eps)));
        let pl = Light::Point { position: Vec3::new(0.0, 0.5, 3.0) };
        assert!(occluded(&bvh, &s, &shadow_ray(&pl, Vec3::new(0.0, 0.1, -1.0), Vec3::Y, eps)));
        assert!(!occluded(&bvh, &s, &shadow_ray(&pl, Vec3::new(0.0, 0.2, 2.0), Vec3::Y, eps)));
    }

    #[test]
    fn static_and_dynamic_trees_in_one_array_see_everything() {
        // courtyard's banners are dynamic: a static tree over the rest and a relocated dynamic
        // tree behind it in the same arrays answer exactly like one tree over the whole scene
        let s = builtin("courtyard").unwrap();
        let (d, n) = (s.dynamic_first(), s.triangle_count());
        assert!(d < n);
        let full = Bvh::build(&s).unwrap();
        let st = Bvh::build_range(&s, 0..d).unwrap();
        let dy = Bvh::build_range(&s, d..n).unwrap();
        assert!(dy.nodes.len() <= Bvh::max_nodes(n - d) && dy.prim_indices.len() == n - d);
        assert!(dy.prim_indices.iter().all(|&p| (d as u32..n as u32).contains(&p)));
        let root = st.nodes.len() as u32;
        let mut nodes = st.nodes.clone();
        nodes.extend(dy.relocated_nodes(root, st.prim_indices.len() as u32));
        let prims: Vec<u32> = st.prim_indices.iter().chain(&dy.prim_indices).copied().collect();
        let b = s.bounds();
        let l = s.lights[0];
        let (mut hits, mut dyn_hits) = (0, 0);
        for i in 0..2000u32 {
            let h = |k: u32| crate::builtin::hash01(i * 7 + k);
            let p = b.min + (b.max - b.min) * Vec3::new(h(1), h(2) * 0.7, h(3));
            let r = shadow_ray(&l, p, Vec3::Y, 1e-4);
            let two = occluded_from(&nodes, &prims, 0, &s, &r) || occluded_from(&nodes, &prims, root, &s, &r);
            assert_eq!(two, occluded(&full, &s, &r), "ray {i}");
            hits += two as u32;
            dyn_hits += occluded_from(&nodes, &prims, root, &s, &r) as u32;
        }
        assert!(hits > 100 && dyn_hits > 0, "{hits} occluded, {dyn_hits} by banners");
    }

    #[test]
    fn bvh_matches_brute_force() {
        let s = builtin("courtyard").unwrap();
        let bvh = Bvh::build(&s).unwrap();
        let b = s.bounds();
        let l = s.lights[0];
        let mut disagreements = 0;
        for i in 0..400u32 {
            let h = |k: u32| crate::builtin::hash01(i * 7 + k);
            let p = b.min + (b.max - b.min) * Vec3::new(h(1), h(2) * 0.5, h(3));
            let r = shadow_ray(&l, p, Vec3::Y, 1e-4);
            let brute = (0..s.triangle_count()).any(|t| {
                let [a, bb, c] = s.triangle(t);
                intersect_triangle(&r, a, bb, c).is_some_and(|(_, u, v)| !passes_cutout(&s, t, u, v))
            });
            disagreements += (brute != occluded(&bvh, &s, &r)) as u32;
        }
        assert_eq!(disagreements, 0);
    }
}
