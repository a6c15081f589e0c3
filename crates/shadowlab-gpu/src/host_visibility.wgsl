// The visibility buffer (f32 per pixel) copied into an R32Float storage texture, for a host
// renderer to sample in its own shading.

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<storage, read> visibility: array<f32>;
@group(0) @binding(2) var out: texture_storage_2d<r32float, write>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= frame.size.x || id.y >= frame.size.y {
        return;
    }
    textureStore(out, vec2<i32>(id.xy), vec4<f32>(visibility[id.y * frame.size.x + id.x], 0.0, 0.0, 1.0));
}
