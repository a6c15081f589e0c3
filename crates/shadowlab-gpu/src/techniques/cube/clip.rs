//! cube-notw's faces' scene: the scene's triangles clipped to each face's frustum (CPU,
//! `shadowlab_core::techniques::cube::clip_to_face`), drawn with the scene's own materials and texels. The
//! warped depth pass of `warp` moves each vertex by the warp of its projection, which is
//! undefined for vertices behind the light; clipping at a near plane in front of it keeps every
//! vertex inside the face's frustum. Done once per technique instance (static light, static
//! triangles; moving triangles would need this per frame).

use glam::Vec3;
use shadowlab_core::scene::Vertex;
use shadowlab_core::techniques::cube::clip_to_face;

use crate::scene_gpu::GpuScene;
use crate::Gpu;

/// One scene of every face's triangles (+x .. -z, one after another; face f's end before
/// `ends[f]`), each clipped at `near` along the face's axis and to a square of half-width
/// `tan_half`.
pub fn faces_scene(gpu: &Gpu, scene: &GpuScene, light: Vec3, near: f32, tan_half: f32) -> (GpuScene, [u32; 6]) {
    let all = scene.read_vertices(gpu);
    let mut clipped: Vec<Vertex> = Vec::new();
    let ends = std::array::from_fn(|f| {
        clipped.extend(all.chunks_exact(3).flat_map(|t| clip_to_face(&[t[0], t[1], t[2]], light, f, near, tan_half)).flatten());
        (clipped.len() / 3) as u32
    });
    (scene.with_triangles(gpu, "cube-notw.faces", &clipped), ends)
}
