//! The filterable map's report: memory (with the mip chain), reads per pixel, the map's first
//! moment as depth and the view samples per texel.

use shadowlab_core::metrics::sampling_stats;

use super::mips;
use super::{Filtered, Kind};
use crate::technique::TechniqueReport;
use crate::techniques::pictures::{count_image, depth_image};
use crate::Gpu;

pub(super) fn report(t: &Filtered, gpu: &Gpu) -> TechniqueReport {
    let n = (t.res * t.res) as usize;
    let bpt = t.bytes_per_texel();
    let counts: Vec<u32> = gpu.read_buffer_as(&t.counts, n);
    let texels: Vec<f32> = bytemuck::pod_collect_to_vec(&gpu.read_texture(&t.map, bpt as u32));
    let depth = t.first_moment_as_depth(&texels);
    let levels = t.map.mip_level_count();
    let bytes = if levels > 1 { mips::chain_bytes(t.res, bpt) } else { n as u64 * bpt };
    let mut r = TechniqueReport { shadow_data_bytes: bytes, sampling: Some(sampling_stats(&counts)), ..Default::default() };
    let c = &mut r.counters;
    // texels read per evaluated pixel: 2x2 (4 loads, or one gather of 4 depths); trilinear:
    // 2x2 on two levels (plus 4 G-buffer positions of the neighbours for the footprint)
    let texels = if levels > 1 { 8.0 } else { 4.0 };
    c.insert("fetches_per_pixel".into(), texels);
    c.insert("texture_instructions_per_pixel".into(), if t.sd { 1.0 } else { texels });
    c.insert("bytes_read_per_pixel".into(), texels * bpt as f64);
    c.insert("mip_levels".into(), levels as f64);
    c.insert("bytes_per_texel".into(), bpt as f64);
    c.insert("shadow_map_texels".into(), n as f64);
    c.insert("blur_width".into(), t.blur_width as f64);
    // transient targets kept allocated between frames (not read by the evaluation)
    c.insert("raster_depth_bytes".into(), n as f64 * 4.0);
    c.insert("blur_scratch_bytes".into(), t.blur.as_ref().map_or(0.0, |b| b.scratch_bytes() as f64));
    let what = if t.sd { "shadow map (linear depth)" } else { "moment map (first moment as depth)" };
    r.images.push(depth_image(what, t.res, &depth));
    r.images.push(count_image("view samples per texel", t.res, &counts));
    r
}

impl Filtered {
    fn bytes_per_texel(&self) -> u64 {
        self.map.format().block_copy_size(None).unwrap_or(16) as u64
    }

    /// Linear depth per texel recovered from the first channel (for the report picture).
    fn first_moment_as_depth(&self, texels: &[f32]) -> Vec<f32> {
        let ch = (self.bytes_per_texel() / 4) as usize;
        let (c, cp) = (self.params.esm_c, self.params.evsm_c_pos);
        texels
            .chunks(ch)
            .map(|t| match (self.sd, self.kind) {
                (false, Kind::Esm) => t[0].ln() / c,
                (false, Kind::Evsm) => (t[0].ln() / cp + 1.0) * 0.5,
                _ => t[0],
            })
            .collect()
    }
}
