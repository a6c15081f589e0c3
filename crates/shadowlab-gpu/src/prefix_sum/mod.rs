//! GPU prefix sums (inclusive scans) of many runs at once: the rows or the columns of a 2D map
//! (warping functions of `notw`/`rtw`), or any strided runs of a buffer. `scan.wgsl`, one
//! workgroup per run; the CPU reference is `shadowlab_core::techniques::warp::row_prefix`.

use bytemuck::{Pod, Zeroable};

use crate::shaders::compose;
use crate::{binding, Gpu};
use std::sync::Arc;

const SCAN_WGSL: &str = include_str!("scan.wgsl");

pub fn shaders() -> Vec<(&'static str, String)> {
    vec![("prefix_sum/scan.wgsl", compose(SCAN_WGSL, false))]
}

/// WGSL `ScanParams`: `rows` runs of `len` elements; element k of run r at
/// `base + r * row_step + k * elem_step` (input `in_base`, output `out_base`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct ScanParams {
    pub rows: u32,
    pub len: u32,
    pub row_step: u32,
    pub elem_step: u32,
    pub in_base: u32,
    pub out_base: u32,
    /// 1: the input words are f32 bits; 0: u32 counts.
    pub input_f32: u32,
    pub _pad: u32,
}

impl ScanParams {
    /// The rows of a row-major `width x height` map.
    pub fn rows(width: u32, height: u32) -> ScanParams {
        ScanParams { rows: height, len: width, row_step: width, elem_step: 1, ..Default::default() }
    }
    /// The columns of a row-major `width x height` map.
    pub fn columns(width: u32, height: u32) -> ScanParams {
        ScanParams { rows: width, len: height, row_step: 1, elem_step: width, ..Default::default() }
    }
}

pub struct PrefixSum {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
    /// One uniform and bind group per `ScanParams` seen: a map's scans repeat every frame (no
    /// buffer or bind group per frame, tests/hygiene.rs).
    uniforms: std::sync::Mutex<std::collections::HashMap<[u32; 8], Scan>>,
}

/// A scan shape's uniform and its kept bind group.
type Scan = (wgpu::Buffer, Arc<binding::GroupCache>);

impl PrefixSum {
    pub fn new(gpu: &Gpu) -> PrefixSum {
        let layout = binding::layout(
            &gpu.device,
            "prefix_sum",
            wgpu::ShaderStages::COMPUTE,
            &[binding::uniform(), binding::storage(true), binding::storage(false)],
        );
        let pipeline = gpu.compute_pipeline("prefix_sum", &compose(SCAN_WGSL, false), "scan_rows", &[&layout]);
        PrefixSum { layout, pipeline, uniforms: Default::default() }
    }

    /// Records the scan of `p` from `input` (u32 words) into `output` (f32); they must be
    /// different buffers.
    pub fn encode(&self, gpu: &Gpu, enc: &mut wgpu::CommandEncoder, input: &wgpu::Buffer, output: &wgpu::Buffer, p: ScanParams) {
        let (uniform, groups) = {
            let mut made = self.uniforms.lock().unwrap();
            made.entry(bytemuck::cast(p)).or_insert_with(|| (gpu.uniform("prefix_sum.params", &p), Default::default())).clone()
        };
        let group = groups.get(
            gpu,
            "prefix_sum",
            &self.layout,
            &[uniform.as_entire_binding(), input.as_entire_binding(), output.as_entire_binding()],
        );
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("prefix_sum"), timestamp_writes: None });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &group, &[]);
        gpu.dispatch(&mut pass, [p.rows.min(65535), p.rows.div_ceil(65535), 1]);
    }
}
