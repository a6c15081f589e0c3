// min-sm reduction of the view samples projected into the light's fixed frame (directional:
// orthographic plane x, y; spot: image plane x/d, y/d), d = depth along the light.
// `bounds`: bounding box of the plane coordinates, greatest depth and sample count
// (workgroup-reduced, then one global atomic per word). `rows`: per band of `grid` rows of that
// box, the least and greatest x. One-pass mode (mode.w = 1): `bounds` also fills the bands,
// over the previous frame's y range (`prev`), with two overflow slots (grid: below, grid + 1:
// above). Values are order-preserving u32 codes (calipers/frustum.rs encode_max / encode_min),
// all combined with atomicMax over a buffer cleared to 0 (= empty).

struct MsfReduce {
    // world -> light view (right-handed, looking along -z)
    frame_view: mat4x4<f32>,
    // x: 1 if perspective, y: grid (bands), z: pixels per thread along a screen row,
    // w: 1 = one pass, bands over `prev`
    mode: vec4<u32>,
    // x, y: the y range the bands divide in one-pass mode
    prev: vec4<f32>,
}

@group(0) @binding(6) var<uniform> msf: MsfReduce;
// [0] min x, [1] max x, [2] min y, [3] max y, [4] max depth, [5] count, [6..8) unused,
// then (min x, max x) per band, then the two overflow slots
@group(0) @binding(7) var<storage, read_write> red: array<atomic<u32>>;

const HEADER: u32 = 8u;

var<workgroup> wg: array<atomic<u32>, 6>;

fn code_max(x: f32) -> u32 {
    let b = bitcast<u32>(x);
    if (b & 0x80000000u) != 0u {
        return ~b;
    }
    return b | 0x80000000u;
}

fn code_min(x: f32) -> u32 {
    return ~code_max(x);
}

fn decode_max(u: u32) -> f32 {
    if (u & 0x80000000u) != 0u {
        return bitcast<f32>(u & 0x7fffffffu);
    }
    return bitcast<f32>(~u);
}

// (plane x, plane y, depth)
fn project(p: vec3<f32>) -> vec3<f32> {
    let q = (msf.frame_view * vec4<f32>(p, 1.0)).xyz;
    let d = -q.z;
    if msf.mode.x == 1u {
        return vec3<f32>(q.xy / d, d);
    }
    return vec3<f32>(q.xy, d);
}

// Each thread walks `run` pixels of one screen row (thread x covers x = id.x * run ..), keeping
// its extremes in registers: neighbouring pixels mostly share a band, so few atomics are issued.
// Only the mask and the position are read (not view.wgsl's load_sample, which also loads the
// normal and writes the visibility of skipped pixels): half the G-buffer traffic.
fn load_position(id: vec3<u32>, k: u32, p: ptr<function, vec3<f32>>) -> bool {
    let x = id.x * msf.mode.z + k;
    if x >= frame.size.x || id.y >= frame.size.y || mask[id.y * frame.size.x + x] == 0u {
        return false;
    }
    *p = textureLoad(g_position, vec2<u32>(x, id.y), 0).xyz;
    return true;
}

// The slot of plane y (band_of in calipers/frustum.rs).
fn band_of(y: f32, range: vec2<f32>, overflow: bool) -> u32 {
    let grid = msf.mode.y;
    if overflow && y < range.x {
        return grid;
    }
    if overflow && y > range.y {
        return grid + 1u;
    }
    let t = (y - range.x) / max(range.y - range.x, 1e-30);
    return min(u32(max(t, 0.0) * f32(grid)), grid - 1u);
}

fn flush(band: u32, lo: f32, hi: f32) {
    atomicMax(&red[HEADER + 2u * band], code_min(lo));
    atomicMax(&red[HEADER + 2u * band + 1u], code_max(hi));
}

// Per-band x extremes of this thread's run, flushed when the band changes.
struct BandRun {
    band: u32,
    lo: f32,
    hi: f32,
}

fn add_to_run(r: ptr<function, BandRun>, band: u32, x: f32) {
    if band != (*r).band {
        if (*r).band != 0xffffffffu {
            flush((*r).band, (*r).lo, (*r).hi);
        }
        *r = BandRun(band, x, x);
    } else {
        (*r).lo = min((*r).lo, x);
        (*r).hi = max((*r).hi, x);
    }
}

fn end_run(r: ptr<function, BandRun>) {
    if (*r).band != 0xffffffffu {
        flush((*r).band, (*r).lo, (*r).hi);
    }
}

@compute @workgroup_size(8, 8)
fn bounds(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    var lo = vec3<f32>(3.4e38);
    var hi = vec3<f32>(-3.4e38);
    var n = 0u;
    let one_pass = msf.mode.w == 1u;
    var run = BandRun(0xffffffffu, 0.0, 0.0);
    for (var k = 0u; k < msf.mode.z; k++) {
        var p: vec3<f32>;
        if load_position(id, k, &p) {
            let q = project(p);
            lo = min(lo, q);
            hi = max(hi, q);
            n += 1u;
            if one_pass {
                add_to_run(&run, band_of(q.y, msf.prev.xy, true), q.x);
            }
        }
    }
    end_run(&run);
    if n > 0u {
        atomicMax(&wg[0], code_min(lo.x));
        atomicMax(&wg[1], code_max(hi.x));
        atomicMax(&wg[2], code_min(lo.y));
        atomicMax(&wg[3], code_max(hi.y));
        atomicMax(&wg[4], code_max(hi.z));
        atomicAdd(&wg[5], n);
    }
    workgroupBarrier();
    if li == 0u {
        let total = atomicLoad(&wg[5]);
        if total > 0u {
            for (var k = 0u; k < 5u; k++) {
                atomicMax(&red[k], atomicLoad(&wg[k]));
            }
            atomicAdd(&red[5], total);
        }
    }
}

@compute @workgroup_size(8, 8)
fn rows(@builtin(global_invocation_id) id: vec3<u32>) {
    let range = vec2<f32>(decode_max(~atomicLoad(&red[2])), decode_max(atomicLoad(&red[3])));
    var run = BandRun(0xffffffffu, 0.0, 0.0);
    for (var k = 0u; k < msf.mode.z; k++) {
        var p: vec3<f32>;
        if load_position(id, k, &p) {
            let q = project(p);
            add_to_run(&run, band_of(q.y, range, false), q.x);
        }
    }
    end_run(&run);
}
