// The paraboloid depth pass without a fragment stage, where the device has clip distances
// (composed after `enable clip_distances;`, depth.rs `clipped_source`): the rasteriser clips
// every triangle SPLIT_OVERLAP behind the split plane, where depth_plain.wgsl's fragment stage
// would discard, on the same interpolated n.z. With nothing discarded the depth test runs
// before shading (lavapipe: 1.5-2x faster over the pieces, docs/bench/lean.md).

struct ClipOut {
    @builtin(position) clip: vec4<f32>,
    @builtin(clip_distances) behind: array<f32, 1>,
}

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> ClipOut {
    let v = depth_vertex(vi);
    var o: ClipOut;
    o.clip = v.clip;
    o.behind[0] = v.side + SPLIT_OVERLAP;
    return o;
}
