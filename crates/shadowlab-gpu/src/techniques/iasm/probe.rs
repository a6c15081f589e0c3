//! `iasm`'s probe (probe.wgsl, for tests): the GPU's texel index and tile of buffer coordinates,
//! by params.wgsl's lookups (equations 3.2-3.5), to compare with the CPU's.

use shadowlab_core::techniques::iasm::{self as core, TILE_COUNT};

use super::uniforms::{IasmParams, PARAMS_WGSL};
use crate::shaders::compose;
use crate::{binding, Gpu};

const PROBE_WGSL: &str = include_str!("probe.wgsl");

pub(super) fn source() -> String {
    compose(&format!("{PARAMS_WGSL}{PROBE_WGSL}"), false)
}

/// The texel index and tile of each of `uvs` under `params` with resolutions `res` (offsets
/// accumulated from them).
pub(super) fn probe_indices(gpu: &Gpu, mut params: IasmParams, res: &[u32; TILE_COUNT], uvs: &[glam::Vec2]) -> Vec<(u32, u32)> {
    params.res = *res;
    params.off = core::offsets(res);
    let ub = gpu.uniform("iasm.probe_params", &params);
    let data: Vec<[f32; 4]> = uvs.iter().map(|u| [u.x, u.y, 0.0, 0.0]).collect();
    let probe = gpu.buffer_init(
        "iasm.probe",
        bytemuck::cast_slice(&data),
        wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
    );
    let layout = binding::layout(&gpu.device, "iasm.probe", wgpu::ShaderStages::COMPUTE, &[binding::uniform(), binding::storage(false)]);
    let group = binding::group(gpu, "iasm.probe", &layout, &[ub.as_entire_binding(), probe.as_entire_binding()]);
    let pipeline = gpu.compute_pipeline("iasm.probe", &source(), "probe_index", &[&layout]);
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &group, &[]);
        gpu.dispatch(&mut pass, [(uvs.len() as u32).div_ceil(64), 1, 1]);
    }
    gpu.submit(enc.finish());
    let out: Vec<[f32; 4]> = gpu.read_buffer_as(&probe, uvs.len());
    out.iter().map(|v| (v[2].to_bits(), v[3].to_bits())).collect()
}
