// sv volume geometry (vertex only; the stencil ops do the counting). Orientation: every face's
// winding normal points out of its volume, so front faces (counter-clockwise on screen) enter a
// volume and back faces leave it; z-fail: depth-failing back faces increment, front faces
// decrement (mod.rs).
//  - `vs_sides`: side records from the silhouette pass: the quad a, b, b_inf, a_inf of an edge
//    (reversed for negative multiplicity); towards the point at infinity a directional light's
//    a_inf = b_inf, so one triangle.
//  - `vs_caps_ccw` / `vs_caps_cw`: the scene triangles in their own vertex order (the light cap
//    is rasterised exactly like the G-buffer: the same expression on the same vertices). Drawn
//    once with counter-clockwise and once with clockwise front faces: the first draw emits the
//    light caps of triangles facing the light and the dark caps of those facing away, the second
//    the reverse; all other triangles collapse to a point.


struct Edge {
    a: u32,
    b: u32,
    first: u32,
    count: u32,
}

const REVERSED: u32 = 0x80000000u;

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<uniform> light: LightU;
@group(0) @binding(2) var<uniform> sv: SvParams;
@group(0) @binding(3) var<storage, read> edges: array<Edge>;
@group(0) @binding(4) var<storage, read> facing: array<i32>;
@group(0) @binding(5) var<storage, read> sides: array<u32>;

// A point every collapsed triangle's three vertices share (zero area: no fragments).
const NOWHERE: vec4<f32> = vec4<f32>(0.0, 0.0, 0.5, 1.0);

fn at(p: vec3<f32>) -> vec4<f32> {
    return frame.view_proj * vec4<f32>(p, 1.0);
}

// p pushed away from the light: to the point at infinity (w = 0), or by `extrude.x`.
fn extruded(p: vec3<f32>) -> vec4<f32> {
    var d = light.direction.xyz;
    if light.kind != LIGHT_DIRECTIONAL {
        d = p - light.position.xyz;
    }
    if sv.extrude <= 0.0 {
        return frame.view_proj * vec4<f32>(d, 0.0);
    }
    return at(p + normalize(d) * sv.extrude);
}

@vertex
fn vs_sides(@builtin(vertex_index) vi: u32) -> @builtin(position) vec4<f32> {
    let vps = sv.side_vertices;
    let r = sides[vi / vps];
    let e = edges[r & ~REVERSED];
    var a = vertices[e.a].pos;
    var b = vertices[e.b].pos;
    if (r & REVERSED) != 0u {
        let t = a;
        a = b;
        b = t;
    }
    switch vi % vps {
        case 0u: {
            return at(a);
        }
        case 1u, 4u: {
            return extruded(a);
        }
        case 2u, 3u: {
            return at(b);
        }
        default: {
            return extruded(b);
        }
    }
}

fn cap(vi: u32, s: i32) -> vec4<f32> {
    let f = facing[vi / 3u];
    if f == s {
        return frame.view_proj * vec4<f32>(vertices[vi].pos, 1.0);
    }
    // dark caps: at a directional light's point at infinity they have no area
    if f == -s && sv.side_vertices == 6u {
        return extruded(vertices[vi].pos);
    }
    return NOWHERE;
}

@vertex
fn vs_caps_ccw(@builtin(vertex_index) vi: u32) -> @builtin(position) vec4<f32> {
    return cap(vi, 1);
}

@vertex
fn vs_caps_cw(@builtin(vertex_index) vi: u32) -> @builtin(position) vec4<f32> {
    return cap(vi, -1);
}
