// Leak tracing, per pixel (seed 004 sections 3-3.4): the map level (cascade) holding the
// pixel's view depth (beyond the last hybrid level: a ray, section 3.3), its single-depth
// filterable map
// (`*_visibility_gather` of filtered/moments.wgsl: 2x2 gathered depths, moments rebuilt here)
// of the static map, min-combined with the dynamic map; then, by technique,
//   lt:         LTT (eq. 3), reprojection into last frame's temporal mask, ER (eq. 6) and RR
//               (eq. 8) over a jittered 2x2 (or full 3x3) neighbourhood (section 3.1.3);
//   ltt:        LTT alone;
//   hybrid-pcf: a ray where the 2x2 hard tests of the plain depth map disagree (AMD FidelityFX).
// Pixels that need a ray are appended to `list` (list[0] = count); the others get the map's
// value (snapped to 0/1 where RR removed the ray). Writes this frame's mask bits (ST, LTT; RS
// follows in trace.wgsl) and this pixel's depth/normal for next frame's reprojection test.
// Mirrors shadowlab_core::leak.

// One map level: a cascade (orthographic) or the whole map (spot: perspective).
struct Level {
    view_proj: mat4x4<f32>,
    // x: world texel size (orthographic) or per unit of light depth (perspective),
    // y, z: the view depths it serves (z: 1e30 for the only level), w: unused
    info: vec4<f32>,
}

struct LtParams {
    // directional: up to 3 cascades; spot: 1; point: the 6 cube faces (+x, -x, +y, -y, +z, -z)
    levels: array<Level, 6>,
    // hybrid levels (map layers)
    layers: f32,
    // 1 if perspective
    perspective: f32,
    // map side (texels)
    res: f32,
    // 1 / far
    inv_far: f32,
    // 0 lt, 1 ltt, 2 hybrid-pcf
    technique: u32,
    // 0 vsm, 1 esm, 2 evsm, 3 msm
    base: u32,
    // frame index
    frame: u32,
    // FLAG_*
    flags: u32,
    min_variance: f32,
    esm_c: f32,
    evsm_c_pos: f32,
    evsm_c_neg: f32,
    moment_bias: f32,
    // texels
    depth_bias: f32,
    // texels
    normal_offset: f32,
    // LTT: a ray where eps < s < 1 - eps
    eps: f32,
    // relative depth tolerance and min normal cosine of the reprojection test
    depth_tol: f32,
    normal_cos: f32,
    // mask bits per pixel
    mask_bits: f32,
    pad0: f32,
}

const FLAG_RR: u32 = 1u;
const FLAG_FULL: u32 = 2u;
const FLAG_FORCE_ALL: u32 = 4u;
const FLAG_HISTORY_TEST: u32 = 8u;
const FLAG_DYNAMIC: u32 = 16u;
const FLAG_HAS_HISTORY: u32 = 32u;
// The uniform's `technique`, `base`, `perspective` and its FLAG_POINT bit (uniforms.rs), fixed at pipeline creation
// (classify.rs): lavapipe runs every side of a branch on a value it reads from a buffer.
override TECHNIQUE: u32;
override BASE: u32;
override PERSPECTIVE: bool;
override POINT: bool;

const BIT_ST: u32 = 1u;
const BIT_LTT: u32 = 2u;
const BIT_RS: u32 = 4u;

@group(0) @binding(6) var<uniform> lp: LtParams;
@group(0) @binding(7) var static_map: texture_2d_array<f32>;
@group(0) @binding(8) var dynamic_map: texture_2d_array<f32>;
@group(0) @binding(9) var gather_sampler: sampler;
@group(0) @binding(10) var g_motion: texture_2d<f32>;
@group(0) @binding(11) var<storage, read> prev_mask: array<u32>;
@group(0) @binding(12) var<storage, read_write> cur_mask: array<atomic<u32>>;
@group(0) @binding(13) var<storage, read> prev_history: array<vec2<f32>>;
@group(0) @binding(14) var<storage, read_write> cur_history: array<vec2<f32>>;
@group(0) @binding(15) var<storage, read_write> list: array<atomic<u32>>;

