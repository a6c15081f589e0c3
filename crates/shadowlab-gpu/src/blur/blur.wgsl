// Separable Gaussian blur, one axis per dispatch, edges clamped. The composed shader starts with
// `alias BlurTarget = texture_storage_2d<FORMAT, write>;` (blur/mod.rs), so one file serves
// r32float, rg32float and rgba32float targets; the source is read as a 4-channel float texture.
// Weights: exp(-i^2 / (2 sigma^2)) for i in [-half, half], normalised
// (shadowlab_core::moments::gaussian_kernel).

struct BlurParams {
    // (1, 0) horizontal or (0, 1) vertical
    dir: vec2<i32>,
    half: i32,
    sigma: f32,
}

@group(0) @binding(0) var<uniform> bp: BlurParams;
@group(0) @binding(1) var src: texture_2d<f32>;
@group(0) @binding(2) var dst: BlurTarget;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<i32>(textureDimensions(src));
    let at = vec2<i32>(id.xy);
    if at.x >= size.x || at.y >= size.y {
        return;
    }
    var acc = vec4<f32>(0.0);
    var wsum = 0.0;
    for (var i = -bp.half; i <= bp.half; i++) {
        let w = exp(-f32(i * i) / (2.0 * bp.sigma * bp.sigma));
        let q = clamp(at + bp.dir * i, vec2<i32>(0), size - 1);
        acc += w * textureLoad(src, q, 0);
        wsum += w;
    }
    textureStore(dst, at, acc / wsum);
}
