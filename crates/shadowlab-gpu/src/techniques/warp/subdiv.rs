//! The subdivision before the warped depth pass (`render`'s `subdivide` stage, subdiv.wgsl,
//! `subdiv` > 0): a root pass queues every triangle, each level splits the queued pieces whose
//! warped edges bend more than `subdiv` texels into the other queue and finishes the rest, and
//! `draw_args` turns the finished count into the depth pass's indirect draw. With `cull_hidden`
//! the occluder map is drawn first (occluders.rs) and hidden edges stay unsplit; with
//! `tessellate` the queue's first levels only, then tess.wgsl's grids. This is one map's
//! (subdiv_map.wgsl); subdiv_layers.rs runs the same passes over several maps at once.

use super::depth::lookup_entries;
use super::{base_constants, compose, layout_at, Knobs, LayerDraw, WarpParams, Warped, LOOKUP_WGSL, PARAMS_WGSL};
use crate::record::Recorder;
use crate::scene_gpu::GpuScene;
use crate::shaders::flag;
use crate::technique::FrameInputs;
use crate::{binding, Gpu, GpuError};

pub(super) const SUBDIV_WGSL: &str = include_str!("subdiv.wgsl");
pub(super) const TESS_WGSL: &str = include_str!("tess.wgsl");
const SUBDIV_MAP_WGSL: &str = include_str!("subdiv_map.wgsl");

pub(super) fn source() -> String {
    compose(&format!("{PARAMS_WGSL}{LOOKUP_WGSL}{SUBDIV_WGSL}{TESS_WGSL}{SUBDIV_MAP_WGSL}"), true)
}

/// subdiv.wgsl's pipeline constants for `p`'s map over `triangles` triangles that may add
/// `extra` pieces.
pub(super) fn constants(p: &WarpParams, triangles: u32, extra: u32) -> Vec<(&'static str, f64)> {
    let mut c = base_constants(p);
    c.extend([("CULL_HIDDEN", flag(p.cull_hidden > 0.5)), ("TRIANGLES", triangles as f64), ("EXTRA_CAPACITY", extra as f64)]);
    c
}

/// The level queue's passes (subdiv.wgsl), in [`record_passes`]' order.
const QUEUE_ENTRIES: [&str; 4] = ["split_root", "split_args", "split_level", "draw_args"];
/// With `tessellate`: the queue's first levels, then the tessellation's passes (tess.wgsl).
const TESS_ENTRIES: [&str; 10] = [
    "split_root",
    "split_args",
    "split_level",
    "tess_begin",
    "tess_levels",
    "tess_args",
    "tess_alloc",
    "tess_emit_args",
    "tess_emit",
    "draw_args",
];
/// The subdivision's entry points for maps of `p`: the tessellation's or the level queue's.
pub(super) fn entries(p: &WarpParams) -> &'static [&'static str] {
    if p.tessellate != 0 {
        &TESS_ENTRIES
    } else {
        &QUEUE_ENTRIES
    }
}

/// Level uniforms (and groups after the root's) of the subdivision of maps of `p`: one a queue
/// level, and with `tessellate` one more for the tessellation's passes.
pub(super) fn level_count(p: &WarpParams) -> u32 {
    if p.tessellate != 0 {
        p.tessellate.min(p.subdiv_levels) + 1
    } else {
        p.subdiv_levels
    }
}

/// The subdivision layout (the lookup, the pieces, the counters, the two queues, the level's
/// uniform, the occluder pyramid) and its passes ([`entries`]), specialised to `p`
/// (params.wgsl's constants and `CULL_HIDDEN`).
pub(super) fn pipelines(gpu: &Gpu, name: &str, scene: &GpuScene, p: &WarpParams) -> (wgpu::BindGroupLayout, Vec<wgpu::ComputePipeline>) {
    let look = lookup_entries();
    let (ro, rw) = (binding::storage(true), binding::storage(false));
    let layout = layout_at(
        gpu,
        &format!("{name}.subdivide"),
        wgpu::ShaderStages::COMPUTE,
        &[look[0], look[1], look[2], look[3], (10, rw), (11, rw), (12, rw), (13, rw), (14, binding::uniform()), (15, ro)],
    );
    let src = source();
    let constants = constants(p, p.triangles, p.extra_capacity);
    let pipelines = entries(p)
        .iter()
        .map(|e| gpu.compute_pipeline_with(&format!("{name}.{e}"), &src, e, &[&layout, &scene.layout], &constants))
        .collect();
    (layout, pipelines)
}

impl Warped {
    /// The `subdivide` stage (after the `occluders` stage when `cull_hidden` draws them here).
    pub(super) fn subdivide(&self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) {
        self.draw_hidden_occluders(gpu, f, rec);
        rec.stage(&format!("{}.subdivide", self.name()), |enc| self.record_subdivision(gpu, enc, &f.scene.group));
    }

