//! The lab: one scene on the GPU, views prepared once (G-buffer, mask, reference), techniques
//! run against them. The CLI and the integration tests both drive this.

use std::cell::Cell;
use std::collections::BTreeMap;

use shadowlab_core::bvh::Bvh;
use shadowlab_core::camera::Camera;
use shadowlab_core::light::Light;
use shadowlab_core::params::{ParamValues, TechniqueSpec};
use shadowlab_core::scene::Scene;

use crate::frame::{FrameUniform, LightUniform};
use crate::gbuffer::{GBuffer, GBufferPass};
use crate::scene_gpu::GpuScene;
use crate::shade::ShadePass;
use crate::techniques::{self, FrameInputs, TechniqueInfo, TechniqueReport};
use crate::timing::StageTimer;
use crate::{Gpu, GpuError};

pub struct Lab<'a> {
    pub gpu: &'a Gpu,
    pub scene: &'a Scene,
    /// BVH over the whole scene as stored (moving objects at t = 0): the CPU cross-checks'.
    /// For another time use `Bvh::build(&scene.at_time(t))`.
    pub bvh: Bvh,
    pub gscene: GpuScene,
    gbuffer_pass: GBufferPass,
    shade_pass: ShadePass,
    /// Animation time of the GPU scene now: (t, previous t), in frames.
    time: Cell<(f32, f32)>,
    /// Wall time of the last `set_time` that moved something (ms).
    animate_ms: Cell<f64>,
}

/// One view of the scene for one light, with its G-buffer read back.
pub struct View {
    pub camera: Camera,
    pub prev_camera: Camera,
    /// Animation time of this view and of its motion vectors' previous frame (frames).
    pub time: f32,
    pub prev_time: f32,
    pub light: Light,
    pub width: u32,
    pub height: u32,
    pub gbuffer: GBuffer,
    pub frame: wgpu::Buffer,
    pub light_buf: wgpu::Buffer,
    pub visibility: wgpu::Buffer,
    /// Shaded colour of this view (packed RGBA8 per pixel).
    pub color: wgpu::Buffer,
    /// xyz world position, w linear depth (0 = empty).
    pub position: Vec<[f32; 4]>,
    pub normal: Vec<[f32; 4]>,
    pub mask: Vec<u32>,
    /// G-buffer and mask stage times (ms).
    pub stages_ms: BTreeMap<String, f64>,
}

/// A technique created for one light, kept across the views of a path.
pub struct Instance {
    pub label: String,
    pub info: &'static TechniqueInfo,
    pub params: ParamValues,
    pub tech: Box<dyn techniques::Technique>,
    /// Pipeline and resource creation (ms).
    pub setup_ms: f64,
}

impl View {
    /// What a technique reads for this view of `scene` (for driving techniques directly).
    pub fn inputs<'a>(&'a self, scene: &'a GpuScene) -> FrameInputs<'a> {
        FrameInputs {
            scene,
            gbuffer: &self.gbuffer,
            light: self.light,
            camera: self.camera,
            prev_camera: self.prev_camera,
            light_buf: &self.light_buf,
            frame: &self.frame,
            visibility: &self.visibility,
        }
    }
}

/// The result of one technique on one view.
pub struct Run {
    pub label: String,
    pub technique: &'static str,
    pub params: ParamValues,
    pub visibility: Vec<f32>,
    /// RGBA8 shaded picture.
    pub shaded: Vec<u8>,
    pub report: TechniqueReport,
    /// Median per stage over the timed repetitions.
    pub stages_ms: BTreeMap<String, f64>,
    pub total_ms: f64,
    /// Pipeline and resource creation (not part of total_ms).
    pub setup_ms: f64,
}

