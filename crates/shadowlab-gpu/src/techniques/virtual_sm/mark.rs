//! `virtual`'s marking `virtual.mark` (mark.wgsl): every view sample flags the pages it reads
//! (and the coarser candidates a full pool falls back to) and counts its samples; the flags,
//! and the moving chunks' boxes bounded in the same stage, are read back (`virtual.readback`,
//! the one sync of a frame) for the CPU's allocation.

use shadowlab_core::techniques::virtual_sm::Clipmap;

use super::bounds::ChunkBounds;
use super::resources::Resources;
use super::uniforms::PAGES_WGSL;
use crate::record::Recorder;
use crate::technique::{compose_view, view_layout, FrameInputs};
use crate::techniques::cube::FACES_WGSL;
use crate::{binding, Gpu};

const MARK_WGSL: &str = include_str!("mark.wgsl");

pub(super) fn source() -> String {
    compose_view(&format!("{FACES_WGSL}{PAGES_WGSL}{MARK_WGSL}"), false)
}

pub(super) struct MarkPass {
    pub(crate) groups: crate::binding::GroupCache,
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
}

impl MarkPass {
    pub fn new(gpu: &Gpu) -> MarkPass {
        let layout = view_layout(gpu, "virtual.mark", &[binding::uniform(), binding::storage(false)]);
        let pipeline = gpu.compute_pipeline("virtual.mark", &source(), "main", &[&layout]);
        MarkPass { groups: Default::default(), layout, pipeline }
    }

    /// Marks the pages of clipmap `c`, bounds the moving chunks (`dynamic`) and reads both back:
    /// the flags of `c.table_len()` entries, then 6 words per moving chunk.
    pub fn record(
        &self,
        gpu: &Gpu,
        f: &FrameInputs,
        rec: &mut Recorder,
        r: &Resources,
        c: &Clipmap,
        dynamic: Option<&ChunkBounds>,
    ) -> Vec<u32> {
        let group =
            f.view_group(gpu, &self.groups, "virtual.mark", &self.layout, &[r.uniform.as_entire_binding(), r.requests.as_entire_binding()]);
        let table_bytes = c.table_len() as u64 * 4;
        rec.stage("virtual.mark", |enc| {
            enc.clear_buffer(&r.requests, 0, None);
            gpu.dispatch_2d(enc, "virtual.mark", &self.pipeline, &[&group], f.gbuffer.width, f.gbuffer.height);
            enc.copy_buffer_to_buffer(&r.requests, 0, &r.probe, 0, table_bytes);
            if let Some(b) = dynamic {
                b.record(gpu, enc, f.scene);
                enc.copy_buffer_to_buffer(&b.boxes, 0, &r.probe, table_bytes, b.count as u64 * 24);
            }
        });
        let words = c.table_len() + dynamic.map_or(0, |b| b.count as usize * 6);
        rec.read_buffer_as(&r.probe, words, "virtual.readback")
    }
}
