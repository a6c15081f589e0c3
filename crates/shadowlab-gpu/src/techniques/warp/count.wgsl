// A view sample's place in its map's count map (analyze.wgsl `count` for one map,
// count_layers.wgsl for every layer of a warp::Layers). The includer provides the map's
// uniform `wp` and `occ_at(x, y)`, the occluder map's depth at a texel of the DV crop
// (`edge_importance`).

// A point's coordinates in the map cropped to the DV rectangle r.
fn map_coords(p: vec3<f32>, r: vec4<f32>) -> vec2<f32> {
    return (clip_to_map(base_clip(wp, p)).xy - r.xy) / (r.zw - r.xy);
}

fn inside(u: vec2<f32>) -> bool {
    return all(u >= vec2<f32>(0.0)) && all(u < vec2<f32>(1.0));
}

// Whether occluder depth o is clearly nearer the light than depth z: by 2 % of the distance
// (perspective: 1 - depth grows about as 1 / distance) or 0.5 % of the depth range.
fn clearly_nearer(o: f32, z: f32) -> bool {
    if wp.perspective > 0.5 {
        return 1.0 - o > (1.0 - z) * 1.02;
    }
    return o < z - 0.005;
}

// Whether the sample at DV texel t (depth z) lies on a shadow edge of the occluder map: among
// its 3x3 texels, one clearly nearer (an occluder) and one not (its own surface, or lit).
fn on_shadow_edge(tx: u32, ty: u32, z: f32) -> bool {
    let w = u32(wp.res);
    var near = false;
    var open = false;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let x = u32(clamp(i32(tx) + dx, 0, i32(w) - 1));
            let y = u32(clamp(i32(ty) + dy, 0, i32(w) - 1));
            if clearly_nearer(occ_at(x, y), z) {
                near = true;
            } else {
                open = true;
            }
        }
    }
    return near && open;
}

// A sample's count at DV coordinates u: 1, or 1 + edge_importance on a shadow edge.
fn sample_weight(p: vec3<f32>, u: vec2<f32>) -> u32 {
    let w = u32(wp.res);
    if wp.edge_importance > 0u && on_shadow_edge(texel_of(u.x, w), texel_of(u.y, w), clip_to_map(base_clip(wp, p)).z) {
        return 1u + wp.edge_importance;
    }
    return 1u;
}

// The count-map texel (row-major) of the sample at p with DV coordinates u, inside the crop.
fn count_index(u: vec2<f32>) -> u32 {
    let w = u32(wp.res);
    return texel_of(u.y, w) * w + texel_of(u.x, w);
}
