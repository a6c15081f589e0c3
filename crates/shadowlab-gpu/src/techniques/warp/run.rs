//! The per-frame passes of the warped techniques, their report, and readbacks for tests.

use shadowlab_core::metrics::sampling_stats;
use shadowlab_core::techniques::warp::Warp2D;

use super::{Variant, Warped, DV_CROP_CLOSED, SMOOTH_BLOCK};
use crate::prefix_sum::ScanParams;
use crate::record::Recorder;
use crate::technique::{FrameInputs, NamedImage, Technique, TechniqueReport};
use crate::techniques::pictures::{count_image, depth_image};
use crate::{raster, Gpu, GpuError};

/// Signed picture of warp offsets (seed 000 Figure 4): yellow positive, blue negative, black 0.
pub fn offset_image(name: &str, w: u32, h: u32, o: &[f32]) -> NamedImage {
    let max = o.iter().fold(1e-6f32, |m, v| m.max(v.abs()));
    let rgba = o
        .iter()
        .flat_map(|&v| {
            let t = (v.abs() / max).sqrt();
            let c = (255.0 * t) as u8;
            if v >= 0.0 {
                [c, c, 0, 255]
            } else {
                [0, c / 2, c, 255]
            }
        })
        .collect();
    NamedImage { name: name.into(), width: w, height: h, rgba }
}

impl Warped {
    fn name(&self) -> &'static str {
        self.label
    }

    fn pipeline(&self, entry: &str) -> &wgpu::ComputePipeline {
        &self.analyze.iter().find(|(e, _)| *e == entry).expect("entry point created for this variant").1
    }

    /// The depth pass's bindings: the lookup resources and the pieces (binding 10).
    fn depth_entries<'a>(&'a self, xv: &'a wgpu::TextureView, yv: &'a wgpu::TextureView) -> Vec<wgpu::BindGroupEntry<'a>> {
        let pieces = if self.params.subdiv > 0.0 { &self.pieces } else { &self.counters };
        let look = self.lookup_resources(xv, yv);
        let mut entries: Vec<wgpu::BindGroupEntry> =
            look.iter().enumerate().map(|(i, r)| wgpu::BindGroupEntry { binding: 6 + i as u32, resource: r.clone() }).collect();
        entries.push(wgpu::BindGroupEntry { binding: 10, resource: pieces.as_entire_binding() });
        entries
    }

    fn depth_group(&self, gpu: &Gpu, xv: &wgpu::TextureView, yv: &wgpu::TextureView) -> wgpu::BindGroup {
        let entries = self.depth_entries(xv, yv);
        gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(self.name()),
            layout: &self.lookup_layout,
            entries: &entries,
        })
    }

    fn lookup_resources<'a>(&'a self, xv: &'a wgpu::TextureView, yv: &'a wgpu::TextureView) -> [wgpu::BindingResource<'a>; 4] {
        [
            self.uniform.as_entire_binding(),
            self.dv.as_entire_binding(),
            wgpu::BindingResource::TextureView(xv),
            wgpu::BindingResource::TextureView(yv),
        ]
    }

    /// The DV rectangle (lo x, lo y, hi x, hi y) in base map coordinates, as the shaders use it.
    pub fn read_dv_rect(&self, gpu: &Gpu) -> [f32; 4] {
        let b: Vec<u32> = gpu.read_buffer_as(&self.dv, 4);
        if self.params.dv_mode == 0.0 || b[0] > b[2] || b[1] > b[3] {
            return [0.0, 0.0, 1.0, 1.0];
        }
        let s = 16777216.0f32;
        let (lo, hi) = shadowlab_core::techniques::warp::grow_rect(
            [b[0] as f32 / s, b[1] as f32 / s],
            [b[2] as f32 / s, b[3] as f32 / s],
            self.res as usize,
            self.params.dv_margin,
        );
        [lo[0], lo[1], hi[0], hi[1]]
    }

    /// The count map of the last frame before warping (`notw`, `rtw`).
    pub fn read_counts_before(&self, gpu: &Gpu) -> Vec<u32> {
        let n = (self.res * self.res) as usize;
        gpu.read_buffer_as(&self.work, 2 * n)[..n].to_vec()
    }

    /// `cull_hidden`: the last frame's occluder map (res x res) and its pyramid of maxima (all
    /// levels, level 0 first).
    pub fn read_occluders(&self, gpu: &Gpu) -> Option<(Vec<f32>, Vec<f32>)> {
        let o = self.occluders.as_ref()?;
        Some((bytemuck::pod_collect_to_vec(&gpu.read_texture(o.depth(), 4)), gpu.read_buffer_as(&o.hzb, (o.hzb.size() / 4) as usize)))
    }

    /// The view samples per texel of the final (warped) map, counted by the last evaluation.
    pub fn read_counts_final(&self, gpu: &Gpu) -> Vec<u32> {
        gpu.read_buffer_as(&self.counts, (self.res * self.res) as usize)
    }

    /// The count map rebuilt through the row warps (`notw`).
    pub fn read_counts_rows(&self, gpu: &Gpu) -> Vec<u32> {
        let n = (self.res * self.res) as usize;
        gpu.read_buffer_as(&self.work, 2 * n)[n..].to_vec()
    }

    /// The warp textures of the last frame.
    pub fn read_warp(&self, gpu: &Gpu) -> Warp2D {
        let ox: Vec<f32> = bytemuck::pod_collect_to_vec(&gpu.read_texture(&self.warp_x, 4));
        let oy: Vec<f32> = bytemuck::pod_collect_to_vec(&gpu.read_texture(&self.warp_y, 4));
        Warp2D {
            res: self.res as usize,
            rows_x: self.warp_x.height() as usize,
            cols_y: self.warp_y.width() as usize,
            ox,
            oy,
            interp: self.params.interp != 0,
        }
    }

    /// Bytes of the warps kept per light.
    pub fn warp_bytes(&self) -> u64 {
        match self.variant {
            Variant::Dv => 0,
            _ => 4 * (self.warp_x.width() * self.warp_x.height() + self.warp_y.width() * self.warp_y.height()) as u64,
        }
    }
}

