// IASM frame parameters (mod.rs `IasmParams`), shared by analysis.wgsl and eval.wgsl.
// Light space: x = right, y = up, depth = dot(p, dir) (larger = farther from the light).
// Buffer coordinates uv: u along x, v downwards (v = 0 at the top = largest y); tile (tx, ty)
// has index ty * 4 + tx (thesis equations 3.2, 3.3).
struct IasmParams {
    // xyz: right, w: square origin x
    right: vec4<f32>,
    // xyz: up, w: square origin y
    up: vec4<f32>,
    // xyz: light direction, w: square side (world units)
    dir: vec4<f32>,
    // x: m, y: k (equation 3.1), z: constant bias, w: normal offset (texels of the tile)
    imp: vec4<f32>,
    // per-tile resolution r_t (0 = empty tile, not rendered)
    res: array<vec4<u32>, 4>,
    // per-tile accumulated offset sum_{i<t} r_i^2
    off: array<vec4<u32>, 4>,
    // per-tile near / far light depth of the tile frustum
    near: array<vec4<f32>, 4>,
    far: array<vec4<f32>, 4>,
}

const TILES: f32 = 4.0;

fn buffer_uv(ip: IasmParams, p: vec3<f32>) -> vec2<f32> {
    let s = (vec2<f32>(dot(p, ip.right.xyz), dot(p, ip.up.xyz)) - vec2<f32>(ip.right.w, ip.up.w)) / ip.dir.w;
    return vec2<f32>(s.x, 1.0 - s.y);
}

fn inside(uv: vec2<f32>) -> bool {
    return all(uv >= vec2<f32>(0.0)) && all(uv < vec2<f32>(1.0));
}

// Equations 3.2, 3.3.
fn tile_of(uv: vec2<f32>) -> u32 {
    let pt = clamp(floor(uv * TILES), vec2<f32>(0.0), vec2<f32>(TILES - 1.0));
    return u32(pt.y) * 4u + u32(pt.x);
}

fn tile_res(ip: IasmParams, t: u32) -> u32 {
    return ip.res[t / 4u][t % 4u];
}

// Equations 3.4, 3.5 (with the tile corner at p_t / n; see iasm.rs `texel_index`).
fn buffer_index(ip: IasmParams, uv: vec2<f32>) -> u32 {
    let t = tile_of(uv);
    let pt = clamp(floor(uv * TILES), vec2<f32>(0.0), vec2<f32>(TILES - 1.0));
    let r = tile_res(ip, t);
    let rf = f32(r);
    let pb = clamp(floor((uv * TILES - pt) * rf), vec2<f32>(0.0), vec2<f32>(rf - 1.0));
    return ip.off[t / 4u][t % 4u] + u32(pb.x) + u32(pb.y) * r;
}
