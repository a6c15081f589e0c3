//! Leak tracing's `<name>.classify` pass (classify.wgsl): every evaluated pixel's test (LTT on
//! the filterable bound, or hybrid-pcf's unanimous 2x2), the temporal mask read from last
//! frame's reprojected pixel, and the pixels needing a ray appended to the list (atomic append).

use super::resources::Resources;
use super::screen::Screen;
use super::uniforms::{LtParams, FLAG_POINT};
use crate::record::Recorder;
use crate::shaders::flag;
use crate::technique::{compose_view, view_layout, FrameInputs};
use crate::techniques::filtered::MOMENTS_WGSL;
use crate::{binding, Gpu};

const CLASSIFY_WGSL: &str = include_str!("classify.wgsl");

pub(super) fn source() -> String {
    compose_view(&format!("{MOMENTS_WGSL}{CLASSIFY_WGSL}"), false)
}

pub(super) struct ClassifyPass {
    /// One kept group per frame parity (the masks swap roles each frame).
    pub(crate) groups: [crate::binding::GroupCache; 2],
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
}

impl ClassifyPass {
    /// The pass, specialised to `p`'s technique, base representation, projection and light kind
    /// (classify.wgsl's pipeline constants).
    pub fn new(gpu: &Gpu, name: &str, p: &LtParams) -> ClassifyPass {
        let nf = wgpu::BindingType::Sampler(wgpu::SamplerBindingType::NonFiltering);
        let (ro, rw, tex) = (binding::storage(true), binding::storage(false), binding::texture_float());
        let arr = wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: false },
            view_dimension: wgpu::TextureViewDimension::D2Array,
            multisampled: false,
        };
        let layout = view_layout(gpu, &format!("{name}.classify"), &[binding::uniform(), arr, arr, nf, tex, ro, rw, ro, rw, rw]);
        let constants = [
            ("TECHNIQUE", p.technique as f64),
            ("BASE", p.base as f64),
            ("PERSPECTIVE", flag(p.perspective > 0.5)),
            ("POINT", flag(p.flags & FLAG_POINT != 0)),
        ];
        let pipeline = gpu.compute_pipeline_with(&format!("{name}.classify"), &source(), "main", &[&layout], &constants);
        ClassifyPass { groups: Default::default(), layout, pipeline }
    }

    /// The bind group of the frame `s` is at: both maps (the static one again without a dynamic
    /// map), the motion vectors, last frame's mask and history (read), this frame's (written)
    /// and the ray list. Both parities' groups are made on the first frame.
    pub fn group(&self, gpu: &Gpu, f: &FrameInputs, name: &str, r: &Resources, s: &Screen) -> wgpu::BindGroup {
        let cur = (s.frames % 2) as usize;
        let [now, _next] = [cur, 1 - cur].map(|p| self.parity_group(gpu, f, name, r, s, p));
        now
    }

    fn parity_group(&self, gpu: &Gpu, f: &FrameInputs, name: &str, r: &Resources, s: &Screen, cur: usize) -> wgpu::BindGroup {
        let prev = 1 - cur;
        use wgpu::BindingResource as R;
        f.view_group(
            gpu,
            &self.groups[cur],
            &format!("{name}.classify"),
            &self.layout,
            &[
                r.uniform.as_entire_binding(),
                R::TextureView(&r.map_views[0]),
                R::TextureView(&r.map_views[1]),
                R::Sampler(&r.sampler),
                R::TextureView(&f.gbuffer.motion_view),
                s.masks[prev].as_entire_binding(),
                s.masks[cur].as_entire_binding(),
                s.history[prev].as_entire_binding(),
                s.history[cur].as_entire_binding(),
                s.list.as_entire_binding(),
            ],
        )
    }

    /// Stage `<name>.classify`: this frame's mask and the list's count cleared, then every pixel.
    pub fn record(&self, gpu: &Gpu, rec: &mut Recorder, name: &str, group: &wgpu::BindGroup, s: &Screen) {
        let cur = (s.frames % 2) as usize;
        let label = format!("{name}.classify");
        rec.stage(&label, |enc| {
            enc.clear_buffer(&s.masks[cur], 0, None);
            enc.clear_buffer(&s.list, 0, Some(4));
            gpu.dispatch_2d(enc, &label, &self.pipeline, &[group], s.width, s.height);
        });
    }
}
