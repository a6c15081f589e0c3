//! The viewer's frame function, without a window: one recorded frame per call (G-buffer, mask,
//! technique A and optionally B, shading, the composed picture), one submit and one wait, as a
//! host of the library seam ([`shadowlab_gpu::host`]). While the camera is still it also brings
//! the reference up to date, a band of rows per frame, and then evaluates the techniques
//! against it ([`Evaluation`]: the lab's error image and metrics, computed by the same code).

use std::collections::BTreeMap;

use shadowlab_core::camera::Camera;
use shadowlab_core::light::Light;
use shadowlab_core::metrics::ErrorMetrics;
use shadowlab_gpu::frame::{FrameUniform, LightUniform};
use shadowlab_gpu::gbuffer::{GBuffer, GBufferPass};
use shadowlab_gpu::lab::{Instance, Lab};
use shadowlab_gpu::record::{self, Clock, FrameStamps, Recorder};
use shadowlab_gpu::registry::{self, Resolved};
use shadowlab_gpu::shade::ShadePass;
use shadowlab_gpu::technique::{run_frame, FrameInputs, TechniqueReport};
use shadowlab_gpu::{binding, Gpu, GpuError};

mod reference;

use reference::Progress;

const COMPOSE_WGSL: &str = include_str!("compose.wgsl");

/// The composed picture's format (registered with egui as a texture; read back for screenshots).
pub const VIEW_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// The reference is traced this many pixels per frame while the camera is still (about 0.2 s
/// per band for `rt` on lavapipe), so that the window keeps answering while it refines.
pub const REFERENCE_BAND_PIXELS: u32 = 196_608;

pub fn shaders() -> Vec<(&'static str, String)> {
    vec![("compose.wgsl", COMPOSE_WGSL.to_string())]
}

/// What each side of the picture shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Show {
    Shaded,
    Visibility,
    /// Against `rt`: false lit red, false shadow blue (the report's split error image); the
    /// shaded picture while the reference is not current.
    Error,
}

/// The right side of a split screen.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Right {
    None,
    /// Technique B.
    Technique,
    /// The reference `rt` (refined progressively while the camera is still).
    Reference,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Look {
    pub show: Show,
    pub right: Right,
    /// Divider position, 0..1 of the width.
    pub divider: f32,
}

/// Camera, light and animation time of one frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    pub camera: Camera,
    pub prev_camera: Camera,
    pub light: Light,
    pub time: f32,
    pub prev_time: f32,
}

/// A technique the viewer runs, with its own visibility, colour and error buffers.
struct Slot {
    spec: Resolved,
    inst: Instance,
    light: Light,
    vis: wgpu::Buffer,
    color: wgpu::Buffer,
    error: wgpu::Buffer,
}

/// One technique evaluated against the reference on a still view.
#[derive(Clone, Debug)]
pub struct SideEval {
    pub label: String,
    pub metrics: ErrorMetrics,
    /// RGBA8, the report's split error image.
    pub error: Vec<u8>,
    /// Counters, memory, degraded flags and debug pictures (after the lab-only analysis).
    pub report: TechniqueReport,
    /// Per-stage ms of one profiled frame (each stage waited for alone), on adapters without
    /// sane timestamps (filled in a frame after the evaluation, see [`Evaluation::profiled`]);
    /// empty on timestamp adapters, whose every frame has its stages ([`FrameInfo::stamped_ms`]).
    pub stages_ms: BTreeMap<String, f64>,
}

/// The techniques against the reference on the current still view.
#[derive(Clone, Debug)]
pub struct Evaluation {
    /// Counts the evaluations of this renderer (a new one for every still view or edit).
    pub id: u64,
    pub a: SideEval,
    pub b: Option<SideEval>,
    /// Time spent tracing the reference, summed over its bands (ms, wall clock).
    pub reference_ms: f64,
    /// Whether `stages_ms` are in: a profiled frame runs one still frame after the evaluation
    /// (adapters without sane timestamps), so that the error view is not kept waiting for it.
    pub profiled: bool,
}

/// Where the reference stands for the current view.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RefStatus {
    /// The camera, light or time moved since the last reference.
    Stale,
    /// Bands of rows traced so far, of all.
    Refining {
        done: u32,
        of: u32,
    },
    Current,
}

