// Clipmap pages of `virtual` (shadowlab_core::techniques::virtual_sm, whose functions these
// mirror operation for operation so that marking on the GPU and the CPU agree): the level a
// sample asks for, global texel coordinates, pages and their page-table slots. pcf.y picks the
// projection: 0 = orthographic clipmap (directional), 1 = the spot's perspective mip chain
// (virtual_sm/spot.rs: light coordinates in [0, 2], level k's window = the whole level).

struct VirtualParams {
    // xyz: light-space x axis; w: world size of a level-0 texel (spot: per unit of light depth)
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
    // x: PCF kernel width; y: projection (0 orthographic, 1 spot); zw unused
    pcf: vec4<u32>,
    // spot: xyz the light's position, w tan(half-angle of the cone); unused otherwise
    spot: vec4<f32>,
    // xy: each level's window origin (global page coordinates)
    origins: array<vec4<i32>, 24>,
}

fn is_spot() -> bool {
    return vp.pcf.y == 1u;
}

// Light-view depth of p from a spot light.
fn spot_z(p: vec3<f32>) -> f32 {
    return dot(p - vp.spot.xyz, vp.dir.xyz);
}

// World size of a level-0 texel at p (Clipmap::texel0_at).
fn texel0_at(p: vec3<f32>) -> f32 {
    if is_spot() {
        return vp.right.w * spot_z(p);
    }
    return vp.right.w;
}

// World size of a level-k texel at p.
fn texel_world(k: u32, p: vec3<f32>) -> f32 {
    if is_spot() {
        return texel0_at(p) * exp2(f32(k));
    }
    return 1.0 / inv_texel(k);
}

// The level of a sample at p: the smallest L with t0 2^L >= footprint 2^bias (level_for).
fn choose_level(p: vec3<f32>) -> u32 {
    let f = length(p - frame.camera_pos.xyz) * vp.view.y * vp.view.z;
    var l = 0u;
    var t = texel0_at(p);
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

// Level-0 light coordinates before the texel scale (Clipmap::light_coords).
fn light_coords(p: vec3<f32>) -> vec2<f32> {
    if is_spot() {
        let v = p - vp.spot.xyz;
        let s = dot(v, vp.dir.xyz) * vp.spot.w;
        return vec2<f32>(dot(v, vp.right.xyz) / s + 1.0, 1.0 - dot(v, vp.up.xyz) / s);
    }
    return vec2<f32>(dot(p, vp.right.xyz), -dot(p, vp.up.xyz));
}

fn texel_coords(k: u32, p: vec3<f32>) -> vec2<f32> {
    return light_coords(p) * inv_texel(k);
}

// Depth in [0, 1], 0 near the light: linear (orthographic) or post-projective (spot).
fn light_depth(p: vec3<f32>) -> f32 {
    let n = vp.dir.w;
    let f = vp.view.x;
    if is_spot() {
        let z = spot_z(p);
        return ((z - n) / (f - n)) * (f / z);
    }
    return (dot(p, vp.dir.xyz) - n) / (f - n);
}

fn page_of(g: vec2<f32>) -> vec2<i32> {
    return vec2<i32>(floor(g * (1.0 / f32(vp.dims.z))));
}

// Pages a side of level k's window (Clipmap::side).
fn side(k: u32) -> i32 {
    let n = i32(vp.dims.y);
    if is_spot() {
        return max(n >> k, 1);
    }
    return n;
}

// The page under g at level k, clamped to a spot map (Clipmap::page_at).
fn page_at(k: u32, g: vec2<f32>) -> vec2<i32> {
    let pg = page_of(g);
    if is_spot() {
        return clamp(pg, vec2<i32>(0), vec2<i32>(side(k) - 1));
    }
    return pg;
}

fn in_window(k: u32, pg: vec2<i32>) -> bool {
    let d = pg - vp.origins[k].xy;
    let n = side(k);
    return all(d >= vec2<i32>(0)) && all(d < vec2<i32>(n));
}

fn wrap(a: i32, n: i32) -> i32 {
    return ((a % n) + n) % n;
}

fn table_index(k: u32, pg: vec2<i32>) -> u32 {
    let n = i32(vp.dims.y);
    return u32((i32(k) * n + wrap(pg.y, n)) * n + wrap(pg.x, n));
}
