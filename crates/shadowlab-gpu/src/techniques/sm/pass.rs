//! `sm`'s passes as parts other techniques reuse: [`DepthPass`] (the scene's depth from a light
//! view-projection into a `res x res` map, `depth.wgsl`) and [`MapPass`] (that depth pass plus
//! the biased / PCF evaluation of `eval.wgsl`, the per-texel sample counts and the report).
//! `sm` fits the projection once to the scene; `min-sm` refits it every frame; `mdsm` renders
//! its base map with the depth pass alone.

use shadowlab_core::lightspace::LightProjection;
use shadowlab_core::metrics::sampling_stats;
use shadowlab_core::params::family::Bias;

use super::{depth_source, eval_source, MapSettings, SmParams};
use crate::record::Recorder;
use crate::scene_gpu::GpuScene;
use crate::technique::{view_layout, EvalPipelines, FrameInputs, TechniqueReport};
use crate::techniques::pictures::{count_image, depth_image};
use crate::{binding, raster, Gpu};

impl SmParams {
    /// The uniform for projection `lp` of a `res x res` map with `bias`, `kernel` = PCF grid width.
    pub fn new(lp: &LightProjection, res: u32, kernel: f32, bias: &Bias) -> SmParams {
        SmParams {
            light_view_proj: lp.view_proj.to_cols_array_2d(),
            texel: [lp.texel, lp.perspective as u32 as f32, res as f32, kernel],
            bias: bias.packed(),
        }
    }
}

/// The depth-only pass into a `res x res` Depth32Float map (`{name}.map`, stage `{name}.render`).
pub struct DepthPass {
    name: &'static str,
    pub res: u32,
    pub map: wgpu::Texture,
    /// The map's view (render target and evaluation binding, made once).
    pub map_view: wgpu::TextureView,
    /// `SmParams` (the depth pass reads only `light_view_proj`).
    pub uniform: wgpu::Buffer,
    pipeline: wgpu::RenderPipeline,
    group: wgpu::BindGroup,
}

impl DepthPass {
    /// `name` prefixes the labels and the stage name; the caller has checked `res`.
    pub fn new(gpu: &Gpu, scene: &GpuScene, name: &'static str, res: u32, params: &SmParams) -> DepthPass {
        let d = &gpu.device;
        let map = raster::depth_target(gpu, &format!("{name}.map"), res, res, 1, wgpu::TextureUsages::empty());
        let uniform = gpu.uniform(&format!("{name}.params"), params);
        let label = format!("{name}.depth");
        let layout = binding::layout(d, &label, wgpu::ShaderStages::VERTEX, &[binding::uniform()]);
        let group = binding::group(gpu, &label, &layout, &[uniform.as_entire_binding()]);
        let pipeline = raster::depth_pipeline(gpu, &label, &depth_source(), &[&layout, &scene.layout], scene.has_cutouts);
        DepthPass { name, res, map_view: map.create_view(&Default::default()), map, uniform, pipeline, group }
    }

    /// Uploads a new uniform (projection, texel, bias).
    pub fn set(&self, rec: &mut Recorder, params: &SmParams) {
        rec.write_buffer(&self.uniform, 0, bytemuck::bytes_of(params));
    }

    /// Clears the map and draws the scene into it.
    pub fn render(&self, _gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) {
        let map_view = &self.map_view;
        let stage = format!("{}.render", self.name);
        rec.stage(&stage, |enc| {
            let mut pass = raster::begin_pass(enc, &stage, &[], &map_view);
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.group, &[]);
            pass.set_bind_group(1, &f.scene.group, &[]);
            pass.draw(0..f.scene.triangle_count * 3, 0..1);
        });
    }

    /// The map, row-major.
    pub fn read(&self, gpu: &Gpu) -> Vec<f32> {
        bytemuck::pod_collect_to_vec(&gpu.read_texture(&self.map, 4))
    }
}

