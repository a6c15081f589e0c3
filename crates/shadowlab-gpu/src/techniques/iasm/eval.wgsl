// IASM evaluation (thesis 3.6): the offset sample (normal offset and constant bias along the
// light, in texels of the tile the sample lies in) is projected with the whole-square matrix
// S0 to find its tile and texel (equations 3.2-3.5) and compared with the stored depth of that
// tile's frustum. Samples outside the square or in an empty tile are lit. Counts view samples
// per buffer texel for the sampling statistics.

@group(0) @binding(6) var<uniform> ip: IasmParams;
@group(0) @binding(7) var<storage, read> shadow: array<u32>;
@group(0) @binding(8) var<storage, read_write> counts: array<atomic<u32>>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    var s: Sample;
    if !load_sample(id, &s) {
        return;
    }
    let p = s.p;
    let uv0 = buffer_uv(ip, p);
    if !inside(uv0) {
        visibility[s.i] = 1.0;
        return;
    }
    let t0 = tile_of(uv0);
    let r0 = tile_res(ip, t0);
    if r0 == 0u {
        visibility[s.i] = 1.0;
        return;
    }
    atomicAdd(&counts[buffer_index(ip, uv0)], 1u);
    let texel = ip.dir.w / (TILES * f32(r0));
    let l = -ip.dir.xyz;
    let q = p + s.n * (ip.imp.w * texel) + l * (ip.imp.z * texel);
    let uv = buffer_uv(ip, q);
    let t = tile_of(uv);
    if !inside(uv) || tile_res(ip, t) == 0u {
        visibility[s.i] = 1.0;
        return;
    }
    let near = ip.near[t / 4u][t % 4u];
    let far = ip.far[t / 4u][t % 4u];
    let z = (dot(q, ip.dir.xyz) - near) / max(far - near, 1e-6);
    let stored = 1.0 - bitcast<f32>(shadow[buffer_index(ip, uv)]);
    visibility[s.i] = select(0.0, 1.0, z <= stored);
}
