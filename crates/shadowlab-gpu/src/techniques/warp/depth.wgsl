// Warped shadow-map pass (seed 000 Algorithm 1 in the vertex stage): each vertex is projected,
// cropped to the desired view and moved by the warp textures; depth stays the base projection's
// post-projective depth (0 = near the light; paraboloid: distance / far). With subdivision on,
// the vertices come from the pieces of subdiv.wgsl.
//
// `exact_depth` (EXACT_DEPTH): the rasteriser interpolates depth linearly between warped
// vertices, which is wrong inside a piece by up to the subdivision threshold. The stored depth
// d = clip_to_map(base_clip(p)).z of a point p on a plane is an affine function of its base
// (cropped, unwarped) map coordinates u, for orthographic and perspective (spot) projections
// alike: a projective map sends planes to planes. So the vertex stage passes the plane
// d = dot(g, u) + c of the piece's triangle (flat) and the unwarped u (screen-linear, a first
// guess); depth_exact.wgsl inverts the warp at the fragment by Newton steps and writes the
// plane's depth there.

@group(0) @binding(10) var<storage, read> pieces: array<vec4<u32>>;

// The map's knobs that choose code paths, fixed at pipeline creation (depth.rs `constants`;
// equal to the uniform's `subdiv > 0`, `exact_depth`, `exact_inverse`, and the scene's
// cut-outs; PARABOLOID and WARPED in params.wgsl).
override SUBDIVIDED: bool;
override EXACT_DEPTH: bool;
override EXACT_INVERSE: bool;
override CUTOUTS: bool;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
    @location(1) @interpolate(flat) material: u32,
    // exact depth: the unwarped cropped map coordinate (initial guess of the inversion)
    @location(2) @interpolate(linear) u: vec2<f32>,
    // exact depth: plane gradient (x, y) and offset (z); w = 1 when valid
    @location(3) @interpolate(flat) plane: vec4<f32>,
    // exact depth: the piece corners' depth range (the exact depth is clamped to it)
    @location(4) @interpolate(flat) zrange: vec2<f32>,
    // paraboloid: n.z of the vertex direction in the hemisphere's light space (planar: 1)
    @location(5) side: f32,
}

// Paraboloid: fragments farther than SPLIT_OVERLAP behind the split plane (params.wgsl) are
// discarded; their images would wrap around the map.
fn behind_hemisphere(in: VsOut) -> bool {
    return in.side < -SPLIT_OVERLAP;
}

// Whether the fragment stage drops this fragment: an alpha cut-out, or behind the hemisphere.
fn discarded(in: VsOut) -> bool {
    if CUTOUTS && cut_out(materials[in.material], in.uv) {
        return true;
    }
    return PARABOLOID && behind_hemisphere(in);
}

fn bary_pos(tri: u32, b: vec2<f32>) -> vec3<f32> {
    let v0 = vertices[3u * tri].pos;
    return v0 + (vertices[3u * tri + 1u].pos - v0) * b.x + (vertices[3u * tri + 2u].pos - v0) * b.y;
}

// Piece i of the subdivision: its slot, or past the slots (the triangles' and the pieces they
// may add) entry i - slots of the lists of a layered subdivision (subdiv_scatter.wgsl), four a
// slot; without the flat mark of a layered subdivision's pieces (subdiv_layers.wgsl), and with
// the scene's triangle (`scene_triangles`).
fn piece_at(i: u32) -> vec4<u32> {
    let slots = wp.triangles + wp.extra_capacity;
    var p: vec4<u32>;
    if i < slots {
        p = pieces[i];
    } else {
        let k = i - slots;
        p = pieces[pieces[slots + k / 4u][k % 4u]];
    }
    return vec4<u32>(scene_triangle(wp, p.x & 0x7fffffffu), p.yzw);
}

// Corner c of a subdivision piece (triangle, three unorm16x2 barycentrics; subdiv.wgsl).
fn piece_vertex(p: vec4<u32>, c: u32) -> Vertex {
    let b = unpack2x16unorm(array<u32, 3>(p.y, p.z, p.w)[c]);
    var v = vertices[3u * p.x];
    let v1 = vertices[3u * p.x + 1u];
    let v2 = vertices[3u * p.x + 2u];
    let b0 = 1.0 - b.x - b.y;
    v.pos = v.pos * b0 + v1.pos * b.x + v2.pos * b.y;
    v.uv = v.uv * b0 + v1.uv * b.x + v2.uv * b.y;
    return v;
}

// Plane d = dot(g, u) + c through three points (u, d); w = 0 when the triangle is seen edge-on
// from the light (its projected edges nearly parallel: depth undefined) or a point is behind it.
fn depth_plane(a: array<vec4<f32>, 3>, r: vec4<f32>) -> vec4<f32> {
    if min(min(a[0].w, a[1].w), a[2].w) <= 1e-7 {
        return vec4<f32>(0.0);
    }
    let m0 = clip_to_map(a[0]);
    let m1 = clip_to_map(a[1]);
    let m2 = clip_to_map(a[2]);
    let u0 = to_dv(m0.xy, r);
    let e1 = to_dv(m1.xy, r) - u0;
    let e2 = to_dv(m2.xy, r) - u0;
    let det = e1.x * e2.y - e1.y * e2.x;
    if det * det <= EDGE_ON * dot(e1, e1) * dot(e2, e2) || det == 0.0 {
        return vec4<f32>(0.0);
    }
    let d1 = m1.z - m0.z;
    let d2 = m2.z - m0.z;
    let g = vec2<f32>(d1 * e2.y - d2 * e1.y, e1.x * d2 - e2.x * d1) / det;
    return vec4<f32>(g, m0.z - dot(g, u0), 1.0);
}