impl<'a> Lab<'a> {
    pub fn new(gpu: &'a Gpu, scene: &'a Scene) -> Result<Lab<'a>, GpuError> {
        let bvh = Bvh::build(scene).map_err(GpuError::Invalid)?;
        let d = scene.dynamic_first();
        let gscene = if d == scene.triangle_count() {
            GpuScene::new(gpu, scene, &bvh)?
        } else {
            let static_bvh = if d == 0 { Bvh::empty() } else { Bvh::build_range(scene, 0..d).map_err(GpuError::Invalid)? };
            GpuScene::new(gpu, scene, &static_bvh)?
        };
        let gbuffer_pass = GBufferPass::new(gpu, &gscene);
        let shade_pass = ShadePass::new(gpu);
        gpu.take_error()?;
        Ok(Lab { gpu, scene, bvh, gscene, gbuffer_pass, shade_pass, time: Cell::new((0.0, 0.0)), animate_ms: Cell::new(0.0) })
    }

    /// Moves the scene's moving objects to time `t` (frames), with motion vectors against
    /// `prev_t`; the following views are rendered at that time (see [`View::time`]). Cheap when
    /// nothing moves or the time is unchanged. Starts at (0, 0).
    pub fn set_time(&self, t: f32, prev_t: f32) -> Result<(), GpuError> {
        if self.time.get() == (t, prev_t) && t.is_finite() {
            return Ok(());
        }
        let t0 = std::time::Instant::now();
        self.gscene.set_time(self.gpu, self.scene, t, prev_t)?;
        self.animate_ms.set(t0.elapsed().as_secs_f64() * 1e3);
        self.time.set((t, prev_t));
        Ok(())
    }

    /// The current animation time (t, previous t).
    pub fn time(&self) -> (f32, f32) {
        self.time.get()
    }

    /// Renders the G-buffer and the mask for `light` at the current animation time
    /// ([`Lab::set_time`]), and reads them back.
    pub fn view(&self, camera: &Camera, prev: &Camera, light: &Light, width: u32, height: u32) -> Result<View, GpuError> {
        let gpu = self.gpu;
        gpu.check_size(width, height, "output size")?;
        camera.validate().map_err(GpuError::Invalid)?;
        light.validate().map_err(GpuError::Invalid)?;
        let g = GBuffer::new(gpu, width, height);
        let frame = gpu.uniform("frame", &FrameUniform::new(camera, prev, width, height));
        let light_buf = gpu.uniform("light", &LightUniform::new(light, self.gscene.eps));
        let mut timer = StageTimer::default();
        self.gbuffer_pass.render(gpu, &mut timer, &self.gscene, &frame, &g);
        self.gbuffer_pass.mask(gpu, &mut timer, &frame, &light_buf, &g);
        gpu.take_error()?;
        let position: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&gpu.read_texture(&g.position, 16));
        let normal: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&gpu.read_texture(&g.normal, 16));
        let mask: Vec<u32> = gpu.read_buffer_as(&g.mask, g.pixels());
        let visibility = gpu.storage("visibility", g.pixels() as u64 * 4);
        let color = ShadePass::output(gpu, &g);
        let (time, prev_time) = self.time.get();
        let mut stages_ms = timer.medians();
        if self.gscene.is_animated() {
            // CPU transform + dynamic BVH rebuild + upload of the last `set_time`
            stages_ms.insert("scene.animate".into(), self.animate_ms.get());
        }
        Ok(View {
            camera: *camera,
            prev_camera: *prev,
            time,
            prev_time,
            light: *light,
            width,
            height,
            gbuffer: g,
            frame,
            light_buf,
            visibility,
            color,
            position,
            normal,
            mask,
            stages_ms,
        })
    }

    /// Resolves `spec`, creates the technique, runs it once to warm up and `repeat` more times
    /// timed, then shades and reads back its visibility.
    pub fn run(&self, view: &View, spec: &TechniqueSpec, repeat: usize) -> Result<Run, GpuError> {
        let (info, params) = techniques::resolve(spec, Some(&view.light))?;
        self.run_resolved(view, info, params, spec.label(), repeat)
    }

    pub fn run_resolved(
        &self,
        view: &View,
        info: &'static TechniqueInfo,
        params: ParamValues,
        label: String,
        repeat: usize,
    ) -> Result<Run, GpuError> {
        let mut inst = self.instantiate(info, params, label, &view.light)?;
        self.step(view, &mut inst, true, repeat)
    }

    /// Creates a technique for `light` once, to be run on a sequence of views with
    /// [`Lab::step`] (camera paths: techniques that keep state across frames see them in order).
    pub fn instantiate(
        &self,
        info: &'static TechniqueInfo,
        params: ParamValues,
        label: String,
        light: &Light,
    ) -> Result<Instance, GpuError> {
        let t0 = std::time::Instant::now();
        let tech = (info.create)(self.gpu, &self.gscene, &params, light)?;
        self.gpu.take_error()?;
        Ok(Instance { label, info, params, tech, setup_ms: t0.elapsed().as_secs_f64() * 1e3 })
    }

    /// Runs `inst` on `view`: once untimed when `warm_up`, then `repeat` times timed (at least
    /// once); then shades and reads back its visibility and report.
    /// The scene is moved to the view's time first if it was moved elsewhere since.
    pub fn step(&self, view: &View, inst: &mut Instance, warm_up: bool, repeat: usize) -> Result<Run, GpuError> {
        let gpu = self.gpu;
        self.set_time(view.time, view.prev_time)?;
        let inputs = view.inputs(&self.gscene);
        let tech = inst.tech.as_mut();
        if warm_up {
            techniques::run_frame(tech, gpu, &inputs, &mut StageTimer::default())?;
            gpu.take_error()?;
        }
        let mut timer = StageTimer::default();
        for _ in 0..repeat.max(1) {
            techniques::run_frame(tech, gpu, &inputs, &mut timer)?;
        }
        gpu.take_error()?;
        let stages_ms = timer.medians();
        let total_ms = stages_ms.values().sum();
        let visibility: Vec<f32> = gpu.read_buffer_as(&view.visibility, view.gbuffer.pixels());
        let report = tech.report(gpu);
        let mut shade_timer = StageTimer::default();
        let shaded = self.shade_pass.shade(gpu, &mut shade_timer, &inputs, &view.color);
        gpu.take_error()?;
        Ok(Run {
            label: inst.label.clone(),
            technique: inst.info.name,
            params: inst.params.clone(),
            visibility,
            shaded,
            report,
            stages_ms,
            total_ms,
            setup_ms: inst.setup_ms,
        })
    }

    /// The reference on this view.
    pub fn reference(&self, view: &View, repeat: usize) -> Result<Run, GpuError> {
        self.run_resolved(view, &crate::reference::INFO, ParamValues::default(), "rt".into(), repeat)
    }
}