fn to_map(level: u32, p: vec3<f32>) -> vec3<f32> {
    let c = lp.levels[level].view_proj * vec4<f32>(p, 1.0);
    let ndc = c.xyz / c.w;
    let depth = select(c.z, c.w * lp.inv_far, PERSPECTIVE);
    return vec3<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5, depth);
}

// Cube face of direction d (shadowlab_core::leak::cube_face): 2 * dominant axis + negative.
fn cube_face(d: vec3<f32>) -> u32 {
    let a = abs(d);
    if a.x >= a.y && a.x >= a.z {
        return select(0u, 1u, d.x < 0.0);
    }
    if a.y >= a.z {
        return select(2u, 3u, d.y < 0.0);
    }
    return select(4u, 5u, d.z < 0.0);
}

fn base_visibility(z: vec4<f32>, w: vec4<f32>, d: f32) -> f32 {
    return visibility_gather_of(BASE, z, w, d, vec4<f32>(lp.min_variance, lp.esm_c, lp.evsm_c_pos, lp.evsm_c_neg), lp.moment_bias);
}

// Mask bits of pixel i (one light in the low 3 bits of a `history.z`-bit texel, packed in words).
fn mask_load(i: u32) -> u32 {
    let bits = u32(lp.mask_bits);
    let per = 32u / bits;
    return (prev_mask[i / per] >> ((i % per) * bits)) & 7u;
}

fn mask_or(i: u32, b: u32) {
    let bits = u32(lp.mask_bits);
    let per = 32u / bits;
    atomicOr(&cur_mask[i / per], b << ((i % per) * bits));
}

fn expand(m: u32, st: bool) -> bool {
    let m_st = (m & BIT_ST) != 0u;
    let m_ltt = (m & BIT_LTT) != 0u;
    let m_rs = (m & BIT_RS) != 0u;
    return (m_ltt && (m_rs != st)) || (m_st != st);
}

fn remove(m: u32, st: bool) -> bool {
    let m_st = (m & BIT_ST) != 0u;
    let m_ltt = (m & BIT_LTT) != 0u;
    let m_rs = (m & BIT_RS) != 0u;
    return (st == m_st) && (!m_ltt || st == m_rs);
}

fn pack_normal(n: vec3<f32>) -> f32 {
    return bitcast<f32>(pack4x8snorm(vec4<f32>(n, 0.0)));
}

// Last frame's pixel holding p (motion = current minus previous, pixels), or (-1, -1) when it
// is off-screen or (with the history test) holds another surface: a depth (view depth of p
// from the previous camera) or normal mismatch.
fn reproject(id: vec2<u32>, p: vec3<f32>, n: vec3<f32>) -> vec2<i32> {
    let prev = vec2<f32>(id) + 0.5 - textureLoad(g_motion, id, 0).xy;
    let size = vec2<f32>(frame.size);
    if any(prev < vec2<f32>(0.0)) || any(prev >= size) {
        return vec2<i32>(-1);
    }
    let q = vec2<i32>(prev);
    if (lp.flags & FLAG_HISTORY_TEST) != 0u {
        let h = prev_history[u32(q.y) * frame.size.x + u32(q.x)];
        let expected = (frame.prev_view_proj * vec4<f32>(p, 1.0)).w;
        let prev_n = unpack4x8snorm(bitcast<u32>(h.y)).xyz;
        if h.x <= 0.0 || abs(h.x - expected) > lp.depth_tol * expected || dot(prev_n, n) < lp.normal_cos {
            return vec2<i32>(-1);
        }
    }
    return q;
}

