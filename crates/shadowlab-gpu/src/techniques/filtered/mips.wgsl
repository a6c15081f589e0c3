// Mip chain of a moment map: each texel of level i+1 is the mean of its 2x2 texels of level i
// (a box pre-filter; moments stay valid under any averaging). The composed shader starts with
// `alias MipTarget = texture_storage_2d<FORMAT, write>;` (filtered/mips.rs).

@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var dst: MipTarget;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(dst);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    let hi = vec2<i32>(textureDimensions(src)) - 1;
    let s = vec2<i32>(id.xy) * 2;
    let m = textureLoad(src, min(s, hi), 0) + textureLoad(src, min(s + vec2<i32>(1, 0), hi), 0)
        + textureLoad(src, min(s + vec2<i32>(0, 1), hi), 0) + textureLoad(src, min(s + vec2<i32>(1, 1), hi), 0);
    textureStore(dst, id.xy, 0.25 * m);
}
