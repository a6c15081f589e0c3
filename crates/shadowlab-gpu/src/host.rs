//! The library seam: what a host renderer provides and gets back, on its own device.
//!
//! A host wraps its device with [`Gpu::from_device`], uploads the scene once
//! ([`crate::scene_gpu::GpuScene`]: positions for the shadow-map passes, the BVH for the
//! ray-assisted techniques), and allocates one [`HostView`] per output size. Per frame, in its
//! own command encoder:
//! 1. it draws its own depth/normal pass into [`HostView::gbuffer`]'s `position` (Rgba32Float:
//!    world xyz, w = linear view depth, 0 where empty), `normal` (Rgba32Float: geometric normal
//!    facing the camera) and, for techniques with history (`lt`), `motion` (Rg32Float: pixels,
//!    current minus previous) targets, with `gbuffer.depth` as its depth buffer;
//! 2. wraps the encoder in a [`Recorder`] and calls [`HostView::record_view`] (camera matrices,
//!    light, evaluation mask);
//! 3. records each technique's `prepare`, `render`, `evaluate` with [`HostView::inputs`]
//!    (`techniques::run_frame`);
//! 4. optionally [`HostView::record_visibility_texture`] for an R32Float texture to sample in
//!    its own shading;
//! 5. submits once.
//!
//! The lab ([`crate::lab::Lab`]) drives the same trait with the same [`FrameInputs`]; it only
//! draws the G-buffer itself.

use shadowlab_core::camera::Camera;
use shadowlab_core::light::Light;

use crate::frame::{FrameUniform, LightUniform};
use crate::gbuffer::{GBuffer, MaskPass};
use crate::record::Recorder;
use crate::scene_gpu::GpuScene;
use crate::shaders::compose;
use crate::technique::FrameInputs;
use crate::{binding, Gpu, GpuError};

const TO_TEXTURE_WGSL: &str = include_str!("host_visibility.wgsl");

pub fn shaders() -> Vec<(&'static str, String)> {
    vec![("host_visibility.wgsl", compose(TO_TEXTURE_WGSL, false))]
}

/// Format of [`HostView::visibility_texture`].
pub const VISIBILITY_TEXTURE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;

/// One output size's inputs and outputs for the techniques (see the module docs).
pub struct HostView {
    /// Targets the host draws into (`position`, `normal`, `motion`, `depth`); `albedo` is not
    /// read by any technique; `mask` is written by [`HostView::record_view`].
    pub gbuffer: GBuffer,
    /// `FrameUniform` (camera), written by [`HostView::record_view`].
    pub frame: wgpu::Buffer,
    /// `LightUniform`, written by [`HostView::record_view`].
    pub light_buf: wgpu::Buffer,
    /// Visibility per pixel (f32, 1 lit, 0 shadowed), written by a technique's `evaluate`.
    pub visibility: wgpu::Buffer,
    /// R32Float copy of `visibility` ([`HostView::record_visibility_texture`]).
    pub visibility_texture: wgpu::Texture,
    eps: f32,
    mask: MaskPass,
    copy: wgpu::ComputePipeline,
    copy_group: wgpu::BindGroup,
}

impl HostView {
    pub fn new(gpu: &Gpu, scene: &GpuScene, width: u32, height: u32) -> Result<HostView, GpuError> {
        gpu.check_size(width, height, "output size")?;
        let gbuffer = GBuffer::new(gpu, width, height);
        let frame = gpu.uniform("host.frame", &<FrameUniform as bytemuck::Zeroable>::zeroed());
        let light_buf = gpu.uniform("host.light", &<LightUniform as bytemuck::Zeroable>::zeroed());
        let visibility = gpu.storage("host.visibility", gbuffer.pixels() as u64 * 4);
        let visibility_texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("host.visibility_texture"),
            size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: VISIBILITY_TEXTURE_FORMAT,
            usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let layout = binding::layout(
            &gpu.device,
            "host.visibility_texture",
            wgpu::ShaderStages::COMPUTE,
            &[binding::uniform(), binding::storage(true), binding::storage_texture_r32f()],
        );
        let tv = visibility_texture.create_view(&Default::default());
        let copy_group = binding::group(
            gpu,
            "host.visibility_texture",
            &layout,
            &[frame.as_entire_binding(), visibility.as_entire_binding(), wgpu::BindingResource::TextureView(&tv)],
        );
        let copy = gpu.compute_pipeline("host.visibility_texture", &compose(TO_TEXTURE_WGSL, false), "main", &[&layout]);
        Ok(HostView {
            gbuffer,
            frame,
            light_buf,
            visibility,
            visibility_texture,
            eps: scene.eps,
            mask: MaskPass::new(gpu),
            copy,
            copy_group,
        })
    }

    /// Records the camera (this and the previous frame's) and the light, then the evaluation
    /// mask (geometry present, facing the light, inside a spot cone) from the host's
    /// position and normal targets (stage `mask`).
    pub fn record_view(&self, gpu: &Gpu, rec: &mut Recorder, camera: &Camera, prev: &Camera, light: &Light) -> Result<(), GpuError> {
        camera.validate().map_err(GpuError::Invalid)?;
        light.validate().map_err(GpuError::Invalid)?;
        let (w, h) = (self.gbuffer.width, self.gbuffer.height);
        rec.write_buffer(&self.frame, 0, bytemuck::bytes_of(&FrameUniform::new(camera, prev, w, h)));
        rec.write_buffer(&self.light_buf, 0, bytemuck::bytes_of(&LightUniform::new(light, self.eps)));
        self.mask.record(gpu, rec, &self.frame, &self.light_buf, &self.gbuffer);
        Ok(())
    }

    /// What a technique reads for this view; `visibility` is where it writes (this view's own
    /// buffer, or another one of `gbuffer.pixels()` f32 for a second technique).
    pub fn inputs<'a>(
        &'a self,
        scene: &'a GpuScene,
        camera: Camera,
        prev: Camera,
        light: Light,
        visibility: &'a wgpu::Buffer,
    ) -> FrameInputs<'a> {
        FrameInputs {
            scene,
            gbuffer: &self.gbuffer,
            light,
            camera,
            prev_camera: prev,
            light_buf: &self.light_buf,
            frame: &self.frame,
            visibility,
        }
    }

    /// Copies `visibility` into `visibility_texture` (stage `host.visibility_texture`).
    pub fn record_visibility_texture(&self, gpu: &Gpu, rec: &mut Recorder) {
        let (w, h) = (self.gbuffer.width, self.gbuffer.height);
        rec.stage("host.visibility_texture", |enc| gpu.dispatch_2d(enc, "host.visibility_texture", &self.copy, &[&self.copy_group], w, h));
    }
}