/// What one frame measured.
#[derive(Clone, Debug)]
pub struct FrameInfo {
    /// The recorded frame: one submit and one wait (wall clock, ms).
    pub frame_ms: f64,
    /// Whether the frame re-used the last live frame (still, nothing changed: composition only).
    pub reused: bool,
    /// Per-stage GPU time from timestamps (empty on adapters without sane ones).
    pub stamped_ms: BTreeMap<String, f64>,
    pub reference: RefStatus,
    /// Whether the light change of this frame re-created the techniques (dropping every cache
    /// they keep for a light: maps, lt's history, iasm's pages).
    pub recreated: bool,
}

struct Targets {
    width: u32,
    height: u32,
    g: GBuffer,
    frame: wgpu::Buffer,
    light_buf: wgpu::Buffer,
    view: wgpu::Texture,
    /// The reference's view of the G-buffer: the same targets with a band of the mask.
    band_g: GBuffer,
    band_vis: wgpu::Buffer,
    ref_vis: wgpu::Buffer,
    ref_color: wgpu::Buffer,
}

impl Targets {
    fn new(gpu: &Gpu, width: u32, height: u32) -> Result<Targets, GpuError> {
        gpu.check_size(width, height, "view size")?;
        let g = GBuffer::new(gpu, width, height);
        let px = g.pixels() as u64 * 4;
        let band_g = GBuffer { mask: gpu.storage("view.band_mask", px), ..g.clone() };
        let view = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("view.picture"),
            size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: VIEW_FORMAT,
            usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_SRC,
            // egui samples it as sRGB, like its own textures
            view_formats: &[wgpu::TextureFormat::Rgba8UnormSrgb],
        });
        Ok(Targets {
            width,
            height,
            frame: gpu.uniform("view.frame", &<FrameUniform as bytemuck::Zeroable>::zeroed()),
            light_buf: gpu.uniform("view.light", &<LightUniform as bytemuck::Zeroable>::zeroed()),
            view,
            band_vis: gpu.storage("view.band_visibility", px),
            ref_vis: gpu.storage("view.rt_visibility", px),
            ref_color: gpu.storage("view.rt_color", px),
            band_g,
            g,
        })
    }

    fn inputs<'a>(&'a self, lab: &'a Lab, pose: &Pose, g: &'a GBuffer, vis: &'a wgpu::Buffer) -> FrameInputs<'a> {
        FrameInputs {
            scene: &lab.gscene,
            gbuffer: g,
            light: pose.light,
            camera: pose.camera,
            prev_camera: pose.prev_camera,
            light_buf: &self.light_buf,
            frame: &self.frame,
            visibility: vis,
        }
    }
}

pub struct Renderer<'a> {
    gpu: &'a Gpu,
    pub lab: Lab<'a>,
    gpass: GBufferPass,
    shade: ShadePass,
    compose: wgpu::ComputePipeline,
    compose_layout: wgpu::BindGroupLayout,
    stamps: Option<FrameStamps>,
    t: Targets,
    a: Slot,
    b: Option<Slot>,
    rt: Instance,
    progress: Option<Progress>,
    eval: Option<(String, Evaluation)>,
    evals: u64,
    /// What the live buffers hold (view, techniques): a still frame that would record the same
    /// again only composes, so the reference refines without the live frame's cost.
    live: Option<String>,
}

impl<'a> Renderer<'a> {
    /// A renderer of `lab`'s scene at `width` x `height` running `a` (and `b` on the right side).
    pub fn new(lab: Lab<'a>, width: u32, height: u32, light: &Light, a: Resolved, b: Option<Resolved>) -> Result<Renderer<'a>, GpuError> {
        let gpu = lab.gpu;
        use binding::*;
        let tex = wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format: VIEW_FORMAT,
            view_dimension: wgpu::TextureViewDimension::D2,
        };
        let compose_layout = layout(
            &gpu.device,
            "view.compose",
            wgpu::ShaderStages::COMPUTE,
            &[uniform(), storage(true), storage(true), storage(true), storage(true), storage(true), tex],
        );
        let compose = gpu.compute_pipeline("view.compose", COMPOSE_WGSL, "main", &[&compose_layout]);
        let t = Targets::new(gpu, width, height)?;
        let rt = lab.instantiate(&registry::reference(), light)?;
        let a = Self::slot(&lab, &t, a, light)?;
        let b = b.map(|b| Self::slot(&lab, &t, b, light)).transpose()?;
        Ok(Renderer {
            gpu,
            gpass: GBufferPass::new(gpu, &lab.gscene),
            shade: ShadePass::new(gpu),
            stamps: gpu.gpu_timestamps.then(|| FrameStamps::new(gpu)),
            lab,
            compose,
            compose_layout,
            t,
            a,
            b,
            rt,
            progress: None,
            eval: None,
            evals: 0,
            live: None,
        })
    }

