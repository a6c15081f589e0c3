//! Leak tracing's `<name>.trace` stage: args.wgsl sizes an indirect dispatch from the ray list's
//! count, then trace.wgsl traces one ray per listed pixel with `rt`'s BVH traversal
//! (`reference::TRACE_WGSL`) and writes its answer into this frame's mask.

use super::screen::Screen;
use super::uniforms::TraceParams;
use crate::record::Recorder;
use crate::reference::TRACE_WGSL;
use crate::scene_gpu::GpuScene;
use crate::technique::{compose_view, view_layout, FrameInputs};
use crate::{binding, Gpu};

const TRACE_BODY_WGSL: &str = include_str!("trace.wgsl");
pub(super) const ARGS_WGSL: &str = include_str!("args.wgsl");

pub(super) fn source() -> String {
    compose_view(&format!("{TRACE_WGSL}{TRACE_BODY_WGSL}"), true)
}

pub(super) struct TracePass {
    /// The trace's group per ping-pong mask, and the arguments' group (kept: no group per frame).
    pub(crate) groups: [crate::binding::GroupCache; 2],
    pub(crate) args_groups: crate::binding::GroupCache,
    trace_layout: wgpu::BindGroupLayout,
    trace_pipeline: wgpu::ComputePipeline,
    args_layout: wgpu::BindGroupLayout,
    args_pipeline: wgpu::ComputePipeline,
}

/// The bind groups of one frame: the trace's and the indirect arguments'.
pub(super) struct TraceGroups {
    trace: wgpu::BindGroup,
    args: wgpu::BindGroup,
}

impl TracePass {
    pub fn new(gpu: &Gpu, scene: &GpuScene, name: &str) -> TracePass {
        let (ro, rw) = (binding::storage(true), binding::storage(false));
        let trace_layout = view_layout(gpu, &format!("{name}.trace"), &[binding::uniform(), ro, rw]);
        let trace_pipeline = gpu.compute_pipeline(&format!("{name}.trace"), &source(), "main", &[&trace_layout, &scene.layout]);
        let args_layout = binding::layout(&gpu.device, &format!("{name}.args"), wgpu::ShaderStages::COMPUTE, &[binding::uniform(), ro, rw]);
        let args_pipeline = gpu.compute_pipeline(&format!("{name}.args"), ARGS_WGSL, "main", &[&args_layout]);
        TracePass { groups: Default::default(), args_groups: Default::default(), trace_layout, trace_pipeline, args_layout, args_pipeline }
    }

    /// This frame's `TraceParams`: the mask's bits per pixel and the pixels.
    pub fn uniform(gpu: &Gpu, name: &str, mask_bits: u32, pixels: u32) -> wgpu::Buffer {
        gpu.uniform(&format!("{name}.trace_params"), &TraceParams { cfg: [mask_bits, pixels, 0, 0] })
    }

    /// The groups of the frame `s` is at, over its `uniform` (both parities' made on the first
    /// frame).
    pub fn groups(&self, gpu: &Gpu, f: &FrameInputs, name: &str, uniform: &wgpu::Buffer, s: &Screen) -> TraceGroups {
        let cur = (s.frames % 2) as usize;
        let [trace, _next] = [cur, 1 - cur].map(|p| {
            f.view_group(
                gpu,
                &self.groups[p],
                &format!("{name}.trace"),
                &self.trace_layout,
                &[uniform.as_entire_binding(), s.list.as_entire_binding(), s.masks[p].as_entire_binding()],
            )
        });
        let args = self.args_groups.get(
            gpu,
            &format!("{name}.args"),
            &self.args_layout,
            &[uniform.as_entire_binding(), s.list.as_entire_binding(), s.args.as_entire_binding()],
        );
        TraceGroups { trace, args }
    }

    /// Stage `<name>.trace`: the arguments from the list's count, then the rays (indirect).
    pub fn record(&self, gpu: &Gpu, rec: &mut Recorder, name: &str, f: &FrameInputs, g: &TraceGroups, s: &Screen) {
        let label = format!("{name}.trace");
        rec.stage(&label, |enc| {
            {
                let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(&label), timestamp_writes: None });
                pass.set_pipeline(&self.args_pipeline);
                pass.set_bind_group(0, &g.args, &[]);
                gpu.dispatch(&mut pass, [1, 1, 1]);
            }
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(&label), timestamp_writes: None });
            pass.set_pipeline(&self.trace_pipeline);
            pass.set_bind_group(0, &g.trace, &[]);
            pass.set_bind_group(1, &f.scene.group, &[]);
            gpu.dispatch_indirect(&mut pass, &s.args, 0);
        });
    }
}
