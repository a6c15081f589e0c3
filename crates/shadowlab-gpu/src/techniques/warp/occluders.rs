//! `cull_hidden`, `edge_importance` (planar warped maps): the scene drawn into the DV-cropped
//! map without the warp (occluders.wgsl, a plain shadow map, res x res), which the count map
//! reads for `edge_importance`; for `cull_hidden` its depths are reduced to a pyramid of 2x2
//! maxima (hzb.wgsl). subdiv.wgsl then leaves an edge unsplit when everything around it is
//! nearer to the light than the edge: its bend cannot show. The decision is a function of the
//! edge (both pieces on it agree: no cracks) and of the map (the same on every run), and an
//! unsplit edge is still drawn, coarser, never dropped.

use std::ops::Range;

use super::{base_constants, compose, layout_at, WarpParams, LOOKUP_WGSL, PARAMS_WGSL};
use crate::scene_gpu::GpuScene;
use crate::{binding, raster, Gpu};

const OCCLUDERS_WGSL: &str = include_str!("occluders.wgsl");
const HZB_WGSL: &str = include_str!("hzb.wgsl");

pub(super) fn occluders_src() -> String {
    compose(&format!("{PARAMS_WGSL}{LOOKUP_WGSL}{OCCLUDERS_WGSL}"), true)
}

pub(super) fn hzb_src() -> String {
    compose(&format!("{PARAMS_WGSL}{HZB_WGSL}"), false)
}

pub(super) struct Occluders {
    res: u32,
    /// The occluder map: `layer` of `depth` (its own texture, or a layer of [`super::Layers`]').
    depth: wgpu::Texture,
    layer: u32,
    /// The layer's view, made once.
    view: wgpu::TextureView,
    raster: wgpu::RenderPipeline,
    /// `cull_hidden`: the pyramid of maxima, level 0 (res x res) first (params.wgsl
    /// `hzb_offset`), and how it is built; else none (`edge_importance` reads the map only).
    pub hzb: Option<Pyramid>,
}

/// Where a map's occluder map goes when it is a layer of shared ones ([`super::Layers`]):
/// `layer` of `depth`; with `owner_pyramid` the owner builds every layer's pyramid at once
/// (subdiv_layers.rs) and the map none.
pub(super) struct Target<'a> {
    pub depth: &'a wgpu::Texture,
    pub layer: u32,
    pub owner_pyramid: bool,
}

pub(super) struct Pyramid {
    /// The pyramids, level 0 first, of `layers` maps of side `res` (one map: its own).
    buffer: wgpu::Buffer,
    res: u32,
    layers: u32,
    base: wgpu::ComputePipeline,
    reduce: wgpu::ComputePipeline,
    /// One bind group per level (the occluder map, the pyramid, the level's uniform (res, level)),
    /// made once: nothing in them changes between frames.
    groups: Vec<wgpu::BindGroup>,
}

/// Levels above 0 until the side is 1.
fn top_level(res: u32) -> u32 {
    32 - (res.max(1) - 1).leading_zeros()
}

/// Side of level `l`: ceil(res / 2^l) (params.wgsl `hzb_side`).
fn side(res: u32, l: u32) -> u32 {
    res.div_ceil(1 << l).max(1)
}

/// Floats of the whole pyramid.
pub fn pyramid_len(res: u32) -> u64 {
    (0..=top_level(res)).map(|l| (side(res, l) as u64).pow(2)).sum()
}

impl Occluders {
    /// With `target` the map is that layer of that array texture (res x res), else its own.
    pub fn new(
        gpu: &Gpu,
        name: &str,
        res: u32,
        p: &WarpParams,
        lookup: &wgpu::BindGroupLayout,
        scene: &GpuScene,
        target: Option<Target>,
    ) -> Occluders {
        let label = format!("{name}.occluders");
        let constants = base_constants(p);
        let raster = raster::depth_pipeline_with(gpu, &label, &occluders_src(), &[lookup, &scene.layout], scene.has_cutouts, &constants);
        let (depth, layer) = match target.as_ref().map(|t| (t.depth, t.layer)) {
            Some((t, layer)) => {
                assert!(
                    t.width() == res && t.height() == res && layer < t.depth_or_array_layers(),
                    "{name}: occluder layers of another size"
                );
                (t.clone(), layer)
            }
            None => (raster::depth_target(gpu, &label, res, res, 1, wgpu::TextureUsages::empty()), 0),
        };
        let view = depth.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2),
            base_array_layer: layer,
            array_layer_count: Some(1),
            ..Default::default()
        });
        let own_pyramid = p.cull_hidden > 0.5 && !target.is_some_and(|t| t.owner_pyramid);
        let hzb = own_pyramid.then(|| {
            let array = depth.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                base_array_layer: layer,
                array_layer_count: Some(1),
                ..Default::default()
            });
            Pyramid::new(gpu, name, res, &constants, &array, None)
        });
        Occluders { res, hzb, view, depth, layer, raster }
    }

    /// The occluder map's texture and layer.
    pub fn depth(&self) -> (&wgpu::Texture, u32) {
        (&self.depth, self.layer)
    }

    /// The occluder map's view.
    pub fn view(&self) -> &wgpu::TextureView {
        &self.view
    }

    /// Bytes of the occluder map and its pyramid.
    pub fn bytes(&self) -> u64 {
        4 * self.res as u64 * self.res as u64 + self.hzb.as_ref().map_or(0, |_| pyramid_len(self.res) * 4)
    }

    /// The occluder pass over `triangles` of `scene` and (`cull_hidden`) the pyramid; `lookup`
    /// is the depth pass's group (the DV rectangle).
    pub fn record(&self, gpu: &Gpu, enc: &mut wgpu::CommandEncoder, lookup: &wgpu::BindGroup, scene: &GpuScene, triangles: Range<u32>) {
        {
            let mut pass = raster::begin_pass(enc, "occluders", &[], &self.view);
            pass.set_pipeline(&self.raster);
            pass.set_bind_group(0, lookup, &[]);
            pass.set_bind_group(1, &scene.group, &[]);
            pass.draw(triangles.start * 3..triangles.end * 3, 0..1);
        }
        if let Some(h) = &self.hzb {
            h.record(gpu, enc);
        }
    }
}