    fn slot(lab: &Lab, t: &Targets, spec: Resolved, light: &Light) -> Result<Slot, GpuError> {
        let gpu = lab.gpu;
        let px = t.g.pixels() as u64 * 4;
        let inst = lab.instantiate(&spec, light)?;
        Ok(Slot {
            inst,
            spec,
            light: *light,
            vis: gpu.storage("view.visibility", px),
            color: gpu.storage("view.color", px),
            error: gpu.storage("view.error", px),
        })
    }

    pub fn size(&self) -> (u32, u32) {
        (self.t.width, self.t.height)
    }

    /// The composed picture (egui shows it; [`Renderer::read_picture`] reads it back).
    pub fn picture(&self) -> &wgpu::Texture {
        &self.t.view
    }

    pub fn technique(&self, right: bool) -> Option<&Resolved> {
        if right {
            self.b.as_ref().map(|s| &s.spec)
        } else {
            Some(&self.a.spec)
        }
    }

    /// Replaces technique A (or B) with `spec`, created afresh for `light`.
    pub fn set_technique(&mut self, right: bool, spec: Option<Resolved>, light: &Light) -> Result<(), GpuError> {
        let slot = spec.map(|s| Self::slot(&self.lab, &self.t, s, light)).transpose()?;
        match (right, slot) {
            (false, Some(s)) => self.a = s,
            (false, None) => return Err(GpuError::Invalid("technique A is required".into())),
            (true, s) => self.b = s,
        }
        self.eval = None;
        self.live = None;
        Ok(())
    }

    /// New output size: every target and technique is made again.
    pub fn resize(&mut self, width: u32, height: u32) -> Result<(), GpuError> {
        if (width, height) == self.size() {
            return Ok(());
        }
        self.t = Targets::new(self.gpu, width, height)?;
        let light = self.a.light;
        self.recreate(&light)?;
        Ok(())
    }

    /// Re-creates the techniques and the reference for `light` (their caches go with them).
    fn recreate(&mut self, light: &Light) -> Result<(), GpuError> {
        self.rt = self.lab.instantiate(&registry::reference(), light)?;
        self.a = Self::slot(&self.lab, &self.t, self.a.spec.clone(), light)?;
        if let Some(b) = &self.b {
            self.b = Some(Self::slot(&self.lab, &self.t, b.spec.clone(), light)?);
        }
        self.progress = None;
        self.eval = None;
        self.live = None;
        Ok(())
    }

    /// The evaluation on the current still view, once the reference is complete.
    pub fn evaluation(&self) -> Option<&Evaluation> {
        self.eval.as_ref().map(|(_, e)| e)
    }

    fn view_key(&self, pose: &Pose) -> String {
        format!("{:?}|{:?}|{:?}|{}|{}x{}", pose.camera, pose.light, pose.time, pose.prev_time, self.t.width, self.t.height)
    }

    fn eval_key(&self, view_key: &str) -> String {
        let b = self.b.as_ref().map(|b| b.spec.text.clone()).unwrap_or_default();
        format!("{view_key}|{}|{b}", self.a.spec.text)
    }

    /// One frame: records and submits the view; when `still`, then also advances the reference
    /// by one band and, once it is complete, evaluates the techniques against it.
    pub fn frame(&mut self, pose: &Pose, look: &Look, still: bool) -> Result<FrameInfo, GpuError> {
        let gpu = self.gpu;
        let recreated = pose.light != self.a.light;
        if recreated {
            self.recreate(&pose.light)?;
        }
        self.lab.set_time(pose.time, pose.prev_time)?;
        let view_key = self.view_key(pose);
        let eval_current = self.eval.as_ref().is_some_and(|(k, _)| *k == self.eval_key(&view_key));
        let stamps = self.stamps.take();
        let with_b = look.right == Right::Technique;
        let live_key = format!("{}|{with_b}", self.eval_key(&view_key));
        let reuse = still && self.live.as_deref() == Some(live_key.as_str());
        let driven = record::drive(gpu, "view.frame", Clock::of(stamps.as_ref()), |rec| {
            if !reuse {
                self.record_live(rec, pose, with_b)?;
            }
            self.record_compose(rec, look, eval_current);
            Ok(())
        });
        self.stamps = stamps;
        self.live = driven.is_ok().then_some(live_key);
        let driven = driven?;
        let (frame_ms, stamped_ms) = (driven.wall_ms, driven.stamped_ms.unwrap_or_default());
        gpu.take_error()?;
        let reference = if still { self.refine(pose, &view_key)? } else { self.status(&view_key) };
        Ok(FrameInfo { frame_ms, stamped_ms, reference, recreated, reused: reuse })
    }

