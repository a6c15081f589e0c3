//! The analysis of the view before the shadow map (`prepare`, analyze.wgsl): the desired view
//! reduced from the view samples, then (`notw`, `rtw`) the count or importance map over the
//! cropped map and the warps built from it: NoTW's row warps, the count map rebuilt through
//! them and the column warps; RTW's 1D collapse, blur and offsets.

use super::{base_constants, Variant, WarpParams, Warped, COUNT_WGSL, DV_WGSL, NOTW_WGSL, PARAMS_WGSL, SMOOTH_BLOCK};
use crate::prefix_sum::ScanParams;
use crate::record::Recorder;
use crate::technique::{compose_view, view_layout, FrameInputs};
use crate::{binding, Gpu};

const ANALYZE_WGSL: &str = include_str!("analyze.wgsl");

pub(super) fn source() -> String {
    compose_view(&format!("{PARAMS_WGSL}{DV_WGSL}{COUNT_WGSL}{NOTW_WGSL}{ANALYZE_WGSL}"), false)
}

/// The entry points a variant dispatches.
fn entries(variant: Variant) -> &'static [&'static str] {
    match variant {
        Variant::Notw => &["dv_reduce", "count", "functions_rows", "smooth_rows", "rebuild", "functions_cols", "smooth_cols"],
        Variant::Rtw => &["dv_reduce", "count", "rtw_collapse", "rtw_blur", "rtw_offsets"],
        Variant::Dv => &["dv_reduce"],
    }
}