    /// `cull_hidden` without `edge_importance` (which draws it before the count map): the
    /// occluder map and its pyramid, which the subdivision reads (stage `occluders`).
    pub fn draw_hidden_occluders(&self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) {
        if let (Some(o), true) = (&self.occluders, self.params.edge_importance == 0) {
            let depth_group = self.depth_group(gpu);
            let triangles = self.triangles(f.scene);
            rec.stage(&format!("{}.occluders", self.name()), |enc| o.record(gpu, enc, &depth_group, f.scene, triangles));
        }
    }

    /// The triangles of `scene` this map draws: its range of a scene of several maps
    /// ([`Warped::draw_triangles`]), else all.
    pub(super) fn triangles(&self, scene: &GpuScene) -> std::ops::Range<u32> {
        self.range.clone().unwrap_or(0..scene.triangle_count)
    }

    /// Draws only `range` of the scenes it is given (its own in a scene of several maps').
    pub fn draw_triangles(&mut self, range: std::ops::Range<u32>) {
        self.range = Some(range);
    }

    /// Draws its owner's pieces of its layer ([`super::LayerSubdivision::draw`]) instead of
    /// subdividing.
    pub fn draw_owner_pieces(&mut self, d: LayerDraw) {
        assert!(self.split.is_none(), "{}: made to subdivide itself", self.name());
        self.pieces = d.pieces.clone();
        self.owns_subdiv = false;
        self.owner_draw = Some(d);
    }

    /// The subdivision's passes over the scene of `scene_group` (the root, each level, the draw
    /// arguments), after this frame's warps and occluder map: the same pieces every time.
    pub(super) fn record_subdivision(&self, gpu: &Gpu, enc: &mut wgpu::CommandEncoder, scene_group: &wgpu::BindGroup) {
        let split = self.split.as_ref().expect("a map that subdivides itself");
        let groups = self.level_groups(gpu);
        let bufs = Buffers { counters: &self.counters, dispatch: &self.dispatch };
        record_passes(gpu, enc, split, &groups, scene_group, bufs, self.params.triangles);
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
                let hzb = self.occluders.as_ref().and_then(|o| o.hzb.as_ref()).map_or(&self.dv, |h| h.buffer());
                e.push(wgpu::BindGroupEntry { binding: 15, resource: hzb.as_entire_binding() });
                self.groups.levels[l].entries(gpu, name, self.split_layout.as_ref().expect("with the subdivision"), &e)
            })
            .collect()
    }
}

/// The counters and the indirect dispatch arguments of a subdivision's levels.
#[derive(Clone, Copy)]
pub(super) struct Buffers<'a> {
    pub counters: &'a wgpu::Buffer,
    pub dispatch: &'a wgpu::Buffer,
}

/// The subdivision's passes over the scene of `scene_group`: split_root over `triangles`, each
/// queue level's split_args and indirect split_level with `groups[l]` for level l, with
/// `tessellate` ([`TESS_ENTRIES`]) the tessellation's passes with the last group, and draw_args
/// (`groups[0]`: the root's).
pub(super) fn record_passes(
    gpu: &Gpu,
    enc: &mut wgpu::CommandEncoder,
    split: &[wgpu::ComputePipeline],
    groups: &[wgpu::BindGroup],
    scene_group: &wgpu::BindGroup,
    b: Buffers,
    triangles: u32,
) {
    let n = triangles.div_ceil(64);
    enc.clear_buffer(b.counters, 0, None);
    let pass = |enc: &mut wgpu::CommandEncoder, g: &wgpu::BindGroup, p: usize, groups: Option<u32>| {
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("subdivide"), timestamp_writes: None });
        pass.set_bind_group(1, scene_group, &[]);
        pass.set_bind_group(0, g, &[]);
        pass.set_pipeline(&split[p]);
        match groups {
            Some(n) => gpu.dispatch(&mut pass, [n.min(65535), n.div_ceil(65535), 1]),
            None => gpu.dispatch_indirect(&mut pass, b.dispatch, 0),
        }
    };
    // a level's input queue's group counts, out of the storage buffer into the indirect one
    let queue_groups = |enc: &mut wgpu::CommandEncoder, l: usize| {
        enc.copy_buffer_to_buffer(b.counters, 32 + 16 * ((l as u64 + 1) % 2) + 4, b.dispatch, 0, 12)
    };
    let tess = split.len() == TESS_ENTRIES.len();
    let levels = groups.len() - 1 - tess as usize;
    pass(enc, &groups[0], 0, Some(n));
    for (l, g) in groups.iter().enumerate().take(levels + 1).skip(1) {
        pass(enc, g, 1, Some(1));
        queue_groups(enc, l);
        pass(enc, g, 2, None);
    }
    if tess {
        // tess_begin sets the queued pieces' groups (for tess_levels and tess_alloc), then
        // tess_emit_args the emission's (tess.wgsl: counters 13-15, one group a chunk)
        let (l, g) = (levels + 1, &groups[levels + 1]);
        pass(enc, g, 3, Some(1));
        queue_groups(enc, l);
        pass(enc, g, 4, None);
        pass(enc, g, 5, Some(1));
        pass(enc, g, 6, None);
        pass(enc, g, 7, Some(1));
        enc.copy_buffer_to_buffer(b.counters, 52, b.dispatch, 0, 12);
        pass(enc, g, 8, None);
    }
    pass(enc, &groups[0], split.len() - 1, Some(1));
}

