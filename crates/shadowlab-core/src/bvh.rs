//! The reference's acceleration structure: a binary BVH built on the CPU with `obvhs`
//! (PLOC build, SAH-cost reinsertion and leaf collapse), flattened into the 32-byte node layout
//! that `rt.wgsl` traverses, plus the CPU traversal of the same nodes that cross-checks the GPU.

use bytemuck::{Pod, Zeroable};
use glam::{Vec2, Vec3};
use obvhs::bvh2::{leaf_collapser::collapse, reinsertion::ReinsertionOptimizer};
use obvhs::{aabb::Aabb, bvh2::Bvh2, ploc::PlocBuilder, Boundable, BvhBuildParams};
use rayon::prelude::*;

use crate::light::Light;
use crate::scene::Scene;

/// `obvhs::bvh2::builder::build_bvh2` step for step (PLOC, reinsertion, leaf collapse,
/// reinsertion), without its build timer: `std::time::Instant` panics on wasm32 (docs/web.md).
fn build_bvh2<T: Boundable>(prims: &[T], config: BvhBuildParams) -> Bvh2 {
    let mut bvh2 = PlocBuilder::with_capacity(prims.len()).build(
        config.ploc_search_distance,
        prims,
        (0..prims.len() as u32).collect::<Vec<_>>(),
        config.sort_precision,
        config.search_depth_threshold,
    );
    let mut reinsertion = ReinsertionOptimizer::default();
    reinsertion.run(&mut bvh2, config.reinsertion_batch_ratio, None);
    collapse(&mut bvh2, config.max_prims_per_leaf.clamp(1, 255), config.collapse_traversal_cost);
    reinsertion.run(&mut bvh2, config.reinsertion_batch_ratio * config.post_collapse_reinsertion_batch_ratio_multiplier, None);
    bvh2
}

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
    ///
    /// Triangles with bit-identical bounding boxes (duplicated faces, zero-area triangles at one
    /// point), more than [`LEAF_PRIMS`] of them, are one primitive of the `obvhs` build: its
    /// PLOC clustering merges one pair of equal boxes per pass, so thousands of copies made the
    /// build quadratic and the tree as deep as the copies. Each such group is spread afterwards
    /// over a balanced subtree with leaves of at most [`LEAF_PRIMS`] ([`expand`]). Without such
    /// repeats the tree is the plain `obvhs` build, node for node.
    pub fn from_triangles(tris: &[[Vec3; 3]], first: u32) -> Result<Bvh, String> {
        let t0 = web_time::Instant::now();
        if tris.is_empty() {
            return Err("scene has no triangles".into());
        }
        let boxes: Vec<Aabb> = tris.iter().map(|&[a, b, c]| Aabb::from_points(&[a.into(), b.into(), c.into()])).collect();
        let groups = Groups::of(&boxes);
        let reps: Vec<Aabb> =
            groups.starts[..groups.starts.len() - 1].iter().map(|&s| boxes[groups.members[s as usize] as usize]).collect();
        let b = build_bvh2(&reps, BvhBuildParams::medium_build());
        let (nodes, local) = expand(&b, &groups, &boxes);
        let depth = tree_depth(&nodes);
        if depth >= MAX_DEPTH {
            return Err(format!("BVH depth {depth} exceeds the traversal stack ({MAX_DEPTH})"));
        }
        let prim_indices = local.iter().map(|i| i + first).collect();
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

/// Most primitives in a leaf made by [`expand`] (the `obvhs` build's own limit).
pub const LEAF_PRIMS: usize = 8;

/// Triangles grouped for the `obvhs` build, in order of first appearance: a bounding box that
/// more than [`LEAF_PRIMS`] triangles share bit for bit is one group, every other triangle is a
/// group of its own (the two halves of a quad share a box; a handful of copies does not hurt
/// the build). Group `g` is `members[starts[g] .. starts[g + 1]]` (triangle indices, ascending;
/// `starts` ends with `members.len()`).
struct Groups {
    starts: Vec<u32>,
    members: Vec<u32>,
}

impl Groups {
    fn of(boxes: &[Aabb]) -> Groups {
        let key = |b: &Aabb| {
            let (lo, hi) = (b.min.to_array(), b.max.to_array());
            [lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]].map(f32::to_bits)
        };
        // per repeated box: (copies, its group once given)
        let mut shared: std::collections::HashMap<[u32; 6], (usize, u32)> = std::collections::HashMap::new();
        for b in boxes {
            shared.entry(key(b)).or_insert((0, u32::MAX)).0 += 1;
        }
        shared.retain(|_, (n, _)| *n > LEAF_PRIMS);
        let mut count = 0u32;
        let group: Vec<u32> = boxes
            .iter()
            .map(|b| {
                let g = match shared.get_mut(&key(b)) {
                    Some((_, g)) if *g != u32::MAX => return *g,
                    Some((_, g)) => {
                        *g = count;
                        count
                    }
                    None => count,
                };
                count += 1;
                g
            })
            .collect();
        // counting sort of the triangles by group (stable: ascending within a group)
        let groups = count as usize;
        let mut starts = vec![0u32; groups + 1];
        for &g in &group {
            starts[g as usize + 1] += 1;
        }
        for g in 0..groups {
            starts[g + 1] += starts[g];
        }
        let mut next = starts.clone();
        let mut members = vec![0u32; boxes.len()];
        for (t, &g) in group.iter().enumerate() {
            members[next[g as usize] as usize] = t as u32;
            next[g as usize] += 1;
        }
        Groups { starts, members }
    }

    fn members(&self, g: u32) -> &[u32] {
        &self.members[self.starts[g as usize] as usize..self.starts[g as usize + 1] as usize]
    }
}