/// The analysis layout (the view, then the uniform, the DV bounds, the two work buffers, the two
/// warps written and the occluder map) and, with `own`, a pipeline per entry point of `variant`
/// (none for a map its owner analyses).
pub(super) fn pipelines(
    gpu: &Gpu,
    name: &str,
    variant: Variant,
    p: &WarpParams,
    own: bool,
) -> (wgpu::BindGroupLayout, Vec<(&'static str, wgpu::ComputePipeline)>) {
    let rw = binding::storage(false);
    let store = wgpu::BindingType::StorageTexture {
        access: wgpu::StorageTextureAccess::WriteOnly,
        format: wgpu::TextureFormat::R32Float,
        view_dimension: wgpu::TextureViewDimension::D2,
    };
    let layout = view_layout(gpu, &format!("{name}.analyze"), &[binding::uniform(), rw, rw, rw, store, store, binding::texture_depth()]);
    let src = source();
    let mut constants = base_constants(p);
    constants.push(("SMOOTH_BLOCK", SMOOTH_BLOCK as f64));
    let entries = if own { entries(variant) } else { &[] };
    let pipelines =
        entries.iter().map(|&e| (e, gpu.compute_pipeline_with(&format!("{name}.{e}"), &src, e, &[&layout], &constants))).collect();
    (layout, pipelines)
}

impl Warped {
    fn pipeline(&self, entry: &str) -> &wgpu::ComputePipeline {
        &self.analyze.iter().find(|(e, _)| *e == entry).expect("entry point created for this variant").1
    }

    /// This frame's desired view and warps (stages `desired_view`, with `edge_importance` the
    /// `occluders` of the crop, and `importance_map`). A layer whose owner reads the view has
    /// them made by its owner ([`super::LayerPasses`]: `reduce_dv`, `count`, `analyze`).
    pub(super) fn fit_warps(&self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) {
        if self.view_by_owner {
            return;
        }
        let name = self.name();
        let (w, h) = (f.gbuffer.width, f.gbuffer.height);
        let group = f.view_group(
            gpu,
            &self.groups.analyze,
            &format!("{name}.analyze"),
            &self.analyze_layout,
            &[
                self.uniform.as_entire_binding(),
                self.dv_binding(),
                self.work.as_entire_binding(),
                self.fwork.as_entire_binding(),
                wgpu::BindingResource::TextureView(&self.views[0]),
                wgpu::BindingResource::TextureView(&self.views[1]),
                // the occluder map (`edge_importance`), or a stand-in never read (the map's layer)
                wgpu::BindingResource::TextureView(self.occluders.as_ref().map_or(&self.views[2], |o| o.view())),
            ],
        );
        rec.write_buffer(&self.dv, self.dv_offset, bytemuck::cast_slice(&[u32::MAX, u32::MAX, 0, 0, 0, 0, 0, 0]));
        rec.stage(&format!("{name}.desired_view"), |enc| {
            gpu.dispatch_2d(enc, &format!("{name}.desired_view"), self.pipeline("dv_reduce"), &[&group], w, h);
        });
        if self.variant == Variant::Dv {
            return;
        }
        self.draw_occluders(gpu, f, rec);
        rec.stage(&format!("{name}.importance_map"), |enc| {
            enc.clear_buffer(&self.work, 0, None);
            gpu.dispatch_2d(enc, &format!("{name}.count"), self.pipeline("count"), &[&group], w, h);
            match self.variant {
                Variant::Notw => self.notw_warps(gpu, enc, &group),
                _ => self.rtw_warps(gpu, enc, &group),
            }
        });
    }

    /// With `edge_importance`, the occluder map of this frame's DV crop (stage `occluders`),
    /// which the count map reads (render then reuses it for `cull_hidden`); else nothing.
    pub fn draw_occluders(&self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) {
        if let (Some(o), true) = (&self.occluders, self.params.edge_importance > 0) {
            let depth_group = self.depth_group(gpu);
            let triangles = self.triangles(f.scene);
            rec.stage(&format!("{}.occluders", self.name()), |enc| o.record(gpu, enc, &depth_group, f.scene, triangles));
        }
    }

    /// NoTW after the count map, per direction: the functions (blur, prefix sum and offsets, one
    /// invocation each) and their smoothing; the count map rebuilt through the row warps between.
    fn notw_warps(&self, gpu: &Gpu, enc: &mut wgpu::CommandEncoder, group: &wgpu::BindGroup) {
        let res = self.res;
        self.dispatch_1d(gpu, enc, group, "functions_rows", res);
        gpu.dispatch_2d(enc, "notw.smooth_rows", self.pipeline("smooth_rows"), &[group], res, res.div_ceil(SMOOTH_BLOCK));
        self.dispatch_1d(gpu, enc, group, "rebuild", res);
        self.dispatch_1d(gpu, enc, group, "functions_cols", res);
        gpu.dispatch_2d(enc, "notw.smooth_cols", self.pipeline("smooth_cols"), &[group], res, res.div_ceil(SMOOTH_BLOCK));
    }

    /// Entry point `e` over `n` invocations (workgroups of 64).
    fn dispatch_1d(&self, gpu: &Gpu, enc: &mut wgpu::CommandEncoder, group: &wgpu::BindGroup, e: &str, n: u32) {
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(e), timestamp_writes: None });
        pass.set_pipeline(self.pipeline(e));
        pass.set_bind_group(0, group, &[]);
        gpu.dispatch(&mut pass, [n.div_ceil(64), 1, 1]);
    }

    /// RTW after the importance map: the max-collapse to two 1D functions, their blur, one
    /// prefix sum over both, the offsets.
    fn rtw_warps(&self, gpu: &Gpu, enc: &mut wgpu::CommandEncoder, group: &wgpu::BindGroup) {
        let res = self.res;
        let n = res * res;
        self.dispatch_1d(gpu, enc, group, "rtw_collapse", 2 * res);
        self.dispatch_1d(gpu, enc, group, "rtw_blur", 2 * res);
        let scan = ScanParams { in_base: 2 * n, input_f32: 1, ..ScanParams::rows(res, 2) };
        self.prefix.encode(gpu, enc, &self.work, &self.fwork, scan);
        self.dispatch_1d(gpu, enc, group, "rtw_offsets", 2 * res);
    }
}
