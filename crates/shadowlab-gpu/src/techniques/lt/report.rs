//! Leak tracing's report: memory, counters, the static map, the temporal mask in Table 1's
//! colours and where the rays went.

use shadowlab_core::techniques::lt::{self as leak, Class, Mask, BIT_LTT, BIT_RS};

use super::screen::Screen;
use crate::technique::{NamedImage, TechniqueReport};
use crate::techniques::pictures::depth_image;
use crate::Gpu;

/// What the report reads of a `LeakTracing`.
pub(super) struct Facts<'a> {
    /// `lt` (the temporal mask and its history).
    pub temporal: bool,
    /// Map side (texels).
    pub res: u32,
    pub levels: usize,
    /// A dynamic map beside the static one.
    pub dynamic: bool,
    /// Hybrid cascades with a ray-traced last one.
    pub cascaded: bool,
    pub static_renders: u32,
    pub dynamic_renders: u32,
    /// The full 3x3 neighbourhood (`full`).
    pub full: bool,
    pub mask_bits: u32,
    pub static_map: &'a wgpu::Texture,
    pub screen: Option<&'a Screen>,
}

pub(super) fn report(t: &Facts, gpu: &Gpu) -> TechniqueReport {
    let texels = (t.res * t.res) as u64;
    let maps = (1 + t.dynamic as u64) * t.levels as u64;
    let mut r = TechniqueReport::default();
    let Some(s) = t.screen else { return r };
    let (w, h) = (s.width, s.height);
    let pixels = (w * h) as u64;
    let rays = s.ray_list(gpu).len() as u64;
    let mask = s.mask(gpu, t.mask_bits);
    let mask_bytes_per_light = leak::mask_bytes_per_light(1, pixels).unwrap_or(0.0);
    let temporal = t.temporal;
    // kept across frames: the maps; lt also the mask (2 x mask_bits per pixel) and the
    // reprojection history (2 x 8 bytes per pixel)
    let history_bytes = if temporal { 2 * pixels * 8 } else { 0 };
    r.shadow_data_bytes = maps * texels * 4 + if temporal { mask_bytes_per_light as u64 } else { 0 } + history_bytes;
    let c = &mut r.counters;
    c.insert("rays_traced".into(), rays as f64);
    c.insert("shadow_map_texels".into(), texels as f64);
    c.insert("maps".into(), maps as f64);
    c.insert("map_levels".into(), t.levels as f64);
    c.insert("ray_traced_cascade".into(), t.cascaded as u32 as f64);
    c.insert("static_map_renders".into(), t.static_renders as f64);
    c.insert("dynamic_map_renders".into(), t.dynamic_renders as f64);
    c.insert("fetches_per_pixel".into(), 4.0 * (1 + t.dynamic as u32) as f64);
    if temporal {
        c.insert("mask_bits_per_pixel".into(), t.mask_bits as f64);
        c.insert("mask_bytes_per_light".into(), mask_bytes_per_light);
        c.insert("history_bytes".into(), history_bytes as f64);
        c.insert("mask_reads_per_pixel".into(), if t.full { 9.0 } else { 4.0 });
    }
    // per-frame scratch: the ray list and the indirect arguments
    c.insert("list_bytes".into(), ((pixels + 1) * 4 + 16) as f64);
    let depth: Vec<f32> = bytemuck::pod_collect_to_vec(&gpu.read_texture(t.static_map, 4));
    r.images.push(depth_image("static shadow map, level 0 (linear depth)", t.res, &depth));
    r.images.push(mask_image(w, h, &mask));
    r.images.push(rays_image(w, h, &mask));
    r
}

/// The temporal mask in the colours of Table 1 (black, green, white, purple, red, yellow).
pub fn mask_image(w: u32, h: u32, mask: &[u32]) -> NamedImage {
    let rgba = mask.iter().flat_map(|&b| Class::of(Mask::from_bits(b)).rgb().into_iter().chain([255])).collect();
    NamedImage { name: "temporal mask (Table 1 colours)".into(), width: w, height: h, rgba }
}

/// Where rays went: orange = ray found the pixel lit, blue = ray found it shadowed, black = no ray.
pub fn rays_image(w: u32, h: u32, mask: &[u32]) -> NamedImage {
    let rgba = mask
        .iter()
        .flat_map(|&b| match (b & BIT_LTT != 0, b & BIT_RS != 0) {
            (false, _) => [0, 0, 0, 255],
            (true, false) => [255, 150, 0, 255],
            (true, true) => [40, 90, 255, 255],
        })
        .collect();
    NamedImage { name: "rays (orange lit, blue shadowed)".into(), width: w, height: h, rgba }
}