/// The `obvhs` tree over group representatives as [`BvhNode`]s over triangles, node for node
/// in the same order: a leaf whose groups hold at most [`LEAF_PRIMS`] triangles in all stays a
/// leaf; a larger one becomes a balanced subtree over its triangles (halved by count, so its
/// depth grows with the log of the copies), its nodes appended. Returns the nodes and the
/// triangles in leaf order (without repeated boxes: exactly the `obvhs` tree and order).
fn expand(b: &Bvh2, groups: &Groups, boxes: &[Aabb]) -> (Vec<BvhNode>, Vec<u32>) {
    let node = |aabb: &Aabb, prim_count: u32, first_index: u32| BvhNode {
        min: Vec3::from(aabb.min).into(),
        prim_count,
        max: Vec3::from(aabb.max).into(),
        first_index,
    };
    let mut nodes: Vec<BvhNode> = b.nodes.iter().map(|n| node(&n.aabb, n.prim_count, n.first_index)).collect();
    let mut leaves: Vec<usize> = (0..b.nodes.len()).filter(|&i| b.nodes[i].prim_count > 0).collect();
    leaves.sort_by_key(|&i| b.nodes[i].first_index);
    let mut prims: Vec<u32> = Vec::with_capacity(boxes.len());
    for leaf in leaves {
        let n = &b.nodes[leaf];
        let reps = &b.primitive_indices[n.first_index as usize..(n.first_index + n.prim_count) as usize];
        let mut work = vec![(leaf, reps.iter().flat_map(|&g| groups.members(g)).copied().collect::<Vec<u32>>())];
        while let Some((slot, mut tris)) = work.pop() {
            let aabb = tris.iter().fold(Aabb::empty(), |a, &t| a.union(&boxes[t as usize]));
            if tris.len() <= LEAF_PRIMS {
                nodes[slot] = node(&aabb, tris.len() as u32, prims.len() as u32);
                prims.extend(&tris);
                continue;
            }
            let c = nodes.len();
            nodes.extend([BvhNode::default(); 2]);
            nodes[slot] = node(&aabb, 0, c as u32);
            let right = tris.split_off(tris.len() / 2);
            work.push((c + 1, right));
            work.push((c, tris));
        }
    }
    (nodes, prims)
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

    fn copies(tri: [Vec3; 3], n: usize) -> Vec<[Vec3; 3]> {
        vec![tri; n]
    }

    fn is_permutation(prims: &[u32], first: u32, n: usize) -> bool {
        let mut p = prims.to_vec();
        p.sort_unstable();
        p.iter().copied().eq(first..first + n as u32)
    }

    #[test]
    fn without_repeated_boxes_the_tree_is_obvhs_own() {
        let s = builtin("courtyard").unwrap();
        let tris: Vec<[Vec3; 3]> = (0..s.triangle_count()).map(|i| s.triangle(i)).collect();
        let ours = Bvh::from_triangles(&tris, 5).unwrap();
        let plain: Vec<obvhs::triangle::Triangle> =
            tris.iter().map(|[a, b, c]| obvhs::triangle::Triangle { v0: (*a).into(), v1: (*b).into(), v2: (*c).into() }).collect();
        let b = obvhs::bvh2::builder::build_bvh2_from_tris(&plain, BvhBuildParams::medium_build(), &mut Default::default());
        assert_eq!(ours.nodes.len(), b.nodes.len());
        for (o, n) in ours.nodes.iter().zip(&b.nodes) {
            assert_eq!((o.prim_count, o.first_index), (n.prim_count, n.first_index));
            assert_eq!((o.min, o.max), (Vec3::from(n.aabb.min).into(), Vec3::from(n.aabb.max).into()));
        }
        assert!(ours.prim_indices.iter().copied().eq(b.primitive_indices.iter().map(|i| i + 5)));
    }

    #[test]
    fn coincident_triangles_build_a_balanced_tree() {
        // 100,000 copies of one triangle (a duplicated face): the plain PLOC build merged one
        // pair per pass (quadratic, and as deep as the copies)
        let n = 100_000;
        let tri = [Vec3::new(0.0, 1.0, 0.0), Vec3::new(1.0, 1.0, 0.0), Vec3::new(0.0, 1.0, 1.0)];
        let bvh = Bvh::from_triangles(&copies(tri, n), 0).unwrap();
        // a balanced tree over n / LEAF_PRIMS leaves: 14 levels, plus the root
        let balanced = (n as f64 / LEAF_PRIMS as f64).log2().ceil() as usize + 1;
        assert!(bvh.depth <= balanced + 1, "depth {} for {n} copies", bvh.depth);
        assert!(bvh.nodes.len() <= Bvh::max_nodes(n));
        assert!(is_permutation(&bvh.prim_indices, 0, n));
        assert!(bvh.nodes.iter().all(|b| b.prim_count as usize <= LEAF_PRIMS));
    }

    #[test]
    fn zero_area_and_mixed_repeats_build() {
        // zero-area triangles at one point and along one segment, repeated groups beside
        // distinct triangles: every triangle in exactly one leaf, boxes hold their triangles
        let mut tris = Vec::new();
        let p = Vec3::new(2.0, 0.5, -1.0);
        tris.extend(copies([p, p, p], 20_000));
        tris.extend(copies([p, p + Vec3::X, p + Vec3::X * 0.5], 20_000));
        for i in 0..2_000u32 {
            let h = |k: u32| crate::builtin::hash01(i * 5 + k);
            let o = Vec3::new(h(1), h(2), h(3)) * 10.0;
            let t = [o, o + Vec3::new(0.3, 0.0, 0.1), o + Vec3::new(0.0, 0.2, 0.3)];
            tris.extend(copies(t, 1 + (i % 7) as usize));
        }
        let bvh = Bvh::from_triangles(&tris, 3).unwrap();
        assert!(bvh.depth < 40, "depth {}", bvh.depth);
        assert!(is_permutation(&bvh.prim_indices, 3, tris.len()));
        for n in bvh.nodes.iter().filter(|n| n.prim_count > 0) {
            for &p in &bvh.prim_indices[n.first_index as usize..(n.first_index + n.prim_count) as usize] {
                for v in tris[(p - 3) as usize] {
                    assert!(Vec3::from(n.min).cmple(v).all() && v.cmple(Vec3::from(n.max)).all());
                }
            }
        }
    }

    #[test]
    fn coincident_scene_agrees_with_brute_force() {
        // planebox with its box's top face repeated 3,000 times and 500 zero-area triangles
        let mut s = builtin("planebox").unwrap();
        let top = (0..s.triangle_count()).find(|&t| s.triangle(t).iter().all(|v| v.y == 1.0)).unwrap();
        let face = s.vertices[3 * top..3 * top + 3].to_vec();
        for _ in 0..3_000 {
            s.vertices.extend_from_slice(&face);
        }
        let mut point = face.clone();
        for v in &mut point {
            v.pos = [0.9, 0.6, 0.8];
        }
        for _ in 0..500 {
            s.vertices.extend_from_slice(&point);
        }
        let bvh = Bvh::build(&s).unwrap();
        let l = s.lights[0];
        let (mut hits, mut disagreements) = (0, 0);
        for i in 0..600u32 {
            let h = |k: u32| crate::builtin::hash01(i * 7 + k);
            let p = Vec3::new(h(1) * 4.0 - 2.0, 0.0, h(2) * 4.0 - 2.0);
            let r = shadow_ray(&l, p, Vec3::Y, 1e-4);
            let brute = (0..s.triangle_count()).any(|t| {
                let [a, b, c] = s.triangle(t);
                intersect_triangle(&r, a, b, c).is_some()
            });
            hits += brute as u32;
            disagreements += (brute != occluded(&bvh, &s, &r)) as u32;
        }
        assert_eq!(disagreements, 0);
        assert!(hits > 30, "{hits} occluded rays");
    }
}
