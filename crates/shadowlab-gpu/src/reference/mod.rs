//! `rt`: the exact reference. Traces one shadow ray per evaluated G-buffer sample through the
//! scene BVH in a compute shader (no hardware ray tracing needed). It is also registered as a
//! technique so its cost can be compared with the others.

use shadowlab_core::params::ParamTable;

use crate::record::Recorder;
use crate::scene_gpu::GpuScene;
use crate::technique::{compose_view, view_layout, FrameInputs, Technique, TechniqueInfo, TechniqueReport};
use crate::{binding, Gpu, GpuError};

/// The shadow-ray library (`occluded`, `sample_shadowed`): needs `scene.wgsl` and the view
/// inputs of `view.wgsl` (the light uniform). Techniques that trace rays compose it in front of
/// their own body: `compose_view(&format!("{TRACE_WGSL}{body}"), true)`.
pub const TRACE_WGSL: &str = include_str!("trace.wgsl");
const RT_WGSL: &str = include_str!("rt.wgsl");

fn rt_src() -> String {
    compose_view(&format!("{TRACE_WGSL}{RT_WGSL}"), true)
}

pub fn shaders() -> Vec<(&'static str, String)> {
    vec![("rt.wgsl", rt_src())]
}

pub const INFO: TechniqueInfo = TechniqueInfo {
    name: "rt",
    summary: "exact ray-traced hard shadows: one shadow ray per evaluated pixel through a BVH in compute (the reference)",
    cost: "one ray per evaluated pixel; grows with screen size and scene depth complexity",
    quality: "exact (the reference all others are measured against); honours alpha cut-outs",
    source: "Whitted 1980; BVH by obvhs (PLOC + SAH reinsertion)",
    lights: &["directional", "spot", "point"],
    params: ParamTable::NONE,
    stalls: "",
    needs: "",
    storage_buffers: 8,
    compare: &[],
    shaders,
    create: |gpu, scene, _params, _light| Ok(Box::new(RayTraced::new(gpu, scene))),
};

pub struct RayTraced {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    groups: crate::binding::GroupCache,
    rays: wgpu::Buffer,
    bvh_bytes: usize,
}

impl RayTraced {
    pub fn new(gpu: &Gpu, scene: &GpuScene) -> RayTraced {
        let layout = view_layout(gpu, "rt", &[binding::storage(false)]);
        let pipeline = gpu.compute_pipeline("rt", &rt_src(), "main", &[&layout, &scene.layout]);
        RayTraced { pipeline, layout, groups: Default::default(), rays: gpu.storage("rt.rays", 4), bvh_bytes: scene.bvh_bytes }
    }
}

impl Technique for RayTraced {
    /// The BVH is built and uploaded with the scene: nothing to render per frame.
    fn render(&mut self, _gpu: &Gpu, _f: &FrameInputs, _rec: &mut Recorder) -> Result<(), GpuError> {
        Ok(())
    }

    fn evaluate(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        let group = f.view_group(gpu, &self.groups, "rt", &self.layout, &[self.rays.as_entire_binding()]);
        rec.stage("rt.trace", |enc| {
            enc.clear_buffer(&self.rays, 0, None);
            gpu.dispatch_2d(enc, "rt.trace", &self.pipeline, &[&group, &f.scene.group], f.gbuffer.width, f.gbuffer.height)
        });
        Ok(())
    }

    fn report(&mut self, gpu: &Gpu) -> TechniqueReport {
        let rays = gpu.read_buffer_as::<u32>(&self.rays, 1)[0];
        let mut r = TechniqueReport { shadow_data_bytes: self.bvh_bytes as u64, ..Default::default() };
        r.counters.insert("rays_traced".into(), rays as f64);
        r
    }
}