impl Pyramid {
    /// The pyramids of the occluder maps of `view` (an array view): with `shared` = (buffer,
    /// layers, stride) every layer's, `stride` bytes apart in that buffer; else the one layer's
    /// in a buffer of its own.
    pub(super) fn new(
        gpu: &Gpu,
        name: &str,
        res: u32,
        constants: &[(&str, f64)],
        view: &wgpu::TextureView,
        shared: Option<(&wgpu::Buffer, u32, u64)>,
    ) -> Pyramid {
        let depth_array = wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Depth,
            view_dimension: wgpu::TextureViewDimension::D2Array,
            multisampled: false,
        };
        let layout = layout_at(
            gpu,
            &format!("{name}.hzb"),
            wgpu::ShaderStages::COMPUTE,
            &[(0, depth_array), (1, binding::storage(false)), (2, binding::uniform())],
        );
        let src = hzb_src();
        let (buffer, layers, stride) = match shared {
            Some((b, layers, stride)) => (b.clone(), layers, stride),
            None => (gpu.storage(&format!("{name}.hzb"), pyramid_len(res) * 4), 1, 0),
        };
        let groups = (0..=top_level(res))
            .map(|l| {
                let u = gpu.uniform(&format!("{name}.hzb{l}"), &[res, l, 0, 0]);
                gpu.bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("hzb"),
                    layout: &layout,
                    entries: &[
                        wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(view) },
                        wgpu::BindGroupEntry { binding: 1, resource: buffer.as_entire_binding() },
                        wgpu::BindGroupEntry { binding: 2, resource: u.as_entire_binding() },
                    ],
                })
            })
            .collect();
        let mut constants = constants.to_vec();
        constants.push(("HZB_STRIDE", (stride / 4) as f64));
        Pyramid {
            base: gpu.compute_pipeline_with(&format!("{name}.hzb_base"), &src, "hzb_base", &[&layout], &constants),
            reduce: gpu.compute_pipeline_with(&format!("{name}.hzb_reduce"), &src, "hzb_reduce", &[&layout], &constants),
            buffer,
            res,
            layers,
            groups,
        }
    }

    /// Every level of every layer's pyramid, one dispatch a level.
    pub(super) fn record(&self, gpu: &Gpu, enc: &mut wgpu::CommandEncoder) {
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("hzb"), timestamp_writes: None });
        for (l, group) in self.groups.iter().enumerate() {
            let side = side(self.res, l as u32).div_ceil(8);
            pass.set_pipeline(if l == 0 { &self.base } else { &self.reduce });
            pass.set_bind_group(0, group, &[]);
            gpu.dispatch(&mut pass, [side, side, self.layers]);
        }
    }

    /// The last frame's pyramid (all levels, level 0 first) of a map's own.
    pub fn read(&self, gpu: &Gpu) -> Vec<f32> {
        gpu.read_buffer_at(&self.buffer, 0, pyramid_len(self.res) as usize)
    }

    /// The pyramids as a pass binds them.
    pub fn buffer(&self) -> &wgpu::Buffer {
        &self.buffer
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pyramid_ends_in_one_texel_and_holds_every_level() {
        assert_eq!(top_level(512), 9);
        assert_eq!(top_level(1), 0);
        assert_eq!(top_level(600), 10);
        assert_eq!(pyramid_len(4), 16 + 4 + 1);
        assert_eq!(pyramid_len(5), 25 + 9 + 4 + 1);
        // the subdivision's widest rectangle (res - 1 texels) asks for level top_level
        assert_eq!(32 - (599u32).leading_zeros(), top_level(600));
    }
}
