// Clipmap pages of `virtual` (shadowlab_core::techniques::virtual_sm, whose functions these
// mirror operation for operation so that marking on the GPU and the CPU agree): the level a
// sample asks for, global texel coordinates, pages and their page-table slots.

struct VirtualParams {
    // xyz: light-space x axis; w: world size of a level-0 texel
    right: vec4<f32>,
    // xyz: light-space y axis; w: level-0 texels per world unit
    up: vec4<f32>,
    // xyz: the light's travel direction; w: light depth of depth 0
    dir: vec4<f32>,
    // x: light depth of depth 1, y: pixel angle (world size of a pixel per unit of distance),
    // z: 2^resolution_bias, w: texels marked around a sample (PCF reach + normal offset + 1)
    view: vec4<f32>,
    // x: levels, y: pages per window side N, z: page side P (texels), w: atlas columns (slots)
    dims: vec4<u32>,
    // x: constant bias, y: slope-scaled bias, z: normal offset (texels), w: max slope
    bias: vec4<f32>,
    // x: PCF kernel width; yzw unused
    pcf: vec4<u32>,
    // xy: each level's window origin (global page coordinates)
    origins: array<vec4<i32>, 24>,
}

// The level of a sample at p: the smallest L with t0 2^L >= footprint 2^bias (level_for).
fn choose_level(p: vec3<f32>) -> u32 {
    let f = length(p - frame.camera_pos.xyz) * vp.view.y * vp.view.z;
    var l = 0u;
    var t = vp.right.w;
    while l + 1u < vp.dims.x && t < f {
        t *= 2.0;
        l++;
    }
    return l;
}

// Texels per world unit at level k.
fn inv_texel(k: u32) -> f32 {
    var s = vp.up.w;
    for (var i = 0u; i < k; i++) {
        s *= 0.5;
    }
    return s;
}

fn texel_coords(k: u32, p: vec3<f32>) -> vec2<f32> {
    let s = inv_texel(k);
    return vec2<f32>(dot(p, vp.right.xyz) * s, -dot(p, vp.up.xyz) * s);
}

fn light_depth(p: vec3<f32>) -> f32 {
    return (dot(p, vp.dir.xyz) - vp.dir.w) / (vp.view.x - vp.dir.w);
}

fn page_of(g: vec2<f32>) -> vec2<i32> {
    return vec2<i32>(floor(g * (1.0 / f32(vp.dims.z))));
}

fn in_window(k: u32, pg: vec2<i32>) -> bool {
    let d = pg - vp.origins[k].xy;
    let n = i32(vp.dims.y);
    return all(d >= vec2<i32>(0)) && all(d < vec2<i32>(n));
}

fn wrap(a: i32, n: i32) -> i32 {
    return ((a % n) + n) % n;
}

fn table_index(k: u32, pg: vec2<i32>) -> u32 {
    let n = i32(vp.dims.y);
    return u32((i32(k) * n + wrap(pg.y, n)) * n + wrap(pg.x, n));
}