/// A subdivision's counters (subdiv.wgsl's 1048 words and `extra` more), which the depth passes
/// also read as indirect draw arguments.
pub(super) fn counters_buffer(gpu: &Gpu, label: &str, extra: u64) -> wgpu::Buffer {
    gpu.buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: (1048 + extra) * 4,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    })
}

/// The indirect dispatch arguments of the running level (copied out of the counters).
pub(super) fn dispatch_buffer(gpu: &Gpu, label: &str) -> wgpu::Buffer {
    gpu.buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: 12,
        usage: wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// One uniform a level (subdiv.wgsl `Level`): the level, whether it is the last, its input
/// queue and the queues' capacity.
pub(super) fn level_uniforms(gpu: &Gpu, name: &str, levels: u32, queue: u32) -> Vec<wgpu::Buffer> {
    (1..=levels).map(|l| gpu.uniform(&format!("{name}.level{l}"), &[l, (l == levels) as u32, (l + 1) % 2, queue])).collect()
}

/// (on, extra pieces, queue entries) of the subdivision of `tris` triangles within the device's
/// storage binding limit; an error when the queues cannot hold the triangles. `listed`: the
/// subdivision of several maps at once ([`super::LayerSubdivision`]), whose finished pieces are
/// also listed by map (4 bytes more each), with that many texels of maps that draw triangles of
/// their own (0 for copies of one scene, [`super::Layers::repeating_scene`]).
pub(super) fn capacity(k: &Knobs, name: &str, tris: u32, max_binding: u64, listed: Option<u64>) -> Result<(bool, u32, u32), GpuError> {
    let on = k.subdiv > 0.0;
    // 8 pieces a triangle, at least 2^21 (the most measured for dpsm-notw's two hemispheres
    // together: 0.76 M on stress-sibenik); several maps of their own triangles at once: 3 a texel
    // of all (the most measured: 2.6, cube-notw on sponza-peer), as their own subdivisions made
    // them
    let auto = (8 * tris as u64).max(1 << 21).max(3 * listed.unwrap_or(0));
    let wanted = if k.subdiv_capacity > 0 { k.subdiv_capacity as u64 } else { auto };
    // an asked-for capacity is given or refused; the automatic one takes what the device holds
    let piece = 16 + 4 * listed.is_some() as u64;
    let most = max_binding.saturating_sub(16 * tris as u64) / piece;
    if on && k.subdiv_capacity > 0 && wanted > most {
        return Err(GpuError::Invalid(format!(
            "{name}: subdiv_capacity={wanted} needs {:.1} MiB of pieces ({piece} bytes each), over this device's max_storage_buffer_binding_size of {:.1} MiB: at most {most} here",
            (wanted * piece) as f64 / (1u64 << 20) as f64,
            max_binding as f64 / (1u64 << 20) as f64
        )));
    }
    // at least one per triangle: the root finishes up to one extra piece per triangle (the
    // second half of a triangle cut by the near plane) before any level can check
    let extra = if on { wanted.max(tris as u64).min(most) as u32 } else { 0 };
    let queue = if on { queue_capacity(tris, max_binding, listed) } else { 0 };
    // the triangle index keeps 3 bits free for the split mask
    if on && (2 * tris as u64 > queue as u64 || tris >= 1 << 29) {
        return Err(GpuError::Invalid(format!(
            "{name}: {tris} triangles need subdivision queues of {} entries, over this device's storage binding limit",
            2 * tris as u64
        )));
    }
    Ok((on, extra, queue))
}

/// Entries of each level queue of the subdivision of `tris` triangles ([`capacity`]; the levels'
/// uniform holds it): the root queues up to two pieces per triangle (a triangle cut by the near
/// plane); several maps at once (`listed` texels) at least one a texel of all, as their own
/// queues of 2^20 held them.
pub(super) fn queue_capacity(tris: u32, max_binding: u64, listed: Option<u64>) -> u32 {
    (2 * tris as u64).max(1 << 20).max(listed.unwrap_or(0)).min(max_binding / 16) as u32
}

/// Bytes of each queue buffer of `queue` entries for maps of `p`: with `tessellate` the chunks'
/// words follow the queued pieces (tess.wgsl: one a queued piece and one per 64 pieces, four an
/// entry), past the entries the levels may fill, so that a full queue leaves them room.
pub(super) fn queue_bytes(p: &WarpParams, queue: u32, max_binding: u64) -> u64 {
    let chunks = if p.tessellate != 0 { (queue as u64 + p.extra_capacity as u64 / 64).div_ceil(4) + 1 } else { 0 };
    ((queue as u64 + chunks) * 16).min(max_binding)
}
