//! The edge list of silhouette shadow volumes (`sv`): every edge of the scene's triangles once,
//! with the triangles around it, after welding the de-indexed vertex triples by exact position.
//!
//! Multiplicity (the per-edge count of Milet, Kobrtek, Zemčík, Pečiva 2014, "MKZP14" in the
//! seeds): each edge has a fixed direction a -> b (welded id of a < welded id of b). Every
//! non-degenerate triangle casts its own volume, oriented so that its cap faces the light; around
//! an edge, the triangle contributes +1 if that light-facing orientation runs a -> b and -1 if it
//! runs b -> a, i.e. `facing(t) * dir(t, edge)` with `facing` = +1/-1 by the side of the
//! triangle's plane the light is on, and `dir` = +1 when the triangle's winding runs a -> b. The
//! side quads of all triangles' volumes on one edge then sum to `m` copies of the quad
//! (a, b, b_inf, a_inf) (negative: reversed). A closed mesh gives 0 (not a silhouette) or +-2, an
//! open edge +-1, a fin of three triangles +-1 or +-3. Because `facing` is computed once per
//! triangle and `dir` is exact topology, the volumes close exactly whatever the floating point.

use std::collections::HashMap;

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use crate::light::Light;

/// Set in an [`EdgeList::adj`] entry when the triangle's winding runs b -> a.
pub const REVERSED: u32 = 1 << 31;

/// WGSL `Edge` (sv/silhouette.wgsl): endpoints as indices into the scene's vertex array (any
/// vertex of the welded position), and the range of its triangles in `adj`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct Edge {
    pub a: u32,
    pub b: u32,
    pub first: u32,
    pub count: u32,
}

#[derive(Clone, Debug, Default)]
pub struct EdgeList {
    pub edges: Vec<Edge>,
    /// Triangle index, with [`REVERSED`] when its winding runs b -> a.
    pub adj: Vec<u32>,
    /// Distinct positions after welding.
    pub welded_vertices: usize,
    /// Triangles with two vertices at the same position (no edges; they cast nothing).
    pub degenerate_triangles: usize,
}

/// Exact position key; -0.0 and 0.0 weld together.
fn key(p: [f32; 3]) -> [u32; 3] {
    p.map(|c| if c == 0.0 { 0 } else { c.to_bits() })
}

impl EdgeList {
    /// Builds the edge list of de-indexed triangles (`positions.len()` a multiple of 3).
    pub fn build(positions: &[[f32; 3]]) -> EdgeList {
        let mut ids: HashMap<[u32; 3], u32> = HashMap::with_capacity(positions.len() / 4);
        let mut first_vertex: Vec<u32> = Vec::new();
        let welded: Vec<u32> = positions
            .iter()
            .enumerate()
            .map(|(i, p)| {
                *ids.entry(key(*p)).or_insert_with(|| {
                    first_vertex.push(i as u32);
                    first_vertex.len() as u32 - 1
                })
            })
            .collect();
        // (lo, hi, adj entry) for every half-edge, grouped by sorting.
        let mut half: Vec<(u32, u32, u32)> = Vec::with_capacity(positions.len());
        let mut degenerate = 0;
        for (t, w) in welded.chunks_exact(3).enumerate() {
            if w[0] == w[1] || w[1] == w[2] || w[2] == w[0] {
                degenerate += 1;
                continue;
            }
            for k in 0..3 {
                let (x, y) = (w[k], w[(k + 1) % 3]);
                let entry = t as u32 | if x < y { 0 } else { REVERSED };
                half.push((x.min(y), x.max(y), entry));
            }
        }
        half.sort_unstable();
        let mut edges = Vec::new();
        let mut adj = Vec::with_capacity(half.len());
        for group in half.chunk_by(|p, q| (p.0, p.1) == (q.0, q.1)) {
            let (lo, hi, _) = group[0];
            edges.push(Edge {
                a: first_vertex[lo as usize],
                b: first_vertex[hi as usize],
                first: adj.len() as u32,
                count: group.len() as u32,
            });
            adj.extend(group.iter().map(|h| h.2));
        }
        EdgeList { edges, adj, welded_vertices: first_vertex.len(), degenerate_triangles: degenerate }
    }

