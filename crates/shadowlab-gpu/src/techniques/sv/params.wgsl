// `SvParams` (Rust: sv/mod.rs), shared by silhouette.wgsl, volume.wgsl and resolve.wgsl.

struct SvParams {
    triangles: u32,
    edges: u32,
    // vertices per side record (3: one triangle to the point at infinity; 6: a quad)
    side_vertices: u32,
    // depth offset of the receivers (f32 ulps)
    depth_offset: u32,
    // extrusion distance (world units; 0 = to infinity, w = 0)
    extrude: f32,
    pad0: f32,
    pad1: f32,
    pad2: f32,
}