// Steps 3-5 of section 3.1.3: does this pixel trace a ray?
fn temporal(id: vec2<u32>, p: vec3<f32>, n: vec3<f32>, ltt0: bool, st: bool, may_remove: bool) -> bool {
    if (lp.flags & FLAG_HAS_HISTORY) == 0u {
        return true;
    }
    let q = reproject(id, p, n);
    if q.x < 0 {
        return true;
    }
    var any_er = false;
    var all_rr = true;
    let full = (lp.flags & FLAG_FULL) != 0u;
    let k = i32(lp.frame % 4u);
    let o = select(vec2<i32>(-1 + (k & 1), -1 + (k >> 1u)), vec2<i32>(-1), full);
    let span = select(2, 3, full);
    for (var y = 0; y < span; y++) {
        for (var x = 0; x < span; x++) {
            let j = q + o + vec2<i32>(x, y);
            if any(j < vec2<i32>(0)) || any(j >= vec2<i32>(frame.size)) {
                continue;
            }
            let m = mask_load(u32(j.y) * frame.size.x + u32(j.x));
            any_er = any_er || expand(m, st);
            all_rr = all_rr && remove(m, st);
        }
    }
    if !ltt0 {
        return any_er;
    }
    return !((lp.flags & FLAG_RR) != 0u && may_remove && all_rr);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    var s: Sample;
    if id.x < frame.size.x && id.y < frame.size.y {
        cur_history[id.y * frame.size.x + id.x] = vec2<f32>(0.0);
    }
    if !load_sample(id, &s) {
        return;
    }
    cur_history[s.i] = vec2<f32>(textureLoad(g_position, id.xy, 0).w, pack_normal(s.n));

    // the level serving this view depth; beyond the hybrid levels every pixel traces a ray
    let depth = textureLoad(g_position, id.xy, 0).w;
    let levels = u32(lp.layers);
    var c = 0u;
    if POINT {
        c = cube_face(s.p - light.position.xyz);
    } else {
        while c < levels && depth > lp.levels[c].info.z {
            c++;
        }
    }
    let level = min(c, levels - 1u);
    var texel = lp.levels[level].info.x;
    if POINT {
        let a = abs(s.p - light.position.xyz);
        texel *= max(a.x, max(a.y, a.z));
    } else if PERSPECTIVE {
        texel *= max(dot(s.p - light.position.xyz, light.direction.xyz), 0.0);
    }
    let l = to_light(light, s.p);
    let m = to_map(level, s.p + s.n * (lp.normal_offset * texel) + l * (lp.depth_bias * texel));
    var v = 1.0;
    var ray = true;
    var st = false;
    var may_remove = true;
    // samples outside the map (should not happen: it covers the slice) trace a ray
    if c < levels && all(m.xy >= vec2<f32>(0.0)) && all(m.xy <= vec2<f32>(1.0)) && m.z <= 1.0 {
        let d = max(m.z, 0.0);
        var z = textureGather(0, static_map, gather_sampler, m.xy, level);
        if (lp.flags & FLAG_DYNAMIC) != 0u {
            // section 3.4: minimum of both maps per gathered texel, no RR where dynamic won
            let zd = textureGather(0, dynamic_map, gather_sampler, m.xy, level);
            may_remove = !any(zd < z);
            z = min(z, zd);
        }
        let eps = lp.eps;
        if TECHNIQUE == 2u {
            // hybrid-pcf: 2x2 hard tests of the plain depth map (bias applied above)
            let lit = vec4<f32>(z >= vec4<f32>(d));
            let n_lit = dot(lit, vec4<f32>(1.0));
            v = n_lit * 0.25;
            ray = n_lit > 0.5 && n_lit < 3.5;
        } else {
            v = base_visibility(z, gather_weights(m.xy, lp.res), d);
            ray = eps < v && v < 1.0 - eps;
        }
        st = v < 0.5;
        if TECHNIQUE == 0u {
            let ltt0 = ray;
            ray = temporal(id.xy, s.p, s.n, ltt0, st, may_remove);
            if ltt0 && !ray {
                // RR: the removed ray's answer is the shadow test, snapped (section 3.1.2)
                v = select(1.0, 0.0, st);
            }
        }
    }
    ray = ray || (lp.flags & FLAG_FORCE_ALL) != 0u;
    mask_or(s.i, select(0u, BIT_ST, st) | select(0u, BIT_LTT, ray));
    if ray {
        let slot = atomicAdd(&list[0], 1u);
        atomicStore(&list[slot + 1u], s.i);
    } else {
        visibility[s.i] = v;
    }
}
