// Shared by every warp shader: the parameters (mod.rs `WarpParams`), the base light projection
// to map coordinates, the desired-view (DV) rectangle rule and the 1D offset interpolation
// (shadowlab-core warp.rs is the CPU reference of all of it).
//
// Map coordinates: x = column, y = row (0 at the top, like the texture), [0,1]^2 on the map.
// A warping function is stored as `res` offsets at the texels' right edges (o(0) = 0 implicit).

struct WarpParams {
    light_view_proj: mat4x4<f32>,
    // world size of one texel of the full (un-cropped) map (perspective: per unit of depth)
    texel_world: f32,
    // 1 if perspective
    perspective: f32,
    // map side (texels)
    res: f32,
    // PCF kernel width
    pcf: f32,
    // constant bias, slope-scaled bias, normal offset (all in warped texels), max slope
    bias: f32,
    slope_bias: f32,
    normal_offset: f32,
    max_slope: f32,
    // DV margin (texels)
    dv_margin: f32,
    // 0: no DV crop, 1: DV crop (DV_CROP), 2: DV crop and cracks closed by a 3x3 depth
    // minimum (DV_CROP_CLOSED)
    dv_mode: f32,
    // 1: the warp is on (0: the DV crop only)
    warped: f32,
    // NoTW smoothing window (functions)
    window: f32,
    // RTW desired-view weight, distance-to-eye weight, blur radius (texels)
    w_dv: f32,
    w_eye: f32,
    blur: f32,
    // subdivision threshold (warped texels per edge); 0: off
    subdiv: f32,
    // triangles, max subdivision level, extra sub-triangle capacity, 1 = RTW importance
    triangles: u32,
    subdiv_levels: u32,
    extra_capacity: u32,
    rtw_importance: u32,
    // 1 = offsets interpolated linearly between neighbouring functions (continuous warp),
    // 0 = eq. 6 as printed (function floor(y w) / floor(x' w))
    interp: u32,
    // NoTW uniform floor (fraction of the mean count per texel)
    mix: f32,
    // 1 = exact depth per fragment (depth_exact.wgsl)
    exact_depth: u32,
    // projection kind: PLANAR, or PARABOLOID_FRONT / _BACK (one hemisphere of a point light)
    projection: u32,
    // warp strength alpha (warp(u) = u + alpha * offsets; 1 = the computed warp)
    strength: f32,
    // bias footprint mode (0: isotropic, world texel / smallest singular value; see eval.wgsl)
    bias_mode: f32,
    // cap of mode 2's footprint (cropped texels; 0 = 1 / MIN_WARP_SCALE)
    footprint_cap: f32,
    // 1 = exact depth clamped to the whole triangle's corner depths (0: the piece's corners)
    depth_clamp: f32,
    // subdivision: an edge whose warped image spans less than this (warped texels) is not
    // split; 0 = no bound
    min_piece: f32,
    // 1 = exact depth inverts the warp exactly (unwarp_exact), 0 = Newton steps (unwarp)
    exact_inverse: f32,
    // 1: subdivision does not split edges hidden behind nearer geometry (occluders.wgsl)
    cull_hidden: f32,
    // 1: the smoothing across functions weighs them with a tent (analyze.wgsl smooth_block)
    tent: f32,
    // extra count of a view sample on a shadow edge of the occluder map (analyze.wgsl count)
    edge_importance: u32,
    // subdivision (planar): > 0 splits an edge on its perpendicular bend (> subdiv) and its
    // displacement along itself (> depth_split, warped texels); 0: on the whole displacement
    depth_split: f32,
    // exact depth: a piece whose corners spread less than this along the light's axis (texels
    // of world size) keeps the interpolated depth (depth.wgsl); 0: none
    exact_tol: f32,
    // subdivision levels before the tessellation (tess.wgsl); 0: the level queue alone
    tessellate: u32,
    // the scene's triangles: a subdivision of several maps over one scene (dpsm's hemispheres,
    // warp::LayerSubdivision) numbers map k's triangle t as k * scene_triangles + t
    scene_triangles: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
}

// Knobs that choose code paths, fixed per map at pipeline creation (mod.rs `Warped` passes
// `base_constants` to every warp pipeline): PARABOLOID = the uniform's `projection` is not
// PLANAR, WARPED = its `warped`. lavapipe runs both sides of a branch on a uniform value on
// lanes it masks off, so a branch on a constant, which is compiled away, is the lean one.
override PARABOLOID: bool;
override WARPED: bool;

// Fixed-point scale of DV coordinates for the atomic min/max.
const DV_SCALE: f32 = 16777216.0;

// Projection kinds (WarpParams.projection). PLANAR: light_view_proj is the light's view-projection.
// PARABOLOID_FRONT / _BACK (seed 002 eq. 3.3-3.10): light_view_proj is world -> the hemisphere's light space
// (+z = its axis) scaled by 1/far; the map plane point is (n.x, n.y) / (1 + n.z) for the unit
// direction n, depth = distance / far (linear, 0 at the light).
const PLANAR: u32 = 0u;
const PARABOLOID_FRONT: u32 = 1u;
const PARABOLOID_BACK: u32 = 2u;

// The scene's triangle of a subdivided triangle index (see `scene_triangles`).
fn scene_triangle(pw: WarpParams, t: u32) -> u32 {
    return t % max(pw.scene_triangles, 1u);
}

