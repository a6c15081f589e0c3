//! `csm`'s report: memory, per-cascade splits and texel sizes, sampling over all cascades,
//! each cascade's depth and count maps, and the cascade each pixel used (`sdsm` adds its fitted
//! boxes to it).

use shadowlab_core::metrics::sampling_stats;

use super::Cascaded;
use crate::technique::{NamedImage, TechniqueReport};
use crate::techniques::pictures::{count_image, depth_image};
use crate::Gpu;

/// Cascade colours of the cascade-index picture (cascade 0 first); blended pixels are lighter.
const COLOURS: [[u8; 3]; 8] =
    [[230, 60, 50], [60, 180, 75], [50, 110, 230], [240, 200, 40], [170, 70, 200], [40, 200, 210], [240, 130, 40], [150, 150, 150]];

pub(super) fn report(t: &Cascaded, gpu: &Gpu) -> TechniqueReport {
    let texels = t.res as usize * t.res as usize;
    let counts: Vec<u32> = gpu.read_buffer_as(&t.counts, t.count * texels);
    let mut r =
        TechniqueReport { shadow_data_bytes: (t.count * texels * 4) as u64, sampling: Some(sampling_stats(&counts)), ..Default::default() };
    let c = &mut r.counters;
    c.insert("cascades".into(), t.count as f64);
    c.insert("shadow_map_texels".into(), (t.count * texels) as f64);
    // the cascades as the evaluation used them (csm: the slice boxes; sdsm: the fitted ones,
    // their larger texel side)
    let used = &t.params.cascades[..t.boxes.len()];
    if let Some(u) = used.first() {
        c.insert("split_0".into(), u.info[1] as f64);
    }
    for (i, u) in used.iter().enumerate() {
        c.insert(format!("split_{}", i + 1), u.info[2] as f64);
        c.insert(format!("texel_{i}"), u.info[0] as f64);
        c.insert(format!("box_side_{i}"), u.info[0] as f64 * t.res as f64);
    }
    if let Some((lo, hi)) = t.depth_range {
        c.insert("gbuffer_depth_min".into(), lo as f64);
        c.insert("gbuffer_depth_max".into(), hi as f64);
    }
    let mut blended = 0.0;
    if let Some((buf, w, h)) = &t.chosen {
        let tags: Vec<u32> = gpu.read_buffer_as(buf, (*w * *h) as usize);
        let evaluated = tags.iter().filter(|x| **x != 0).count().max(1) as f64;
        blended = tags.iter().filter(|x| **x > 16).count() as f64 / evaluated;
        for i in 0..t.count {
            let n = tags.iter().filter(|x| **x != 0 && ((**x - 1) % 16) as usize == i).count();
            c.insert(format!("pixels_in_cascade_{i}"), n as f64 / evaluated);
        }
        r.images.push(index_image(&tags, *w, *h));
    }
    c.insert("blended_fraction".into(), blended);
    c.insert("fetches_per_pixel".into(), (t.pcf * t.pcf) as f64 * (1.0 + blended));
    for i in 0..t.count {
        let depth: Vec<f32> = bytemuck::pod_collect_to_vec(&read_layer(gpu, &t.maps, i as u32));
        r.images.push(depth_image(&format!("cascade {i} depth"), t.res, &depth));
        r.images.push(count_image(&format!("cascade {i} view samples per texel"), t.res, &counts[i * texels..(i + 1) * texels]));
    }
    r
}

/// Which cascade each pixel used (colours per cascade, lighter in a blend band; black = not evaluated).
fn index_image(tags: &[u32], w: u32, h: u32) -> NamedImage {
    let rgba = tags
        .iter()
        .flat_map(|&t| {
            if t == 0 {
                return [0, 0, 0, 255];
            }
            let [r, g, b] = COLOURS[((t - 1) % 16) as usize % COLOURS.len()];
            if t > 16 {
                [r / 2 + 128, g / 2 + 128, b / 2 + 128, 255]
            } else {
                [r, g, b, 255]
            }
        })
        .collect();
    NamedImage { name: "cascade used per pixel".into(), width: w, height: h, rgba }
}

/// One layer of a depth texture array, read back as tightly packed f32 (copied through a 2D
/// texture so the shared readback helper applies).
fn read_layer(gpu: &Gpu, tex: &wgpu::Texture, layer: u32) -> Vec<u8> {
    let size = wgpu::Extent3d { width: tex.width(), height: tex.height(), depth_or_array_layers: 1 };
    let tmp = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("csm.layer"),
        size,
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: tex.format(),
        usage: wgpu::TextureUsages::COPY_DST | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    enc.copy_texture_to_texture(
        wgpu::TexelCopyTextureInfo {
            texture: tex,
            mip_level: 0,
            origin: wgpu::Origin3d { x: 0, y: 0, z: layer },
            aspect: wgpu::TextureAspect::All,
        },
        tmp.as_image_copy(),
        size,
    );
    gpu.submit(enc.finish());
    gpu.read_texture(&tmp, 4)
}