/// `sm`'s shadow map: depth pass, evaluation with hardware comparison (`{name}.evaluate`), the
/// view samples counted per texel.
pub struct MapPass {
    pub depth: DepthPass,
    pub pcf: u32,
    pub params: SmParams,
    counts: wgpu::Buffer,
    /// The evaluation and its analysis variant.
    eval: EvalPipelines,
    eval_layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    groups: crate::binding::GroupCache,
}

impl MapPass {
    /// A `res x res` map (`res` checked by the caller) with `pcf` and `bias` over projection `lp`.
    pub fn new(gpu: &Gpu, scene: &GpuScene, name: &'static str, map: &MapSettings, lp: &LightProjection) -> MapPass {
        let (res, pcf) = (map.res, map.pcf);
        let params = SmParams::new(lp, res, pcf as f32, &map.bias);
        let depth = DepthPass::new(gpu, scene, name, res, &params);
        let label = format!("{name}.eval");
        let eval_layout = view_layout(
            gpu,
            &label,
            &[binding::uniform(), binding::texture_depth(), binding::comparison_sampler(), binding::storage(false)],
        );
        let eval = EvalPipelines::new(gpu, &label, &eval_source(), &eval_layout, &[("PCF", pcf as f64)]);
        let sampler = raster::comparison_sampler(gpu, &format!("{name}.cmp"));
        let counts = gpu.storage(&format!("{name}.counts"), res as u64 * res as u64 * 4);
        MapPass { depth, pcf, params, counts, eval, eval_layout, sampler, groups: Default::default() }
    }

    pub fn res(&self) -> u32 {
        self.depth.res
    }

    /// Points the map at a new projection (texel size and perspective flag with it) for the
    /// next render and evaluation.
    pub fn set_projection(&mut self, rec: &mut Recorder, view_proj: glam::Mat4, texel: f32, perspective: bool) {
        self.params.light_view_proj = view_proj.to_cols_array_2d();
        self.params.texel[0] = texel;
        self.params.texel[1] = perspective as u32 as f32;
        self.depth.set(rec, &self.params);
    }

    pub fn render(&self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) {
        self.depth.render(gpu, f, rec);
    }

    fn eval_group(&self, gpu: &Gpu, f: &FrameInputs) -> wgpu::BindGroup {
        let map_view = &self.depth.map_view;
        f.view_group(
            gpu,
            &self.groups,
            &format!("{}.eval", self.depth.name),
            &self.eval_layout,
            &[
                self.depth.uniform.as_entire_binding(),
                wgpu::BindingResource::TextureView(&map_view),
                wgpu::BindingResource::Sampler(&self.sampler),
                self.counts.as_entire_binding(),
            ],
        )
    }

    /// Shadow test of every view sample.
    pub fn evaluate(&self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) {
        let group = self.eval_group(gpu, f);
        let stage = format!("{}.evaluate", self.depth.name);
        self.eval.record(gpu, rec, &stage, &self.counts, &group, f.gbuffer.width, f.gbuffer.height, false);
    }

    /// The lab's analysis: the evaluation again with the view samples counted per texel.
    pub fn analyze(&self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) {
        let group = self.eval_group(gpu, f);
        let stage = format!("{}.analysis", self.depth.name);
        self.eval.record(gpu, rec, &stage, &self.counts, &group, f.gbuffer.width, f.gbuffer.height, true);
    }

    /// `sm`'s report (memory, sampling, fetches, texels, depth and count pictures) and the
    /// per-texel sample counts it was made from.
    pub fn report(&self, gpu: &Gpu) -> (TechniqueReport, Vec<u32>) {
        let res = self.res();
        let n = (res * res) as usize;
        let counts: Vec<u32> = gpu.read_buffer_as(&self.counts, n);
        let depth = self.depth.read(gpu);
        let mut r = TechniqueReport { shadow_data_bytes: n as u64 * 4, sampling: Some(sampling_stats(&counts)), ..Default::default() };
        r.counters.insert("fetches_per_pixel".into(), (self.pcf * self.pcf) as f64);
        r.counters.insert("shadow_map_texels".into(), n as f64);
        r.images.push(depth_image("shadow map (depth)", res, &depth));
        r.images.push(count_image("view samples per texel", res, &counts));
        (r, counts)
    }
}