    fn status(&self, view_key: &str) -> RefStatus {
        match &self.progress {
            Some(p) if p.key == view_key && p.done == p.of => RefStatus::Current,
            Some(p) if p.key == view_key => RefStatus::Refining { done: p.done, of: p.of },
            _ => RefStatus::Stale,
        }
    }

    /// G-buffer, mask, technique A (and B), shading.
    fn record_live(&mut self, rec: &mut Recorder, pose: &Pose, with_b: bool) -> Result<(), GpuError> {
        let gpu = self.gpu;
        let t = &self.t;
        rec.write_buffer(&t.frame, 0, bytemuck::bytes_of(&FrameUniform::new(&pose.camera, &pose.prev_camera, t.width, t.height)));
        rec.write_buffer(&t.light_buf, 0, bytemuck::bytes_of(&LightUniform::new(&pose.light, self.lab.gscene.eps)));
        self.gpass.render(gpu, rec, &self.lab.gscene, &t.frame, &t.g);
        self.gpass.mask(gpu, rec, &t.frame, &t.light_buf, &t.g);
        let slots: Vec<&mut Slot> = std::iter::once(&mut self.a).chain(self.b.as_mut().filter(|_| with_b)).collect();
        for s in slots {
            let inputs = t.inputs(&self.lab, pose, &t.g, &s.vis);
            run_frame(s.inst.tech.as_mut(), gpu, &inputs, rec)?;
            self.shade.record(gpu, rec, &inputs, &s.color);
        }
        Ok(())
    }

    fn record_compose(&self, rec: &mut Recorder, look: &Look, eval_current: bool) {
        let gpu = self.gpu;
        let t = &self.t;
        // (colour buffer, visibility buffer, kind)
        let side = |s: &'_ Slot| -> (wgpu::Buffer, wgpu::Buffer, u32) {
            match look.show {
                Show::Visibility => (s.color.clone(), s.vis.clone(), 1),
                Show::Error if eval_current => (s.error.clone(), s.vis.clone(), 0),
                _ => (s.color.clone(), s.vis.clone(), 0),
            }
        };
        let left = side(&self.a);
        let right = match (look.right, &self.b) {
            (Right::Technique, Some(b)) => Some(side(b)),
            (Right::Reference, _) => Some((t.ref_color.clone(), t.ref_vis.clone(), (look.show == Show::Visibility) as u32)),
            _ => None,
        };
        let divider = match right {
            Some(_) => ((look.divider.clamp(0.0, 1.0) * t.width as f32) as u32).min(t.width),
            None => t.width,
        };
        let right = right.unwrap_or_else(|| left.clone());
        let params: [u32; 8] = [t.width, t.height, divider, left.2, right.2, 0, 0, 0];
        let ubuf = gpu.uniform("view.compose", &params);
        let tv = t.view.create_view(&Default::default());
        let group = binding::group(
            gpu,
            "view.compose",
            &self.compose_layout,
            &[
                ubuf.as_entire_binding(),
                left.0.as_entire_binding(),
                left.1.as_entire_binding(),
                right.0.as_entire_binding(),
                right.1.as_entire_binding(),
                t.g.mask.as_entire_binding(),
                wgpu::BindingResource::TextureView(&tv),
            ],
        );
        rec.stage("view.compose", |enc| gpu.dispatch_2d(enc, "view.compose", &self.compose, &[&group], t.width, t.height));
    }

    /// The composed picture of the last frame, RGBA8.
    pub fn read_picture(&self) -> Vec<u8> {
        self.gpu.read_texture(&self.t.view, 4)
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn compose_shader_validates() {
        for (name, src) in super::shaders() {
            let module = naga::front::wgsl::parse_str(&src).unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(&src)));
            naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::empty())
                .validate(&module)
                .unwrap_or_else(|e| panic!("{name}: {e:?}"));
        }
    }
}