impl Technique for Warped {
    fn prepare(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        let name = self.name();
        let (w, h) = (f.gbuffer.width, f.gbuffer.height);
        let (xv, yv) = (self.warp_x.create_view(&Default::default()), self.warp_y.create_view(&Default::default()));
        let group = f.view_group(
            gpu,
            &format!("{name}.analyze"),
            &self.analyze_layout,
            &[
                self.uniform.as_entire_binding(),
                self.dv.as_entire_binding(),
                self.work.as_entire_binding(),
                self.fwork.as_entire_binding(),
                wgpu::BindingResource::TextureView(&xv),
                wgpu::BindingResource::TextureView(&yv),
                // the occluder pyramid (`edge_importance`), or a stand-in never read
                self.occluders.as_ref().map_or(&self.counts, |o| &o.hzb).as_entire_binding(),
            ],
        );
        rec.write_buffer(&self.dv, 0, bytemuck::cast_slice(&[u32::MAX, u32::MAX, 0, 0, 0, 0, 0, 0]));
        rec.stage(&format!("{name}.desired_view"), |enc| {
            gpu.dispatch_2d(enc, &format!("{name}.desired_view"), self.pipeline("dv_reduce"), &[&group], w, h);
        });
        if self.variant == Variant::Dv {
            return Ok(());
        }
        // `edge_importance`: the occluder map of this frame's DV crop before the count map
        // (render then reuses it for `cull_hidden`)
        if let (Some(o), true) = (&self.occluders, self.params.edge_importance > 0) {
            let depth_group = self.depth_group(gpu, &xv, &yv);
            rec.stage(&format!("{name}.occluders"), |enc| o.record(gpu, enc, &depth_group, f.scene));
        }
        let res = self.res;
        let n = res * res;
        rec.stage(&format!("{name}.importance_map"), |enc| {
            enc.clear_buffer(&self.work, 0, None);
            gpu.dispatch_2d(enc, &format!("{name}.count"), self.pipeline("count"), &[&group], w, h);
            match self.variant {
                Variant::Notw => {
                    gpu.dispatch_2d(enc, "notw.blur_rows", self.pipeline("blur_rows"), &[&group], res, res);
                    let scan = ScanParams { in_base: 2 * n, input_f32: 1, ..ScanParams::rows(res, res) };
                    self.prefix.encode(gpu, enc, &self.work, &self.fwork, scan);
                    gpu.dispatch_2d(enc, "notw.offsets_rows", self.pipeline("offsets_rows"), &[&group], res, res);
                    gpu.dispatch_2d(enc, "notw.smooth_rows", self.pipeline("smooth_rows"), &[&group], res, res.div_ceil(SMOOTH_BLOCK));
                    gpu.dispatch_2d(enc, "notw.rebuild", self.pipeline("rebuild"), &[&group], w, h);
                    gpu.dispatch_2d(enc, "notw.blur_cols", self.pipeline("blur_cols"), &[&group], res, res);
                    let scan = ScanParams { in_base: 2 * n, input_f32: 1, ..ScanParams::columns(res, res) };
                    self.prefix.encode(gpu, enc, &self.work, &self.fwork, scan);
                    gpu.dispatch_2d(enc, "notw.offsets_cols", self.pipeline("offsets_cols"), &[&group], res, res);
                    gpu.dispatch_2d(enc, "notw.smooth_cols", self.pipeline("smooth_cols"), &[&group], res, res.div_ceil(SMOOTH_BLOCK));
                }
                _ => {
                    let one_d = |enc: &mut wgpu::CommandEncoder, e: &str| {
                        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(e), timestamp_writes: None });
                        pass.set_pipeline(self.pipeline(e));
                        pass.set_bind_group(0, &group, &[]);
                        pass.dispatch_workgroups((2 * res).div_ceil(64), 1, 1);
                    };
                    one_d(enc, "rtw_collapse");
                    one_d(enc, "rtw_blur");
                    let scan = ScanParams { in_base: 3 * n, input_f32: 1, ..ScanParams::rows(res, 2) };
                    self.prefix.encode(gpu, enc, &self.work, &self.fwork, scan);
                    one_d(enc, "rtw_offsets");
                }
            }
        });
        Ok(())
    }

    fn render(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        let name = self.name();
        let (xv, yv) = (self.warp_x.create_view(&Default::default()), self.warp_y.create_view(&Default::default()));
        let subdiv = self.params.subdiv > 0.0;
        let mut entries = self.depth_entries(&xv, &yv);
        let depth_group =
            gpu.device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some(name), layout: &self.lookup_layout, entries: &entries });
        if subdiv {
            entries.push(wgpu::BindGroupEntry { binding: 11, resource: self.counters.as_entire_binding() });
            // level l reads queue (l + 1) % 2 and writes the other; the root writes queue 0
            let groups: Vec<wgpu::BindGroup> = (0..=self.level_uniforms.len())
                .map(|l| {
                    let qi = (l + 1) % 2;
                    let mut e = entries.clone();
                    e.push(wgpu::BindGroupEntry { binding: 12, resource: self.queues[qi].as_entire_binding() });
                    e.push(wgpu::BindGroupEntry { binding: 13, resource: self.queues[1 - qi].as_entire_binding() });
                    let u = &self.level_uniforms[l.saturating_sub(1)];
                    e.push(wgpu::BindGroupEntry { binding: 14, resource: u.as_entire_binding() });
                    let hzb = self.occluders.as_ref().map_or(&self.dv, |o| &o.hzb);
                    e.push(wgpu::BindGroupEntry { binding: 15, resource: hzb.as_entire_binding() });
                    gpu.device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some(name), layout: &self.split_layout, entries: &e })
                })
                .collect();
            if let (Some(o), true) = (&self.occluders, self.params.edge_importance == 0) {
                rec.stage(&format!("{name}.occluders"), |enc| o.record(gpu, enc, &depth_group, f.scene));
            }
            let tris = self.params.triangles;
            let n = tris.div_ceil(64);
            rec.stage(&format!("{name}.subdivide"), |enc| {
                enc.clear_buffer(&self.counters, 0, None);
                let pass = |enc: &mut wgpu::CommandEncoder, g: &wgpu::BindGroup, p: usize, groups: Option<u32>| {
                    let mut pass =
                        enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("subdivide"), timestamp_writes: None });
                    pass.set_bind_group(1, &f.scene.group, &[]);
                    pass.set_bind_group(0, g, &[]);
                    pass.set_pipeline(&self.split[p]);
                    match groups {
                        Some(n) => pass.dispatch_workgroups(n.min(65535), n.div_ceil(65535), 1),
                        None => pass.dispatch_workgroups_indirect(&self.dispatch, 0),
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
            });
        }
        let map_view = self.map.create_view(&Default::default());
        rec.stage(&format!("{name}.shadow_map"), |enc| {
            let mut pass = raster::begin_pass(enc, &format!("{name}.shadow_map"), &[], &map_view);
            pass.set_pipeline(&self.depth_pipeline);
            pass.set_bind_group(0, &depth_group, &[]);
            pass.set_bind_group(1, &f.scene.group, &[]);
            if subdiv {
                pass.draw_indirect(&self.counters, 16);
            } else {
                pass.draw(0..f.scene.triangle_count * 3, 0..1);
            }
        });
        Ok(())
    }

    fn evaluate(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        self.eval_pass(gpu, f, rec, false)
    }

    fn analyze(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        self.eval_pass(gpu, f, rec, true)
    }

    fn report(&mut self, gpu: &Gpu) -> TechniqueReport {
        let res = self.res;
        let n = (res * res) as usize;
        let after: Vec<u32> = gpu.read_buffer_as(&self.counts, n);
        let depth: Vec<f32> = bytemuck::pod_collect_to_vec(&gpu.read_texture(&self.map, 4));
        let map_bytes = n as u64 * 4;
        let mut r = TechniqueReport {
            shadow_data_bytes: map_bytes + self.warp_bytes() + 32,
            sampling: Some(sampling_stats(&after)),
            ..Default::default()
        };
        let c = &mut r.counters;
        let per_tap = if self.params.dv_mode == DV_CROP_CLOSED { 9.0 } else { 1.0 };
        c.insert("fetches_per_pixel".into(), (self.pcf * self.pcf) as f64 * per_tap);
        c.insert("shadow_map_texels".into(), n as f64);
        c.insert("warp_bytes".into(), self.warp_bytes() as f64);
        c.insert("scratch_bytes".into(), self.scratch_bytes() as f64);
        let dv = self.read_dv_rect(gpu);
        c.insert("dv_area_fraction".into(), ((dv[2] - dv[0]) * (dv[3] - dv[1])) as f64);
        if self.params.subdiv > 0.0 {
            let a: Vec<u32> = gpu.read_buffer_as(&self.counters, 24);
            let drawn = a[4] / 3;
            c.insert("subdiv_triangles_drawn".into(), drawn as f64);
            c.insert("subdiv_pieces_per_texel".into(), drawn as f64 / n as f64);
            c.insert("subdiv_pieces_dropped".into(), a[1] as f64);
            c.insert("subdiv_queue_full_finishes".into(), a[2] as f64);
            c.insert("subdiv_cut_level".into(), a[19] as f64);
            c.insert("subdiv_pieces_unsplit".into(), a[20] as f64);
            if self.params.cull_hidden > 0.5 {
                c.insert("subdiv_hidden_edge_tests".into(), a[21] as f64);
            }
            if a[19] > 0 {
                r.degraded.push(format!(
                    "subdivision level {} of {}: the pieces did not fit the piece capacity ({}); {} pieces were drawn unsplit (bent edges)",
                    a[19], self.params.subdiv_levels, self.params.extra_capacity, a[20]
                ));
            }
            if a[1] > 0 || a[2] > 0 {
                r.degraded.push(format!("{} pieces dropped, {} queue-full finishes", a[1], a[2]));
            }
        }
        if self.variant != Variant::Dv {
            let before = self.read_counts_before(gpu);
            let s = sampling_stats(&before);
            c.insert("used_texel_fraction_before_warp".into(), s.used_texel_fraction);
            c.insert("samples_per_used_texel_cv_before_warp".into(), s.samples_per_used_texel_cv);
            r.images.push(count_image("count map before warping (after DV)", res, &before));
            if self.variant == Variant::Notw {
                r.images.push(count_image("count map after row warps", res, &self.read_counts_rows(gpu)));
            }
        }
        r.images.push(count_image("count map after warping", res, &after));
        r.images.push(depth_image("warped shadow map (depth)", res, &depth));
        if self.variant != Variant::Dv {
            let w = self.read_warp(gpu);
            let full = |rows: usize, cols: usize, v: &[f32], x_major: bool| -> Vec<f32> {
                // RTW's 1D functions drawn for every row/column, as the 2D warp applies them
                (0..n)
                    .map(|i| {
                        let (x, y) = (i % res as usize, i / res as usize);
                        if x_major {
                            v[y.min(rows - 1) * res as usize + x]
                        } else {
                            v[y * cols + x.min(cols - 1)]
                        }
                    })
                    .collect()
            };
            r.images.push(offset_image("row warping functions o_x (row i, position x)", res, res, &full(w.rows_x, 1, &w.ox, true)));
            r.images.push(offset_image("column warping functions o_y (column j, position y)", res, res, &full(1, w.cols_y, &w.oy, false)));
        }
        r
    }
}

impl Warped {
    /// The evaluation; with `counting` the lab's analysis variant (view samples per texel).
    fn eval_pass(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder, counting: bool) -> Result<(), GpuError> {
        let name = self.name();
        let (xv, yv) = (self.warp_x.create_view(&Default::default()), self.warp_y.create_view(&Default::default()));
        let map_view = self.map.create_view(&Default::default());
        let mut extra: Vec<wgpu::BindingResource> = self.lookup_resources(&xv, &yv).to_vec();
        extra.extend([
            wgpu::BindingResource::TextureView(&map_view),
            wgpu::BindingResource::Sampler(&self.sampler),
            self.counts.as_entire_binding(),
        ]);
        let group = f.view_group(gpu, &format!("{name}.final_pass"), &self.eval_layout, &extra);
        self.eval.record(gpu, rec, &format!("{name}.final_pass"), &self.counts, &group, f.gbuffer.width, f.gbuffer.height, counting);
        Ok(())
    }
}
