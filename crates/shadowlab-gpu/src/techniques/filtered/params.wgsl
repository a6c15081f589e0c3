// `FilteredParams` (Rust: filtered/mod.rs), shared by render.wgsl and eval.wgsl (and the
// leak-tracing raster, which renders its single-depth maps with render.wgsl).

struct FilteredParams {
    light_view_proj: mat4x4<f32>,
    // world size of one texel (orthographic) or per unit of light-view depth (perspective)
    texel_world: f32,
    // 1 if perspective
    perspective: f32,
    // map side (texels)
    res: f32,
    // 1 / far (perspective linear depth)
    inv_far: f32,
    // 0 vsm, 1 esm, 2 evsm, 3 msm
    kind: u32,
    // 1 = single depth (store z only)
    single_depth: u32,
    // mip levels (0 or 1 = no mips)
    mip_levels: u32,
    pad0: u32,
    min_variance: f32,
    esm_c: f32,
    evsm_c_pos: f32,
    evsm_c_neg: f32,
    moment_bias: f32,
    // texels
    depth_bias: f32,
    // texels
    normal_offset: f32,
    pad1: f32,
}
