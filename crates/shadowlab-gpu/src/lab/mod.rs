//! The lab: one scene on the GPU, views prepared once (G-buffer, mask, reference), techniques
//! run against them. The CLI and the integration tests both drive this; [`path`] runs the
//! reference and techniques over a camera path ([`Lab::run_path`]), [`summary`] sums it up.

pub mod path;
pub mod summary;

pub use path::{FrameRecord, PathError, PathRun, PathSpec, Progress, ReferenceFrame, TechniqueFrames};
pub use summary::{reference_total_ms, summarize, Summary};

use std::cell::Cell;
use std::collections::BTreeMap;

use shadowlab_core::bvh::Bvh;
use shadowlab_core::camera::Camera;
use shadowlab_core::light::Light;
use shadowlab_core::params::{ParamValues, TechniqueSpec};
use shadowlab_core::scene::Scene;

use crate::frame::{FrameUniform, LightUniform};
use crate::gbuffer::{GBuffer, GBufferPass};
use crate::record::{self, Clock, FrameStamps, Recorder};
use crate::registry::{self, Resolved};
use crate::scene_gpu::GpuScene;
use crate::shade::ShadePass;
use crate::technique::{self, FrameInputs, TechniqueInfo, TechniqueReport};
use crate::timing::median;
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
    /// The one query set of a timed frame's stage timestamps (adapters with sane timestamps).
    stamps: Option<FrameStamps>,
    /// Whether the G-buffer and mask passes have run once (untimed warm-up).
    gbuffer_warm: Cell<bool>,
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
    /// G-buffer and mask stage times (ms): GPU timestamps of the timed frame, or the profiled
    /// breakdown (see [`Gpu::stages_timer_name`]); with `scene.animate` when objects move.
    pub stages_ms: BTreeMap<String, f64>,
    /// The G-buffer + mask frame: one submit, one wait (ms; see [`Gpu::timer_name`]).
    pub frame_ms: f64,
}

/// A technique created for one light, kept across the views of a path.
pub struct Instance {
    pub label: String,
    pub info: &'static TechniqueInfo,
    pub params: ParamValues,
    pub tech: Box<dyn technique::Technique>,
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
    /// Per-stage ms: the timed frames' GPU timestamps (median per stage) on adapters with sane
    /// timestamps; else the profiled breakdown (a wait per stage) when one was run
    /// ([`Lab::profile`]), else empty. Never the sum that makes `total_ms`.
    pub stages_ms: BTreeMap<String, f64>,
    /// The timed frame (median over the timed repetitions): one recorded frame, one submit and
    /// one wait (ms; [`Gpu::timer_name`] says which clock).
    pub total_ms: f64,
    /// Submits of one timed frame (1 without mid-frame readbacks).
    pub submits_per_frame: u64,
    /// Mid-frame readbacks of one timed frame, by stage name.
    pub stalls: Vec<String>,
    /// Pipeline and resource creation (not part of total_ms).
    pub setup_ms: f64,
}

