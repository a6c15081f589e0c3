//! A technique added from outside the crate, as docs/adding-a-technique.md describes: one
//! parameter set, one registry entry (`TechniqueInfo`), one shader, one `impl Technique`, and
//! nothing else to edit. `threshold` is a toy with an answer known in advance: a pixel is lit
//! when its world height is at least `height`, so on `planebox` (a ground plane at y = 0 under
//! a box) `height=-1` lights every evaluated pixel and `height=100` none, and `rt`'s shadowed
//! pixels are exactly the first one's false-lit pixels.

use shadowlab_core::builtin::builtin;
use shadowlab_core::metrics::compare;
use shadowlab_core::params::{ParamDef, ParamSet, ParamTable, TechniqueSpec};
use shadowlab_gpu::lab::Lab;
use shadowlab_gpu::record::Recorder;
use shadowlab_gpu::registry::Resolved;
use shadowlab_gpu::technique::{compose_view, view_layout, FrameInputs, Technique, TechniqueInfo, TechniqueReport};
use shadowlab_gpu::{Gpu, GpuError};

use crate::common::*;

shadowlab_core::param_set! {
    /// `threshold`'s one parameter.
    pub struct ThresholdSettings {
        pub height: f32 = ParamDef::number("height", 0.5, -1e3, 1e3, "world height at and above which a pixel is lit", "test"),
    }
}

const EVAL: &str = r#"
@group(0) @binding(6) var<uniform> height: vec4<f32>;
@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    var s: Sample;
    if !load_sample(id, &s) { return; }
    visibility[s.i] = select(0.0, 1.0, s.p.y >= height.x);
}
"#;

fn shaders() -> Vec<(&'static str, String)> {
    vec![("threshold.wgsl", compose_view(EVAL, false))]
}

static INFO: TechniqueInfo = TechniqueInfo {
    name: "threshold",
    summary: "test-only: lit above a height",
    cost: "one fetch per pixel",
    quality: "a toy",
    source: "tests/new_technique.rs",
    lights: &["directional", "spot", "point"],
    params: ParamTable::of::<ThresholdSettings>(),
    stalls: "",
    needs: "",
    storage_buffers: 8,
    compare: &[],
    shaders,
    create: |gpu, _scene, p, _light| Ok(Box::new(Threshold::new(gpu, &ThresholdSettings::from_values(p)))),
};

struct Threshold {
    uniform: wgpu::Buffer,
    layout: wgpu::BindGroupLayout,
    /// The evaluation's bind group, kept while the frame's inputs are the same.
    groups: shadowlab_gpu::binding::GroupCache,
    pipeline: wgpu::ComputePipeline,
}

impl Threshold {
    fn new(gpu: &Gpu, p: &ThresholdSettings) -> Threshold {
        let uniform = gpu.uniform("threshold.params", &[p.height, 0.0, 0.0, 0.0]);
        let layout = view_layout(gpu, "threshold.eval", &[shadowlab_gpu::binding::uniform()]);
        let pipeline = gpu.compute_pipeline("threshold.eval", &shaders()[0].1, "main", &[&layout]);
        Threshold { uniform, layout, groups: Default::default(), pipeline }
    }
}

impl Technique for Threshold {
    fn render(&mut self, _gpu: &Gpu, _f: &FrameInputs, _rec: &mut Recorder) -> Result<(), GpuError> {
        Ok(())
    }
    fn evaluate(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        let group = f.view_group(gpu, &self.groups, "threshold.eval", &self.layout, &[self.uniform.as_entire_binding()]);
        let (w, h) = (f.gbuffer.width, f.gbuffer.height);
        rec.stage("threshold.evaluate", |enc| gpu.dispatch_2d(enc, "threshold.evaluate", &self.pipeline, &[&group], w, h));
        Ok(())
    }
    fn report(&mut self, _gpu: &Gpu) -> TechniqueReport {
        TechniqueReport { shadow_data_bytes: 16, ..Default::default() }
    }
}

fn resolve(spec: &str) -> Result<Resolved, String> {
    let spec = TechniqueSpec::parse(spec)?;
    let values = spec.resolve(INFO.params())?;
    Ok(Resolved::new(&INFO, values, spec.label()))
}

#[test]
fn a_technique_added_in_one_place_runs_in_the_lab_against_rt() {
    // its table is listed and checked like the registry's, without a GPU
    assert_eq!(INFO.params().iter().map(|d| d.key).collect::<Vec<_>>(), ["height"]);
    assert!(resolve("threshold:hieght=1").unwrap_err().contains("no parameter 'hieght' (valid: height, label)"));
    assert!(naga::front::wgsl::parse_str(&shaders()[0].1).is_ok());
    let Some(gpu) = gpu() else { return };
    let scene = builtin("planebox").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 0, 64);
    let rt = lab.reference(&v, 1).unwrap();
    let all = lab.run_resolved(&v, &resolve("threshold:height=-1").unwrap(), 1).unwrap();
    let none = lab.run_resolved(&v, &resolve("threshold:height=100").unwrap(), 1).unwrap();
    let evaluated = v.mask.iter().filter(|m| **m != 0).count();
    let shadowed = rt.visibility.iter().zip(&v.mask).filter(|(x, m)| **m != 0 && **x < 0.5).count();
    assert!(evaluated > 1000 && shadowed > 20 && shadowed < evaluated, "{shadowed} of {evaluated}");
    let m = compare(&all.visibility, &rt.visibility, &v.mask);
    assert_eq!(m.false_shadow_pct, 0.0);
    assert!((m.false_lit_pct - 100.0 * shadowed as f64 / evaluated as f64).abs() < 1e-9, "{m:?}");
    let m = compare(&none.visibility, &rt.visibility, &v.mask);
    assert!((m.false_shadow_pct - 100.0 * (evaluated - shadowed) as f64 / evaluated as f64).abs() < 1e-9, "{m:?}");
    assert_eq!((all.technique, all.report.shadow_data_bytes, all.submits_per_frame), ("threshold", 16, 1));
}
