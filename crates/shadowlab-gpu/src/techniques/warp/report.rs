//! The warped map's report (memory, counters, sampling before and after the warp, subdivision
//! capacity, pictures of the count maps, the map and the warping functions) and the readbacks
//! it and the tests use.

use shadowlab_core::metrics::sampling_stats;
use shadowlab_core::techniques::warp::Warp2D;

use super::{Variant, WarpParams, Warped, DV_CROP_CLOSED};
use crate::technique::{NamedImage, TechniqueReport};
use crate::techniques::pictures::{count_image, depth_image};
use crate::Gpu;

/// Signed picture of warp offsets (seed 000 Figure 4): yellow positive, blue negative, black 0.
fn offset_image(name: &str, w: u32, h: u32, o: &[f32]) -> NamedImage {
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

pub(super) fn report(t: &Warped, gpu: &Gpu) -> TechniqueReport {
    let res = t.res;
    let n = (res * res) as usize;
    let after = t.read_counts_final(gpu);
    let depth = t.read_map(gpu);
    let map_bytes = n as u64 * 4;
    let mut r = TechniqueReport {
        shadow_data_bytes: map_bytes + t.warp_bytes() + 32,
        sampling: Some(sampling_stats(&after)),
        ..Default::default()
    };
    let c = &mut r.counters;
    let per_tap = if t.params.dv_mode == DV_CROP_CLOSED { 9.0 } else { 1.0 };
    c.insert("fetches_per_pixel".into(), (t.pcf * t.pcf) as f64 * per_tap);
    c.insert("shadow_map_texels".into(), n as f64);
    c.insert("warp_bytes".into(), t.warp_bytes() as f64);
    c.insert("scratch_bytes".into(), t.scratch_bytes() as f64);
    let dv = t.read_dv_rect(gpu);
    c.insert("dv_area_fraction".into(), ((dv[2] - dv[0]) * (dv[3] - dv[1])) as f64);
    // (a map subdivided by its owner: the owner reports the subdivision)
    if t.params.subdiv > 0.0 && t.owner_draw.is_none() {
        subdivision(t, gpu, &mut r);
    }
    if let Some(frags) = t.exact_depth_fragments(gpu) {
        r.counters.insert("exact_depth_fragments".into(), frags as f64);
        r.counters.insert("exact_depth_fragments_per_texel".into(), frags as f64 / n as f64);
    }
    if t.variant != Variant::Dv {
        let before = t.read_counts_before(gpu);
        let s = sampling_stats(&before);
        r.counters.insert("used_texel_fraction_before_warp".into(), s.used_texel_fraction);
        r.counters.insert("samples_per_used_texel_cv_before_warp".into(), s.samples_per_used_texel_cv);
        r.images.push(count_image("count map before warping (after DV)", res, &before));
        if t.variant == Variant::Notw {
            // whole counts for the picture: a fractional share above 0 stays visible
            let rows: Vec<u32> = t.read_counts_rows(gpu).iter().map(|&c| c.ceil() as u32).collect();
            r.images.push(count_image("count map after row warps", res, &rows));
        }
    }
    r.images.push(count_image("count map after warping", res, &after));
    r.images.push(depth_image("warped shadow map (depth)", res, &depth));
    if t.variant != Variant::Dv {
        warp_images(t, gpu, &mut r);
    }
    r
}

/// The subdivision's counters (pieces drawn, dropped, unsplit) and where its capacity degraded
/// the map.
fn subdivision(t: &Warped, gpu: &Gpu, r: &mut TechniqueReport) {
    let a: Vec<u32> = gpu.read_buffer_as(&t.counters, 24);
    subdivision_counters(&a, a[4] / 3, (t.res * t.res) as usize, &t.params, r);
}

/// The counters of a subdivision whose first 24 words (subdiv.wgsl) are `a`, which drew `drawn`
/// pieces into `texels` texels, for maps of `p` (its levels, capacity and `cull_hidden`).
pub(super) fn subdivision_counters(a: &[u32], drawn: u32, texels: usize, p: &WarpParams, r: &mut TechniqueReport) {
    let c = &mut r.counters;
    c.insert("subdiv_triangles_drawn".into(), drawn as f64);
    c.insert("subdiv_pieces_per_texel".into(), drawn as f64 / texels as f64);
    c.insert("subdiv_pieces_dropped".into(), a[1] as f64);
    c.insert("subdiv_queue_full_finishes".into(), a[2] as f64);
    c.insert("subdiv_cut_level".into(), a[19] as f64);
    c.insert("subdiv_pieces_unsplit".into(), a[20] as f64);
    if p.cull_hidden > 0.5 {
        c.insert("subdiv_hidden_edge_tests".into(), a[21] as f64);
    }
    if p.tessellate != 0 {
        c.insert("subdiv_pieces_degenerate".into(), a[22] as f64);
    }
    if p.tessellate != 0 && a[19] == super::subdiv::level_count(p) {
        r.degraded.push(format!(
            "tessellation after level {}: the pieces did not fit the piece capacity ({}); {} pieces were drawn whole (bent edges)",
            a[19] - 1,
            p.extra_capacity,
            a[20]
        ));
    } else if a[19] > 0 {
        r.degraded.push(format!(
            "subdivision level {} of {}: the pieces did not fit the piece capacity ({}); {} pieces were drawn unsplit (bent edges)",
            a[19], p.subdiv_levels, p.extra_capacity, a[20]
        ));
    }
    if a[1] > 0 || a[2] > 0 {
        r.degraded.push(format!("{} pieces dropped, {} queue-full finishes", a[1], a[2]));
    }
}

/// The row and column warping functions as `res x res` pictures.
fn warp_images(t: &Warped, gpu: &Gpu, r: &mut TechniqueReport) {
    let res = t.res;
    let n = (res * res) as usize;
    let w = t.read_warp(gpu);
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

impl Warped {
    /// The pieces of its own subdivision the last frame drew: its triangles' slots, then the
    /// pieces appended, each (triangle, three corners as packed unorm16 barycentrics; a queued
    /// triangle's slot holds zero corners).
    pub fn read_pieces(&self, gpu: &Gpu) -> Vec<[u32; 4]> {
        let appended = gpu.read_buffer_as::<u32>(&self.counters, 1)[0].min(self.params.extra_capacity);
        let words: Vec<u32> = gpu.read_buffer_as(&self.pieces, 4 * (self.params.triangles + appended) as usize);
        words.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect()
    }

    /// The warped shadow map's depths (res x res, 1 where nothing was drawn).
    pub fn read_map(&self, gpu: &Gpu) -> Vec<f32> {
        bytemuck::pod_collect_to_vec(&gpu.read_texture_layer(&self.map, 4, self.layer))
    }

    /// The DV rectangle (lo x, lo y, hi x, hi y) in base map coordinates, as the shaders use it.
    pub fn read_dv_rect(&self, gpu: &Gpu) -> [f32; 4] {
        let b: Vec<u32> = gpu.read_buffer_at(&self.dv, self.dv_offset, 4);
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
        gpu.read_buffer_at(&self.work, self.work_offset, n)
    }

    /// `cull_hidden`, `edge_importance`: the last frame's occluder map (res x res) and, with
    /// `cull_hidden`, its pyramid of maxima (all levels, level 0 first; else empty).
    pub fn read_occluders(&self, gpu: &Gpu) -> Option<(Vec<f32>, Vec<f32>)> {
        let o = self.occluders.as_ref()?;
        let (depth, layer) = o.depth();
        let pyramid = o.hzb.as_ref().map_or(Vec::new(), |h| h.read(gpu));
        Some((bytemuck::pod_collect_to_vec(&gpu.read_texture_layer(depth, 4, layer)), pyramid))
    }

    /// The view samples per texel of the final (warped) map, counted by the last evaluation.
    pub fn read_counts_final(&self, gpu: &Gpu) -> Vec<u32> {
        gpu.read_buffer_at(&self.counts, self.counts_offset, (self.res * self.res) as usize)
    }

    /// The count map rebuilt through the row warps (`notw`; fractional: each texel's count is
    /// spread over the texels of its image).
    pub fn read_counts_rows(&self, gpu: &Gpu) -> Vec<f32> {
        gpu.read_buffer_at(&self.fwork, self.fwork_offset, (self.res * self.res) as usize)
    }

    /// The warp textures of the last frame.
    pub fn read_warp(&self, gpu: &Gpu) -> Warp2D {
        let ox: Vec<f32> = bytemuck::pod_collect_to_vec(&gpu.read_texture_layer(&self.warp_x, 4, self.layer));
        let oy: Vec<f32> = bytemuck::pod_collect_to_vec(&gpu.read_texture_layer(&self.warp_y, 4, self.layer));
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

    /// Bytes of scratch this map allocated (work buffers, counts, the occluder map and pyramid,
    /// and its own subdivision buffers, not its owner's).
    pub fn scratch_bytes(&self) -> u64 {
        let subdiv = if self.owns_subdiv { self.pieces.size() + 2 * self.queues[0].size() } else { 0 };
        let occ = self.occluders.as_ref().map_or(0, |o| o.bytes());
        // the work buffers and counts: this map's share when layered
        let counts = 4 * self.res as u64 * self.res as u64;
        let [work, fwork] = self.variant.work_words(self.res);
        4 * (work + fwork) + counts + subdiv + occ
    }
}
