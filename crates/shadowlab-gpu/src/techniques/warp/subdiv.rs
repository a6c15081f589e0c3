//! The subdivision before the warped depth pass (`render`'s `subdivide` stage, subdiv.wgsl,
//! `subdiv` > 0): a root pass queues every triangle, each level splits the queued pieces whose
//! warped edges bend more than `subdiv` texels into the other queue and finishes the rest, and
//! `draw_args` turns the finished count into the depth pass's indirect draw. With `cull_hidden`
//! the occluder map is drawn first (occluders.rs) and hidden edges stay unsplit.

use super::depth::lookup_entries;
use super::{base_constants, compose, layout_at, WarpParams, Warped, LOOKUP_WGSL, PARAMS_WGSL};
use crate::record::Recorder;
use crate::scene_gpu::GpuScene;
use crate::shaders::flag;
use crate::technique::FrameInputs;
use crate::{binding, Gpu};

const SUBDIV_WGSL: &str = include_str!("subdiv.wgsl");

pub(super) fn source() -> String {
    compose(&format!("{PARAMS_WGSL}{LOOKUP_WGSL}{SUBDIV_WGSL}"), true)
}

/// The subdivision layout (the lookup, the pieces, the counters, the two queues, the level's
/// uniform, the occluder pyramid) and its split_root, split_args, split_level and draw_args,
/// specialised to `p` (params.wgsl's constants and `CULL_HIDDEN`).
pub(super) fn pipelines(gpu: &Gpu, name: &str, scene: &GpuScene, p: &WarpParams) -> (wgpu::BindGroupLayout, [wgpu::ComputePipeline; 4]) {
    let look = lookup_entries();
    let (ro, rw) = (binding::storage(true), binding::storage(false));
    let layout = layout_at(
        gpu,
        &format!("{name}.subdivide"),
        wgpu::ShaderStages::COMPUTE,
        &[look[0], look[1], look[2], look[3], (10, rw), (11, rw), (12, rw), (13, rw), (14, binding::uniform()), (15, ro)],
    );
    let src = source();
    let mut constants = base_constants(p);
    constants.push(("CULL_HIDDEN", flag(p.cull_hidden > 0.5)));
    let pipelines = ["split_root", "split_args", "split_level", "draw_args"]
        .map(|e| gpu.compute_pipeline_with(&format!("{name}.{e}"), &src, e, &[&layout, &scene.layout], &constants));
    (layout, pipelines)
}

/// The subdivision buffers of a warped map (finished pieces and the two level queues), its
/// largest scratch: 66 MB at the minimum capacity of 2^21 pieces. Maps whose passes run one after
/// another (`cube-notw`'s faces: each face subdivides and draws before the next starts) can share
/// one set: `Warped::subdiv_scratch` lends it, `Warped::new_sharing` borrows it when it is large
/// enough for the borrower's triangles (otherwise the borrower allocates its own).
#[derive(Clone)]
pub struct SubdivScratch {
    pieces: wgpu::Buffer,
    queues: [wgpu::Buffer; 2],
}

impl Warped {
    /// This map's subdivision buffers, to lend to maps rendered after it.
    pub fn subdiv_scratch(&mut self) -> SubdivScratch {
        self.shares_subdiv = true;
        SubdivScratch { pieces: self.pieces.clone(), queues: self.queues.clone() }
    }

    /// Uses `s`'s subdivision buffers instead of this map's own (dropped) if they are at least as
    /// large; bind groups are made per frame, so nothing else refers to the old ones.
    pub fn borrow_subdiv(&mut self, s: &SubdivScratch) {
        if s.pieces.size() >= self.pieces.size() && s.queues.iter().zip(&self.queues).all(|(a, b)| a.size() >= b.size()) {
            self.pieces = s.pieces.clone();
            self.queues = s.queues.clone();
            self.owns_subdiv = false;
            self.shares_subdiv = true;
        }
    }

    /// The `subdivide` stage (after the `occluders` stage when `cull_hidden` draws them here);
    /// `depth_group` is the depth pass's group, which the occluder pass shares.
    pub(super) fn subdivide(&self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder, depth_group: &wgpu::BindGroup) {
        let name = self.name();
        if let (Some(o), true) = (&self.occluders, self.params.edge_importance == 0) {
            rec.stage(&format!("{name}.occluders"), |enc| o.record(gpu, enc, depth_group, f.scene));
        }
        rec.stage(&format!("{name}.subdivide"), |enc| self.record_subdivision(gpu, enc, &f.scene.group));
    }

    /// The subdivision's passes over the scene of `scene_group` (the root, each level, the draw
    /// arguments), after this frame's warps and occluder map: the same pieces every time.
    pub(super) fn record_subdivision(&self, gpu: &Gpu, enc: &mut wgpu::CommandEncoder, scene_group: &wgpu::BindGroup) {
        let groups = self.level_groups(gpu);
        let n = self.params.triangles.div_ceil(64);
        enc.clear_buffer(&self.counters, 0, None);
        let pass = |enc: &mut wgpu::CommandEncoder, g: &wgpu::BindGroup, p: usize, groups: Option<u32>| {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("subdivide"), timestamp_writes: None });
            pass.set_bind_group(1, scene_group, &[]);
            pass.set_bind_group(0, g, &[]);
            pass.set_pipeline(&self.split[p]);
            match groups {
                Some(n) => gpu.dispatch(&mut pass, [n.min(65535), n.div_ceil(65535), 1]),
                None => gpu.dispatch_indirect(&mut pass, &self.dispatch, 0),
            }
        };
        pass(enc, &groups[0], 0, Some(n));
        for (l, g) in groups.iter().enumerate().skip(1) {
            pass(enc, g, 1, Some(1));
            // the input queue's group counts, out of the storage buffer into the indirect one
            enc.copy_buffer_to_buffer(&self.counters, 32 + 16 * ((l as u64 + 1) % 2) + 4, &self.dispatch, 0, 12);
            pass(enc, g, 2, None);
        }
        pass(enc, &groups[0], 3, Some(1));
    }

    /// One group per level (0: the root): the depth pass's bindings, the counters, the level's
    /// input and output queues, its uniform and the occluder pyramid (or a stand-in).
    fn level_groups(&self, gpu: &Gpu) -> Vec<wgpu::BindGroup> {
        let name = self.name();
        let mut entries = self.depth_entries();
        entries.push(wgpu::BindGroupEntry { binding: 11, resource: self.counters.as_entire_binding() });
        // level l reads queue (l + 1) % 2 and writes the other; the root writes queue 0
        (0..=self.level_uniforms.len())
            .map(|l| {
                let qi = (l + 1) % 2;
                let mut e = entries.clone();
                e.push(wgpu::BindGroupEntry { binding: 12, resource: self.queues[qi].as_entire_binding() });
                e.push(wgpu::BindGroupEntry { binding: 13, resource: self.queues[1 - qi].as_entire_binding() });
                let u = &self.level_uniforms[l.saturating_sub(1)];
                e.push(wgpu::BindGroupEntry { binding: 14, resource: u.as_entire_binding() });
                let hzb = self.occluders.as_ref().and_then(|o| o.hzb.as_ref()).map_or(&self.dv, |h| &h.buffer);
                e.push(wgpu::BindGroupEntry { binding: 15, resource: hzb.as_entire_binding() });
                self.groups.levels[l].entries(gpu, name, &self.split_layout, &e)
            })
            .collect()
    }
}