// Base map coordinates (x, y) and depth of a world point as a clip position; w <= 0 behind a
// spot. Paraboloid: the homogeneous form (n.x, n.y, depth (1 + n.z), 1 + n.z), finite for every
// direction but the opposite axis (w = 0); directions of the other hemisphere land outside the
// unit disc (the depth pass discards them by `hemisphere_side`).
fn base_clip(pw: WarpParams, p: vec3<f32>) -> vec4<f32> {
    let a = pw.light_view_proj * vec4<f32>(p, 1.0);
    if !PARABOLOID {
        return a;
    }
    let d = length(a.xyz);
    let n = a.xyz / max(d, 1e-20);
    let w = 1.0 + n.z;
    return vec4<f32>(n.x, n.y, d * w, w);
}

// Paraboloid: n.z of the direction of p in the hemisphere's light space (>= 0: this
// hemisphere; the split plane belongs to the front, whose axis the light space's +z is). Planar: 1.
fn hemisphere_side(pw: WarpParams, p: vec3<f32>) -> f32 {
    if !PARABOLOID {
        return 1.0;
    }
    let a = (pw.light_view_proj * vec4<f32>(p, 1.0)).xyz;
    return a.z / max(length(a), 1e-20);
}

// Paraboloid maps draw (and subdivide) the scene up to SPLIT_OVERLAP (in n.z) past the split
// plane: that part lands just outside the unit disc, so samples whose biased position crosses
// the plane still find their occluders in the border texels. Farther back nothing is drawn:
// the images of triangles there would wrap around the map (the opposite axis maps to infinity).
const SPLIT_OVERLAP: f32 = 0.1;

// Whether this map owns view sample p: planar always; of the two paraboloid maps the front
// owns the split plane (side >= 0), the back (whose +z is the opposite axis) only side > 0.
fn owns_sample(pw: WarpParams, p: vec3<f32>) -> bool {
    let s = hemisphere_side(pw, p);
    return !PARABOLOID || s > 0.0 || (s == 0.0 && pw.projection == PARABOLOID_FRONT);
}

fn clip_to_map(c: vec4<f32>) -> vec3<f32> {
    let ndc = c.xyz / c.w;
    return vec3<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5, ndc.z);
}

// The DV rectangle (lo.xy, hi.xy) from the reduced fixed-point bounds: extent e = max(hi - lo,
// 1/res), grown by margin * e / res per side (warp.rs `grow_rect`). Full map when off or empty.
fn dv_from_bounds(pw: WarpParams, b: vec4<u32>) -> vec4<f32> {
    if pw.dv_mode < 0.5 || b.x > b.z || b.y > b.w {
        return vec4<f32>(0.0, 0.0, 1.0, 1.0);
    }
    let res = pw.res;
    let lo = vec2<f32>(b.xy) / DV_SCALE;
    let hi = vec2<f32>(b.zw) / DV_SCALE;
    let e = max(hi - lo, vec2<f32>(1.0 / res));
    let m = pw.dv_margin * e / res;
    return vec4<f32>(lo - m, lo + e + m);
}

// Offset at s = x * res between the stored edge offsets `left` (edge k) and `right` (edge k+1).
fn edge_lerp(left: f32, right: f32, s: f32, k: u32) -> f32 {
    return left + (right - left) * (s - f32(k));
}

fn texel_of(v: f32, res: u32) -> u32 {
    return min(u32(max(floor(v * f32(res)), 0.0)), res - 1u);
}

// Neighbouring functions i0, i1 and weight t of i1 at coordinate v (function centres at
// (i + 0.5) / res); without interpolation the function floor(v res) alone (eq. 6).
fn neighbours(v: f32, res: u32, interp: bool) -> vec3<f32> {
    if !interp {
        let i = f32(texel_of(v, res));
        return vec3<f32>(i, i, 0.0);
    }
    let s = clamp(v * f32(res) - 0.5, 0.0, f32(res - 1u));
    let i0 = floor(s);
    return vec3<f32>(i0, min(i0 + 1.0, f32(res - 1u)), s - i0);
}

// The hidden-edge pyramid (occluders.wgsl, hzb.wgsl): level 0 is the unwarped DV-cropped depth
// map (res x res texels), level l (side ceil(res / 2^l)) the maximum over 2x2 texels of level
// l - 1, all levels one after another in one array.
fn hzb_side(res: u32, l: u32) -> u32 {
    return max((res + (1u << l) - 1u) >> l, 1u);
}

fn hzb_offset(res: u32, l: u32) -> u32 {
    var o = 0u;
    for (var k = 0u; k < l; k++) {
        let s = hzb_side(res, k);
        o += s * s;
    }
    return o;
}

// Whether a planar piece with corners at base clip positions pc keeps the interpolated depth
// (`exact_tol`): its interpolated and exact depths both lie within its corners' range, so they
// differ by at most the corners' spread along the light's axis (perspective: clip w, the axial
// distance; orthographic: z over its world scale), here below `exact_tol` texels of world size
// (perspective: at the piece's mean distance). Never with `exact_tol` 0.
fn flat_piece(pw: WarpParams, pc: array<vec4<f32>, 3>) -> bool {
    if pw.exact_tol <= 0.0 {
        return false;
    }
    if pw.perspective > 0.5 {
        let spread = max(max(pc[0].w, pc[1].w), pc[2].w) - min(min(pc[0].w, pc[1].w), pc[2].w);
        return spread < pw.exact_tol * pw.texel_world * (pc[0].w + pc[1].w + pc[2].w) / 3.0;
    }
    let m = pw.light_view_proj;
    let per_unit = length(vec3<f32>(m[0][2], m[1][2], m[2][2]));
    let spread = (max(max(pc[0].z, pc[1].z), pc[2].z) - min(min(pc[0].z, pc[1].z), pc[2].z)) / per_unit;
    return spread < pw.exact_tol * pw.texel_world;
}
