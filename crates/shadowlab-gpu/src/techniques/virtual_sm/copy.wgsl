// The static/dynamic split's copy: instance i covers the viewport (page i's slot in the atlas)
// and writes, as its depth, the texel of the page's static copy at the same place in its slot
// of the static pool (`offsets[i].xy`: static slot origin minus atlas slot origin, texels).
// Depth test Always; the moving chunks are drawn over it afterwards with the usual test.

@group(0) @binding(0) var statics: texture_depth_2d;
@group(0) @binding(1) var<storage, read> offsets: array<vec4<i32>>;

struct CopyOut {
    @builtin(position) pos: vec4<f32>,
    @location(0) @interpolate(flat) page: u32,
}

@vertex
fn vs_copy(@builtin(vertex_index) vi: u32, @builtin(instance_index) ii: u32) -> CopyOut {
    var o: CopyOut;
    let x = f32((vi << 1u) & 2u) * 2.0 - 1.0;
    let y = f32(vi & 2u) * 2.0 - 1.0;
    o.pos = vec4<f32>(x, y, 1.0, 1.0);
    o.page = ii;
    return o;
}

@fragment
fn fs_copy(in: CopyOut) -> @builtin(frag_depth) f32 {
    let p = vec2<i32>(floor(in.pos.xy)) + offsets[in.page].xy;
    return textureLoad(statics, p, 0);
}
