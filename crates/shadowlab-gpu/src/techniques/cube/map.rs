//! `cube`'s map: made (the light's range, the face array, the face passes of depth.rs, the
//! evaluation of eval.rs), read back and reported.

use glam::Vec3;
use shadowlab_core::light::Light;
use shadowlab_core::metrics::sampling_stats;
use shadowlab_core::techniques::cube::FACES;

use super::depth::FacePasses;
use super::{eval, point_position, CubeMap, CubeParams, CubeSettings, FaceDepth};
use crate::scene_gpu::GpuScene;
use crate::technique::TechniqueReport;
use crate::techniques::pictures::{count_image, depth_image};
use crate::{raster, Gpu, GpuError};

impl CubeMap {
    pub fn new(gpu: &Gpu, scene: &GpuScene, p: &CubeSettings, light: &Light) -> Result<CubeMap, GpuError> {
        let pos = point_position("cube", light)?;
        let (res, pcf) = (p.res, p.pcf);
        gpu.check_size(res, res, "cube face")?;
        let far = bounds_far(scene, pos);
        let near = (far * 1e-4).max(1e-5);
        let hardware = p.depth == FaceDepth::Hardware;
        let map = raster::depth_target(gpu, "cube.map", res, res, 6, wgpu::TextureUsages::empty());
        let faces = FacePasses::new(gpu, scene, pos, near, far, hardware);
        let params = CubeParams { position: pos.into(), far, res: res as f32, pcf: pcf as f32, near, pad0: 0.0, bias: p.bias.packed() };
        let (eval_layout, eval) = eval::pipelines(gpu, hardware, pcf);
        Ok(CubeMap {
            groups: Default::default(),
            res,
            far,
            near,
            hardware,
            pcf,
            array_view: map
                .create_view(&wgpu::TextureViewDescriptor { dimension: Some(wgpu::TextureViewDimension::D2Array), ..Default::default() }),
            map,
            face_groups: faces.groups,
            depth_pipeline: faces.pipeline,
            face_indices: faces.indices,
            static_pipeline: faces.static_pipeline,
            params: gpu.uniform("cube.params", &params),
            counts: gpu.storage("cube.counts", 6 * res as u64 * res as u64 * 4),
            eval_layout,
            eval,
        })
    }

    /// The distance stored as depth 1 (the faces hold distance / far).
    pub fn far(&self) -> f32 {
        self.far
    }

    /// The six faces (+x, -x, +y, -y, +z, -z), each `res x res` row-major: distance / far.
    /// The faces as distance / far (1 = empty), whichever way they store depth.
    pub fn read_faces(&self, gpu: &Gpu) -> Vec<Vec<f32>> {
        let mut faces = read_layers(gpu, &self.map);
        if self.hardware {
            let res = self.res as usize;
            for (f, face) in faces.iter_mut().enumerate() {
                for (i, v) in face.iter_mut().enumerate() {
                    let (x, y) = ((i % res) as f32 + 0.5, (i / res) as f32 + 0.5);
                    let dc = shadowlab_core::techniques::cube::direction(f, x / res as f32, y / res as f32);
                    *v = if *v <= 0.0 { 1.0 } else { (self.near / *v * dc.length() / self.far).min(1.0) };
                }
            }
        }
        faces
    }

    /// View samples per texel of the last evaluation, face after face.
    pub fn read_counts(&self, gpu: &Gpu) -> Vec<u32> {
        gpu.read_buffer_as(&self.counts, 6 * (self.res * self.res) as usize)
    }
}

/// The largest distance from `pos` to a corner of the scene bounds (+1 %): depth 1.
fn bounds_far(scene: &GpuScene, pos: Vec3) -> f32 {
    let far = scene.bounds.corners().iter().map(|c| (*c - pos).length()).fold(0.0f32, f32::max);
    (far * 1.01).max(1e-3)
}

/// Every layer of a Depth32Float array texture, copied out one layer at a time.
pub fn read_layers(gpu: &Gpu, tex: &wgpu::Texture) -> Vec<Vec<f32>> {
    let (w, h) = (tex.width(), tex.height());
    let tmp = raster::depth_target(gpu, "cube.readback", w, h, 1, wgpu::TextureUsages::COPY_DST);
    (0..tex.depth_or_array_layers())
        .map(|layer| {
            let mut enc = gpu.device.create_command_encoder(&Default::default());
            let src = wgpu::TexelCopyTextureInfo {
                texture: tex,
                mip_level: 0,
                origin: wgpu::Origin3d { x: 0, y: 0, z: layer },
                aspect: wgpu::TextureAspect::All,
            };
            enc.copy_texture_to_texture(src, tmp.as_image_copy(), wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 });
            gpu.submit(enc.finish());
            bytemuck::pod_collect_to_vec(&gpu.read_texture(&tmp, 4))
        })
        .collect()
}

/// Memory, face-list counters, view samples per face, each face's distance and count picture.
pub(super) fn report(t: &CubeMap, gpu: &Gpu) -> TechniqueReport {
    let (res, n) = (t.res, (t.res * t.res) as usize);
    let counts = t.read_counts(gpu);
    let mut r = TechniqueReport { shadow_data_bytes: 6 * n as u64 * 4, sampling: Some(sampling_stats(&counts)), ..Default::default() };
    r.counters.insert("fetches_per_pixel".into(), (t.pcf * t.pcf) as f64);
    r.counters.insert("shadow_map_texels".into(), 6.0 * n as f64);
    // the per-face lists of static triangles (geometry, kept per light; not shadow data)
    r.counters.insert("face_list_bytes".into(), t.face_indices.iter().map(|(_, k)| *k as f64 * 4.0).sum());
    r.counters.insert("face_list_triangles".into(), t.face_indices.iter().map(|(_, k)| (*k / 3) as f64).sum());
    for (f, face) in t.read_faces(gpu).iter().enumerate() {
        let samples = counts[f * n..(f + 1) * n].iter().map(|&c| c as u64).sum::<u64>();
        r.counters.insert(format!("view_samples_face_{}", FACES[f].name), samples as f64);
        r.images.push(depth_image(&format!("face {} (distance)", FACES[f].name), res, face));
    }
    for (f, c) in counts.chunks(n).enumerate() {
        r.images.push(count_image(&format!("face {} view samples per texel", FACES[f].name), res, c));
    }
    r
}