    /// Signed multiplicity of edge `e` given each triangle's [`facing`].
    pub fn multiplicity(&self, e: &Edge, facing: &[i32]) -> i32 {
        self.adj[e.first as usize..(e.first + e.count) as usize]
            .iter()
            .map(|&h| {
                let f = facing[(h & !REVERSED) as usize];
                if h & REVERSED != 0 {
                    -f
                } else {
                    f
                }
            })
            .sum()
    }

    /// Edges by number of adjacent triangles: (open = 1, manifold = 2, more than 2).
    pub fn valence_counts(&self) -> (usize, usize, usize) {
        let n = |f: fn(u32) -> bool| self.edges.iter().filter(|e| f(e.count)).count();
        (n(|c| c == 1), n(|c| c == 2), n(|c| c > 2))
    }

    /// Bytes of the edge and adjacency buffers on the GPU.
    pub fn bytes(&self) -> u64 {
        (self.edges.len() * std::mem::size_of::<Edge>() + self.adj.len() * 4) as u64
    }
}

/// +1 if the light is on the side of the triangle's winding normal, -1 on the other side, 0 if
/// the light lies in its plane or the triangle is degenerate. Mirrors `facing` in
/// sv/silhouette.wgsl (same operations in the same order).
pub fn facing(t: [Vec3; 3], light: &Light) -> i32 {
    let n = (t[1] - t[0]).cross(t[2] - t[0]);
    let to = match *light {
        Light::Directional { direction } => -direction,
        Light::Spot { position, .. } | Light::Point { position } => position - t[0],
    };
    let d = n.dot(to);
    (d > 0.0) as i32 - (d < 0.0) as i32
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tris(list: &[[[f32; 3]; 3]]) -> Vec<[f32; 3]> {
        list.iter().flatten().copied().collect()
    }

    /// Unit cube, 12 triangles wound counter-clockwise seen from outside.
    fn cube() -> Vec<[f32; 3]> {
        let mut out = Vec::new();
        let c = |x: f32, y: f32, z: f32| [x, y, z];
        // each face as (origin, u, v) with u x v pointing outward
        let faces = [
            ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
            ([1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
            ([1.0, 0.0, 1.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]),
            ([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]),
            ([0.0, 1.0, 1.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]),
            ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
        ];
        for (o, u, v) in faces {
            let p = |a: f32, b: f32| c(o[0] + a * u[0] + b * v[0], o[1] + a * u[1] + b * v[1], o[2] + a * u[2] + b * v[2]);
            out.extend([p(0.0, 0.0), p(1.0, 0.0), p(1.0, 1.0), p(0.0, 0.0), p(1.0, 1.0), p(0.0, 1.0)]);
        }
        out
    }

    fn facings(pos: &[[f32; 3]], light: &Light) -> Vec<i32> {
        pos.chunks_exact(3).map(|t| facing([t[0].into(), t[1].into(), t[2].into()], light)).collect()
    }

    #[test]
    fn closed_cube_has_only_two_sided_edges_and_a_silhouette_of_multiplicity_two() {
        let pos = cube();
        // outward winding: every face normal points away from the centre
        for t in pos.chunks_exact(3) {
            let n = (Vec3::from(t[1]) - Vec3::from(t[0])).cross(Vec3::from(t[2]) - Vec3::from(t[0]));
            assert!(n.dot(Vec3::from(t[0]) - Vec3::splat(0.5)) > 0.0);
        }
        let l = EdgeList::build(&pos);
        assert_eq!(l.welded_vertices, 8);
        assert_eq!(l.edges.len(), 18); // 12 cube edges + 6 face diagonals
        assert_eq!(l.valence_counts(), (0, 18, 0));
        // every manifold edge is traversed once each way
        for e in &l.edges {
            let dirs: Vec<bool> = l.adj[e.first as usize..][..2].iter().map(|h| h & REVERSED != 0).collect();
            assert_ne!(dirs[0], dirs[1]);
        }
        // light from a generic direction: the silhouette is a loop of 6 cube edges, each +-2
        let light = Light::Directional { direction: Vec3::new(-0.3, -1.0, -0.6) };
        let f = facings(&pos, &light);
        let m: Vec<i32> = l.edges.iter().map(|e| l.multiplicity(e, &f)).collect();
        assert_eq!(m.iter().filter(|m| m.abs() == 2).count(), 6);
        assert!(m.iter().all(|m| *m == 0 || m.abs() == 2));
        // straight down: the side faces are edge-on (facing 0), so both rims are silhouettes of
        // multiplicity 1 (top face +1, bottom face turned to the light +1)
        let down = Light::Directional { direction: Vec3::new(0.0, -1.0, 0.0) };
        let f = facings(&pos, &down);
        let sil: Vec<i32> = l.edges.iter().map(|e| l.multiplicity(e, &f)).filter(|m| *m != 0).collect();
        assert!(sil.iter().all(|m| m.abs() == 1));
        assert_eq!(sil.len(), 8);
    }

    #[test]
    fn open_quad_has_four_open_edges() {
        let pos = tris(&[[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 1.0]], [[0.0, 0.0, 0.0], [1.0, 0.0, 1.0], [0.0, 0.0, 1.0]]]);
        let l = EdgeList::build(&pos);
        assert_eq!(l.welded_vertices, 4);
        assert_eq!(l.valence_counts(), (4, 1, 0));
        for light in [Light::Directional { direction: Vec3::new(0.2, -1.0, 0.1) }, Light::Point { position: Vec3::new(0.3, -2.0, 0.4) }] {
            let f = facings(&pos, &light);
            assert_eq!(f[0], f[1]);
            for e in &l.edges {
                let m = l.multiplicity(e, &f);
                assert_eq!(m.abs(), if e.count == 1 { 1 } else { 0 }, "{e:?}");
            }
        }
    }

    #[test]
    fn fin_of_three_triangles_on_one_edge() {
        // three blades around the edge a-b (the x axis): normals +z, (0, 0.5, -1) (wound b -> a)
        // and -y
        let a = [0.0, 0.0, 0.0];
        let b = [1.0, 0.0, 0.0];
        let pos = tris(&[[a, b, [0.5, 1.0, 0.0]], [b, a, [0.5, 1.0, 0.5]], [a, b, [0.5, 0.0, 1.0]]]);
        let l = EdgeList::build(&pos);
        assert_eq!(l.valence_counts(), (6, 0, 1));
        let shared = l.edges.iter().find(|e| e.count == 3).unwrap();
        // blade 0 runs a -> b and faces the light: +1; blade 1 runs b -> a and faces away:
        // (-1)(-1) = +1; blade 2 runs a -> b and faces: +1
        let light = Light::Directional { direction: Vec3::new(0.0, 0.3, -1.0) };
        let f = facings(&pos, &light);
        assert_eq!(f, vec![1, -1, 1]);
        assert_eq!(l.multiplicity(shared, &f), 3);
        // blade 2 turned away: 1 + 1 - 1
        let light = Light::Directional { direction: Vec3::new(0.0, -0.3, -1.0) };
        let f = facings(&pos, &light);
        assert_eq!(f, vec![1, -1, -1]);
        assert_eq!(l.multiplicity(shared, &f), 1);
    }

    #[test]
    fn welding_is_exact_and_merges_signed_zero() {
        let pos = tris(&[[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], [[-0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 1e-7]]]);
        let l = EdgeList::build(&pos);
        assert_eq!(l.welded_vertices, 4);
        assert_eq!(l.valence_counts(), (4, 1, 0));
        let degenerate = tris(&[[[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0]]]);
        let l = EdgeList::build(&degenerate);
        assert_eq!((l.edges.len(), l.degenerate_triangles), (0, 1));
    }

    #[test]
    fn facing_by_side_of_the_plane() {
        let t = [Vec3::ZERO, Vec3::X, Vec3::Z]; // normal -y
        assert_eq!(facing(t, &Light::Directional { direction: Vec3::Y }), 1);
        assert_eq!(facing(t, &Light::Directional { direction: -Vec3::Y }), -1);
        assert_eq!(facing(t, &Light::Directional { direction: Vec3::X }), 0);
        assert_eq!(facing(t, &Light::Point { position: Vec3::new(0.2, 3.0, 0.2) }), -1);
    }
}
