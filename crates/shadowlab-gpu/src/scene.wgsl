// Scene data, bind group 1 (scene_gpu.rs): triangles as vertex triples, materials, packed
// RGBA8 texels of all textures, and the BVH. Triangles `scene_info.dynamic_first..` move
// (rewritten every frame); their previous-frame vertices follow all the current ones in
// `vertices` (3 * triangle_count onwards, one storage buffer fewer); the BVH arrays
// hold the static tree (root 0, absent when dynamic_first == 0) and then the dynamic tree
// (root `scene_info.dynamic_root`, absent when dynamic_first == triangle_count).

struct SceneInfo {
    triangle_count: u32,
    dynamic_first: u32,
    dynamic_root: u32,
    _pad: u32,
}

struct BvhNode {
    min: vec3<f32>,
    prim_count: u32,
    max: vec3<f32>,
    first_index: u32,
}

@group(1) @binding(0) var<storage, read> vertices: array<Vertex>;
@group(1) @binding(1) var<storage, read> materials: array<Material>;
@group(1) @binding(2) var<storage, read> texels: array<u32>;
@group(1) @binding(3) var<storage, read> bvh_nodes: array<BvhNode>;
@group(1) @binding(4) var<storage, read> prim_indices: array<u32>;
@group(1) @binding(5) var<uniform> scene_info: SceneInfo;

// World position of vertex `vi` in the previous frame (moving objects; others stand still).
fn previous_position(vi: u32) -> vec3<f32> {
    let first = 3u * scene_info.dynamic_first;
    if vi >= first {
        return vertices[3u * scene_info.triangle_count + vi - first].pos;
    }
    return vertices[vi].pos;
}

// Base colour times texture (RGBA, linear).
fn material_color(m: Material, uv: vec2<f32>) -> vec4<f32> {
    var c = m.base_color;
    if (m.flags & MAT_TEXTURED) != 0u {
        c = c * unpack4x8unorm(texels[m.tex_offset + texel_index(m.tex_width, m.tex_height, uv)]);
    }
    return c;
}

// True where an alpha-tested material is cut out (neither visible nor casting shadows).
fn cut_out(m: Material, uv: vec2<f32>) -> bool {
    if (m.flags & MAT_MASKED) == 0u {
        return false;
    }
    return material_color(m, uv).a < m.alpha_cutoff;
}