impl<'a> Lab<'a> {
    pub fn new(gpu: &'a Gpu, scene: &'a Scene) -> Result<Lab<'a>, GpuError> {
        crate::gbuffer::check_limits(&gpu.limits)?;
        let bvh = Bvh::build(scene).map_err(GpuError::Invalid)?;
        let gscene = GpuScene::from_scene(gpu, scene, &bvh)?;
        let gbuffer_pass = GBufferPass::new(gpu, &gscene);
        let shade_pass = ShadePass::new(gpu);
        gpu.take_error()?;
        let stamps = gpu.gpu_timestamps.then(|| FrameStamps::new(gpu));
        Ok(Lab {
            gpu,
            scene,
            bvh,
            gscene,
            gbuffer_pass,
            shade_pass,
            time: Cell::new((0.0, 0.0)),
            animate_ms: Cell::new(0.0),
            stamps,
            gbuffer_warm: Cell::new(false),
        })
    }

    /// Moves the scene's moving objects to time `t` (frames), with motion vectors against
    /// `prev_t`; the following views are rendered at that time (see [`View::time`]). Cheap when
    /// nothing moves or the time is unchanged. Starts at (0, 0).
    pub fn set_time(&self, t: f32, prev_t: f32) -> Result<(), GpuError> {
        if self.time.get() == (t, prev_t) && t.is_finite() {
            return Ok(());
        }
        let t0 = web_time::Instant::now();
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
        let record = |rec: &mut Recorder| {
            self.gbuffer_pass.render(gpu, rec, &self.gscene, &frame, &g);
            self.gbuffer_pass.mask(gpu, rec, &frame, &light_buf, &g);
        };
        if !self.gbuffer_warm.replace(true) {
            // the first frame compiles the pipelines' shaders (llvmpipe compiles on first use)
            self.timed_frame(|rec| {
                record(rec);
                Ok(())
            })?;
        }
        let (frame_ms, stamped) = self.timed_frame(|rec| {
            record(rec);
            Ok(())
        })?;
        let mut stages_ms = match stamped {
            Some(s) => s,
            None => self.profiled_frame(|rec| {
                record(rec);
                Ok(())
            })?,
        };
        gpu.take_error()?;
        let position: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&gpu.read_texture(&g.position, 16));
        let normal: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&gpu.read_texture(&g.normal, 16));
        let mask: Vec<u32> = gpu.read_buffer_as(&g.mask, g.pixels());
        let visibility = gpu.storage("visibility", g.pixels() as u64 * 4);
        let color = ShadePass::output(gpu, &g);
        let (time, prev_time) = self.time.get();
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
            frame_ms,
        })
    }

    /// Records one frame with `f`, submits it once and waits: (wall ms, per-stage GPU ms when
    /// the adapter has sane timestamps). Mid-frame syncs inside `f` add their submits.
    fn timed_frame(&self, f: impl FnOnce(&mut Recorder) -> Result<(), GpuError>) -> Result<(f64, Option<BTreeMap<String, f64>>), GpuError> {
        let d = record::drive(self.gpu, "frame", Clock::of(self.stamps.as_ref()), f)?;
        Ok((d.wall_ms, d.stamped_ms))
    }

    /// One profiled frame of `f`: each stage submitted and waited for alone (the breakdown).
    fn profiled_frame(&self, f: impl FnOnce(&mut Recorder) -> Result<(), GpuError>) -> Result<BTreeMap<String, f64>, GpuError> {
        Ok(record::drive(self.gpu, "profiled frame", Clock::Profiled, f)?.profile_ms)
    }

    /// Resolves `spec`, creates the technique, runs it once to warm up and `repeat` more times
    /// timed, then shades and reads back its visibility.
    pub fn run(&self, view: &View, spec: &TechniqueSpec, repeat: usize) -> Result<Run, GpuError> {
        self.run_resolved(view, &registry::resolve(spec, Some(&view.light))?, repeat)
    }

    /// [`Lab::run`] for a spec resolved once by the caller.
    pub fn run_resolved(&self, view: &View, spec: &Resolved, repeat: usize) -> Result<Run, GpuError> {
        let mut inst = self.instantiate(spec, &view.light)?;
        let mut run = self.step(view, &mut inst, true, repeat)?;
        if !self.gpu.gpu_timestamps {
            // timestamp adapters have the stages of the timed frames already
            run.stages_ms = self.profile(view, &mut inst)?;
        }
        Ok(run)
    }

    /// One more frame of `inst` on `view`, profiled: each stage submitted and waited for alone,
    /// timed by the wall clock. The breakdown of where a frame's time goes on adapters without
    /// sane timestamps; never added up as the frame's time. It advances `inst` by one frame
    /// (techniques with history see it), so callers run it after the frames they measure.
    pub fn profile(&self, view: &View, inst: &mut Instance) -> Result<BTreeMap<String, f64>, GpuError> {
        self.set_time(view.time, view.prev_time)?;
        let inputs = view.inputs(&self.gscene);
        let tech = inst.tech.as_mut();
        let ms = self.profiled_frame(|rec| technique::run_frame(tech, self.gpu, &inputs, rec))?;
        self.gpu.take_error()?;
        Ok(ms)
    }

    /// Creates a technique for `light` once, to be run on a sequence of views with
    /// [`Lab::step`] (camera paths: techniques that keep state across frames see them in order).
    pub fn instantiate(&self, spec: &Resolved, light: &Light) -> Result<Instance, GpuError> {
        spec.check_light(light)?;
        spec.info.check_limits(&self.gpu.limits)?;
        let t0 = web_time::Instant::now();
        let tech = spec.info.create(self.gpu, &self.gscene, &spec.values, light)?;
        self.gpu.take_error()?;
        Ok(Instance {
            label: spec.label.clone(),
            info: spec.info,
            params: spec.values.clone(),
            tech,
            setup_ms: t0.elapsed().as_secs_f64() * 1e3,
        })
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
            technique::submit_frame(tech, gpu, &inputs)?;
            gpu.wait();
            gpu.take_error()?;
        }
        let mut totals = Vec::new();
        let mut stamped: BTreeMap<String, Vec<f64>> = BTreeMap::new();
        let mut stalls = Vec::new();
        let (mut submits, mut dispatches) = (0, 0);
        for _ in 0..repeat.max(1) {
            let (before, before_dispatches) = (gpu.submit_count(), gpu.dispatches());
            let mut frame_stalls = Vec::new();
            let (ms, stages) = self.timed_frame(|rec| {
                technique::run_frame(tech, gpu, &inputs, rec)?;
                frame_stalls = rec.stalls().to_vec();
                Ok(())
            })?;
            submits = gpu.submit_count() - before;
            dispatches = gpu.dispatches() - before_dispatches;
            stalls = frame_stalls;
            // a timestamped frame's time is the sum of its stages' GPU time
            totals.push(stages.as_ref().map_or(ms, |s| s.values().sum()));
            for (k, v) in stages.unwrap_or_default() {
                stamped.entry(k).or_default().push(v);
            }
        }
        gpu.take_error()?;
        let stages_ms: BTreeMap<String, f64> = stamped.iter().map(|(k, v)| (k.clone(), median(v))).collect();
        let total_ms = median(&totals);
        let visibility: Vec<f32> = gpu.read_buffer_as(&view.visibility, view.gbuffer.pixels());
        // lab-only analysis passes, after the timed frames
        record::drive(gpu, "analysis", Clock::Wall, |rec| tech.analyze(gpu, &inputs, rec))?;
        gpu.take_error()?;
        let mut report = tech.report(gpu);
        // compute dispatches of the last timed frame (Gpu::dispatch counts them): a cost any
        // GPU pays per frame, whatever its speed
        report.counters.insert("dispatches_per_frame".into(), dispatches as f64);
        let shaded = self.shade_pass.shade(gpu, &inputs, &view.color);
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
            submits_per_frame: submits,
            stalls,
            setup_ms: inst.setup_ms,
        })
    }

    /// The reference on this view.
    pub fn reference(&self, view: &View, repeat: usize) -> Result<Run, GpuError> {
        self.run_resolved(view, &registry::reference(), repeat)
    }
}
