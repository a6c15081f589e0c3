// The viewer's picture: the left and right halves of a split screen, each from a packed RGBA8
// colour buffer (shaded, error) or a visibility buffer (grey), with a divider between them.

struct Params {
    width: u32,
    height: u32,
    // first column of the right side (width: no split)
    divider: u32,
    // what each side shows: 0 colour, 1 visibility
    left_kind: u32,
    right_kind: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(0) @binding(0) var<uniform> p: Params;
@group(0) @binding(1) var<storage, read> left_color: array<u32>;
@group(0) @binding(2) var<storage, read> left_vis: array<f32>;
@group(0) @binding(3) var<storage, read> right_color: array<u32>;
@group(0) @binding(4) var<storage, read> right_vis: array<f32>;
@group(0) @binding(5) var<storage, read> mask: array<u32>;
@group(0) @binding(6) var out: texture_storage_2d<rgba8unorm, write>;

fn side(kind: u32, color: u32, vis: f32, evaluated: u32) -> vec4<f32> {
    if kind == 1u {
        if evaluated == 0u {
            // not evaluated for this light (sky, back-facing, outside a spot cone)
            return vec4<f32>(0.06, 0.07, 0.16, 1.0);
        }
        return vec4<f32>(vec3<f32>(vis), 1.0);
    }
    return unpack4x8unorm(color);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= p.width || id.y >= p.height {
        return;
    }
    let i = id.y * p.width + id.x;
    var c: vec4<f32>;
    if id.x < p.divider {
        c = side(p.left_kind, left_color[i], left_vis[i], mask[i]);
    } else {
        c = side(p.right_kind, right_color[i], right_vis[i], mask[i]);
    }
    if p.divider < p.width && (id.x == p.divider || id.x + 1u == p.divider) {
        c = vec4<f32>(1.0, 0.85, 0.2, 1.0);
    }
    textureStore(out, vec2<i32>(id.xy), c);
}
