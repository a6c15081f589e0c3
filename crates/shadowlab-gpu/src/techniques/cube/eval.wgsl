// Cube shadow map evaluation: the sample is offset by sm's bias model (bias.wgsl) in world
// units of one face texel at the sample (2 dot(d, n) / res, continuous across the seams), its
// distance to the light compared with an NxN kernel of nearest-texel taps. Each tap's position
// is turned back into a direction and read on the face that direction falls on, so a kernel
// that crosses a face edge samples the neighbour face (seamless). Counts the view samples per
// texel of the six faces.

struct CubeParams {
    position: vec3<f32>,
    // distance normalisation (the scene's farthest point from the light)
    far: f32,
    // map side per face (texels)
    res: f32,
    // PCF kernel width
    pcf: f32,
    // near plane (depth=hardware)
    near: f32,
    pad0: f32,
    // constant bias, slope-scaled bias, normal offset (texels), max slope (sm's bias.wgsl)
    bias: vec4<f32>,
}

@group(0) @binding(6) var<uniform> cube: CubeParams;
// `depth=hardware`: the faces hold near / z (reversed depth, 0 = empty); the occluder's
// distance is z times the length of the texel's centre direction (whose axis component is 1).
override HW_DEPTH: bool = false;
// The PCF kernel width (= cube.pcf), fixed at pipeline creation: a constant loop bound.
override PCF: u32;

fn stored_distance(g: u32, t: vec2<i32>, res: f32) -> f32 {
    let v = textureLoad(faces, t, i32(g), 0);
    if !HW_DEPTH {
        return v;
    }
    if v <= 0.0 {
        return 2.0;
    }
    let dc = cube_direction(g, (vec2<f32>(t) + 0.5) / res);
    return cube.near / v * length(dc) / cube.far;
}
@group(0) @binding(7) var faces: texture_depth_2d_array;
@group(0) @binding(8) var<storage, read_write> counts: array<atomic<u32>>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    var s: Sample;
    if !load_sample(id, &s) {
        return;
    }
    let res = cube.res;
    let ires = i32(res);
    let l = to_light(light, s.p);

    // sampling statistics: the texel of the unbiased sample
    let d0 = s.p - cube.position;
    let f0 = cube_face(d0);
    let t0 = clamp(vec2<i32>(floor(cube_project(f0, d0) * res)), vec2<i32>(0), vec2<i32>(ires - 1));
    if COUNT_SAMPLES {
        atomicAdd(&counts[(f0 * u32(ires) + u32(t0.y)) * u32(ires) + u32(t0.x)], 1u);
    }

    let k = i32(PCF);
    let half = f32(k - 1) * 0.5;
    let texel = 2.0 * dot(d0, cube_basis(f0)[0]) / res;
    let q = biased_point(s.p, s.n, l, texel, cube.bias, half);
    let d = q - cube.position;
    let f = cube_face(d);
    let m = cube_project(f, d);
    let dist = length(d) / cube.far;
    var lit = 0.0;
    for (var y = 0; y < k; y++) {
        for (var x = 0; x < k; x++) {
            let dir = cube_direction(f, m + (vec2<f32>(f32(x), f32(y)) - half) / res);
            let g = cube_face(dir);
            let t = clamp(vec2<i32>(floor(cube_project(g, dir) * res)), vec2<i32>(0), vec2<i32>(ires - 1));
            lit += select(0.0, 1.0, dist <= stored_distance(g, t, res));
        }
    }
    visibility[s.i] = lit / f32(k * k);
}
