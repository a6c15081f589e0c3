// IASM frame parameters (mod.rs `IasmParams`) and the lookups shared by analysis.wgsl,
// eval.wgsl, eval_atlas.wgsl and probe.wgsl. The functions read the module-scope uniform `ip`
// that each of those files declares at its own binding (passing the 336-byte struct by value
// made every call copy it: evaluation 300-790 ms instead of 75-100 ms at 1024x1024 on lavapipe).
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
    // store=atlas: per-tile top-left corner in the atlas, x | y << 16
    slot: array<vec4<u32>, 4>,
}

const TILES: f32 = 4.0;

fn buffer_uv(p: vec3<f32>) -> vec2<f32> {
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

fn tile_res(t: u32) -> u32 {
    return ip.res[t / 4u][t % 4u];
}

// Texel p_b of uv inside its tile (equation 3.4, with the tile corner at p_t / n; see iasm.rs
// `texel_index`).
fn tile_texel(uv: vec2<f32>) -> vec2<u32> {
    let t = tile_of(uv);
    let pt = clamp(floor(uv * TILES), vec2<f32>(0.0), vec2<f32>(TILES - 1.0));
    let rf = f32(tile_res(t));
    return vec2<u32>(clamp(floor((uv * TILES - pt) * rf), vec2<f32>(0.0), vec2<f32>(rf - 1.0)));
}

// Equation 3.5: index in the linear buffer.
fn buffer_index(uv: vec2<f32>) -> u32 {
    let t = tile_of(uv);
    let pb = tile_texel(uv);
    return ip.off[t / 4u][t % 4u] + pb.x + pb.y * tile_res(t);
}

// Where an evaluated sample looks its shadow up. `ok` false: outside the square or in an empty
// tile (lit). Bias and normal offset are in texels of the tile the sample itself lies in.
struct Lookup {
    ok: bool,
    // buffer coordinates of the offset sample, its tile, its depth in that tile's frustum
    uv: vec2<f32>,
    t: u32,
    z: f32,
    // buffer coordinates of the sample itself (sampling statistics)
    uv0: vec2<f32>,
}

fn lookup(p: vec3<f32>, n: vec3<f32>) -> Lookup {
    var o: Lookup;
    o.ok = false;
    o.uv0 = buffer_uv(p);
    if !inside(o.uv0) {
        return o;
    }
    let r0 = tile_res(tile_of(o.uv0));
    if r0 == 0u {
        return o;
    }
    let texel = ip.dir.w / (TILES * f32(r0));
    let q = p + n * (ip.imp.w * texel) - ip.dir.xyz * (ip.imp.z * texel);
    o.uv = buffer_uv(q);
    o.t = tile_of(o.uv);
    if !inside(o.uv) || tile_res(o.t) == 0u {
        return o;
    }
    let near = ip.near[o.t / 4u][o.t % 4u];
    let far = ip.far[o.t / 4u][o.t % 4u];
    o.z = (dot(q, ip.dir.xyz) - near) / max(far - near, 1e-6);
    o.ok = true;
    return o;
}