// The vertex stage's work (the entry point is depth_vs.wgsl's or depth_clip.wgsl's).
fn depth_vertex(vi: u32) -> VsOut {
    var v: Vertex;
    var piece = vec4<u32>(vi / 3u, 0u, 0xffffu, 0xffff0000u);
    if SUBDIVIDED {
        piece = piece_at(vi / 3u);
        v = piece_vertex(piece, vi % 3u);
    } else {
        v = vertices[vi];
    }
    let r = dv_rect();
    var o: VsOut;
    o.clip = warped_clip(v.pos, r);
    o.uv = v.uv;
    o.material = v.material;
    o.u = vec2<f32>(0.0);
    o.plane = vec4<f32>(0.0);
    o.zrange = vec2<f32>(0.0, 1.0);
    o.side = hemisphere_side(wp, v.pos);
    if EXACT_DEPTH {
        let a = base_clip(wp, v.pos);
        o.u = to_dv(clip_to_map(a).xy, r);
        // the whole triangle's plane (better conditioned than a small piece's), else the piece's
        let t = piece.x;
        if PARABOLOID {
            o.plane = paraboloid_plane(t);
            o.zrange = vec2<f32>(abs(o.plane.w), piece_zrange(piece).y);
            return o;
        }
        var plane = depth_plane(array<vec4<f32>, 3>(base_clip(wp, vertices[3u * t].pos), base_clip(wp, vertices[3u * t + 1u].pos),
            base_clip(wp, vertices[3u * t + 2u].pos)), r);
        let pc = array<vec4<f32>, 3>(base_clip(wp, bary_pos(t, unpack2x16unorm(piece.y))), base_clip(wp, bary_pos(t, unpack2x16unorm(piece.z))),
            base_clip(wp, bary_pos(t, unpack2x16unorm(piece.w))));
        if plane.w == 0.0 {
            plane = depth_plane(pc, r);
        }
        if flat_piece(wp, pc) {
            // the interpolated depth is off by less than `exact_tol`: no inversion
            // (depth_exact.wgsl; a layered subdivision draws such pieces without this stage)
            plane = vec4<f32>(0.0);
        }
        o.plane = plane;
        if plane.w != 0.0 {
            var z = vec3<f32>(clip_to_map(pc[0]).z, clip_to_map(pc[1]).z, clip_to_map(pc[2]).z);
            if wp.depth_clamp > 0.5 {
                // the whole triangle's corners: a piece's chords cover up to `subdiv` warped
                // texels of its curved neighbours, whose plane depth lies outside its own range
                z = vec3<f32>(clip_to_map(base_clip(wp, vertices[3u * t].pos)).z,
                    clip_to_map(base_clip(wp, vertices[3u * t + 1u].pos)).z, clip_to_map(base_clip(wp, vertices[3u * t + 2u].pos)).z);
            }
            o.zrange = vec2<f32>(min(min(z.x, z.y), z.z), max(max(z.x, z.y), z.z));
        }
    }
    return o;
}

// Paraboloid exact depth: the triangle's plane dot(nrm, x) = c in the hemisphere's (scaled)
// light space as (nrm, c); a point of the plane seen in direction n lies at depth c / dot(nrm, n)
// (depth_exact.wgsl). c = 0 (plane through the light: seen edge-on) marks it invalid.
fn paraboloid_plane(t: u32) -> vec4<f32> {
    let a0 = (wp.light_view_proj * vec4<f32>(vertices[3u * t].pos, 1.0)).xyz;
    let a1 = (wp.light_view_proj * vec4<f32>(vertices[3u * t + 1u].pos, 1.0)).xyz;
    let a2 = (wp.light_view_proj * vec4<f32>(vertices[3u * t + 2u].pos, 1.0)).xyz;
    let nrm = cross(a1 - a0, a2 - a0);
    let len = length(nrm);
    if len <= 1e-20 {
        return vec4<f32>(0.0);
    }
    return vec4<f32>(nrm / len, dot(nrm / len, a0));
}

// Depth range of a piece's corners. Paraboloid depth is the distance: on a flat piece the
// largest lies at a corner, the smallest possibly inside (the foot of the perpendicular from the
// light), so the caller takes the plane's distance |c| as the low end.
fn piece_zrange(piece: vec4<u32>) -> vec2<f32> {
    let t = piece.x;
    let z0 = clip_to_map(base_clip(wp, bary_pos(t, unpack2x16unorm(piece.y)))).z;
    let z1 = clip_to_map(base_clip(wp, bary_pos(t, unpack2x16unorm(piece.z)))).z;
    let z2 = clip_to_map(base_clip(wp, bary_pos(t, unpack2x16unorm(piece.w)))).z;
    return vec2<f32>(0.0, max(max(z0, z1), z2));
}

// sin^2 of the angle between the projected edges below which a triangle counts as edge-on.
const EDGE_ON: f32 = 1e-6;
