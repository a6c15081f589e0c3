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

/// Where a map's occluder map and pyramid go when they are a layer of shared ones
/// ([`super::Layers`]): `layer` of `depth`, and the pyramid at a byte offset of `hzb` (else its
/// own buffer).
pub(super) struct Target<'a> {
    pub depth: &'a wgpu::Texture,
    pub layer: u32,
    pub hzb: Option<(&'a wgpu::Buffer, u64)>,
}

pub(super) struct Pyramid {
    /// Its own buffer, or its slice of a shared one (from `offset`).
    buffer: wgpu::Buffer,
    offset: u64,
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
        let slice = target.and_then(|t| t.hzb);
        let hzb = (p.cull_hidden > 0.5).then(|| Pyramid::new(gpu, name, res, &constants, &view, slice));
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
            for (l, group) in h.groups.iter().enumerate() {
                let side = side(self.res, l as u32);
                let pipeline = if l == 0 { &h.base } else { &h.reduce };
                gpu.dispatch_2d(enc, "hzb", pipeline, &[group], side, side);
            }
        }
    }
}

impl Pyramid {
    /// The pyramid of the occluder map `view`, in `slice` (a buffer and byte offset) or its own.
    fn new(
        gpu: &Gpu,
        name: &str,
        res: u32,
        constants: &[(&str, f64)],
        view: &wgpu::TextureView,
        slice: Option<(&wgpu::Buffer, u64)>,
    ) -> Pyramid {
        let layout = layout_at(
            gpu,
            &format!("{name}.hzb"),
            wgpu::ShaderStages::COMPUTE,
            &[(0, binding::texture_depth()), (1, binding::storage(false)), (2, binding::uniform())],
        );
        let src = hzb_src();
        let (buffer, offset) =
            slice.map_or_else(|| (gpu.storage(&format!("{name}.hzb"), pyramid_len(res) * 4), 0), |(b, o)| (b.clone(), o));
        let groups = (0..=top_level(res))
            .map(|l| {
                let u = gpu.uniform(&format!("{name}.hzb{l}"), &[res, l, 0, 0]);
                gpu.bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("hzb"),
                    layout: &layout,
                    entries: &[
                        wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(view) },
                        wgpu::BindGroupEntry { binding: 1, resource: Pyramid::binding_of(&buffer, offset, res) },
                        wgpu::BindGroupEntry { binding: 2, resource: u.as_entire_binding() },
                    ],
                })
            })
            .collect();
        Pyramid {
            base: gpu.compute_pipeline_with(&format!("{name}.hzb_base"), &src, "hzb_base", &[&layout], constants),
            reduce: gpu.compute_pipeline_with(&format!("{name}.hzb_reduce"), &src, "hzb_reduce", &[&layout], constants),
            buffer,
            offset,
            groups,
        }
    }

    fn binding_of(buffer: &wgpu::Buffer, offset: u64, res: u32) -> wgpu::BindingResource<'_> {
        wgpu::BindingResource::Buffer(wgpu::BufferBinding { buffer, offset, size: wgpu::BufferSize::new(pyramid_len(res) * 4) })
    }

    /// The last frame's pyramid (all levels, level 0 first).
    pub fn read(&self, gpu: &Gpu, res: u32) -> Vec<f32> {
        gpu.read_buffer_at(&self.buffer, self.offset, pyramid_len(res) as usize)
    }

    /// The pyramid as a pass binds it (its slice of a shared buffer).
    pub fn binding(&self, res: u32) -> wgpu::BindingResource<'_> {
        Pyramid::binding_of(&self.buffer, self.offset, res)
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
