//! `virtual`'s passes: marking, the readback and CPU allocation (`prepare`), page rendering
//! into the atlas (`render`), evaluation through the page table (`evaluate`).

use shadowlab_core::light::Light;
use shadowlab_core::params::ParamSet;
use shadowlab_core::scene::Bounds;
use shadowlab_core::techniques::virtual_sm::{
    bias_scale, pixel_angle, with_fallbacks, Allocation, Build, Clipmap, Demand, PageCache, PageKey, Projection, StaticCopies,
};

use super::bounds::ChunkBounds;
use super::draw::{clear_pipeline, copy_pipeline, moving_over, Chunk};
use super::{eval_source, mark_source, page_source, VirtualParams, VirtualSettings, MAX_LEVELS};
use crate::record::Recorder;
use crate::scene_gpu::GpuScene;
use crate::technique::{view_layout, EvalPipelines, FrameInputs, Technique, TechniqueReport};
use crate::{binding, raster, Gpu, GpuError};

/// Triangles per culling chunk (iasm's chunks): a page draws the chunks whose light-space
/// rectangle overlaps it. Smaller: tighter culling, more draws per page.
pub const CHUNK_TRIANGLES: u32 = 1024;

/// Triangles per chunk of moving geometry: its swept boxes invalidate the pages under them
/// every frame, so they are kept small (a long swaying cable in 1024-triangle chunks is one
/// box over its whole length). Smaller: tighter invalidation, more boxes read back per frame.
pub const DYNAMIC_CHUNK_TRIANGLES: u32 = 64;

pub struct VirtualShadows {
    pub(super) light: Light,
    /// The `levels` parameter (the clipmap's levels, or a perspective map's mips at most).
    levels_param: u32,
    /// Level indices of the page table (a cube's: 6 x its mips).
    pub(super) levels: u32,
    /// Levels per face, and faces (6 for a point light).
    pub(super) mips: u32,
    pub(super) faces: u32,
    pub(super) virtual_res: u32,
    pub(super) page_res: u32,
    pub(super) extent0: f32,
    pub(super) bias_scale: f32,
    pub(super) reach: f32,
    pub(super) params: VirtualParams,
    pub(super) clipmap: Option<Clipmap>,
    pub(super) cache: PageCache,
    pub(super) alloc: Allocation,
    /// Requested pages of the last frame (priority order).
    pub(super) requested: Vec<PageKey>,
    pub(super) frames: u64,
    pub(super) rendered_total: u64,
    pub(super) cols: u32,
    pub(super) rows: u32,
    /// The static copies (UE5's static/dynamic split) and how each rendered page of the last
    /// frame was built (`alloc.render`'s order).
    pub(super) statics: StaticCopies,
    pub(super) builds: Vec<Build>,
    pub(super) static_cols: u32,
    pub(super) static_atlas: wgpu::Texture,
    /// Per rendered page: its static slot's origin minus its atlas slot's origin (texels).
    pub(super) copy_offsets: wgpu::Buffer,
    pub(super) copy_group: wgpu::BindGroup,
    pub(super) copy_pipeline: wgpu::RenderPipeline,
    /// Triangles the last frame drew into pages (static pool and atlas).
    pub(super) triangles_drawn: u64,
    pub(super) chunks: Vec<Chunk>,
    /// The chunks of moving triangles (`dynamic_first..`), bounded every frame; the last
    /// frame's boxes (None before the first).
    dynamic: Option<ChunkBounds>,
    dynamic_boxes: Option<Vec<Bounds>>,
    /// Index of the first dynamic chunk in `chunks`.
    pub(super) dynamic_chunk0: usize,
    pub(super) invalidated: usize,
    /// Fallback pages (one level coarser) the last frame added for pages a full pool left out.
    pub(super) fallback_added: usize,
    pub(super) invalidated_total: u64,
    probe: wgpu::Buffer,
    pub(super) atlas: wgpu::Texture,
    uniform: wgpu::Buffer,
    pub(super) requests: wgpu::Buffer,
    page_table: wgpu::Buffer,
    page_mats: wgpu::Buffer,
    pub(super) counts: wgpu::Buffer,
    mark_layout: wgpu::BindGroupLayout,
    mark: wgpu::ComputePipeline,
    eval_layout: wgpu::BindGroupLayout,
    eval: EvalPipelines,
    pub(super) page_group: wgpu::BindGroup,
    pub(super) page_pipeline: wgpu::RenderPipeline,
    pub(super) clear_pipeline: wgpu::RenderPipeline,
}

impl VirtualShadows {
    /// Settings that break [`VirtualSettings`]'s rules are an error.
    pub fn new(gpu: &Gpu, scene: &GpuScene, p: &VirtualSettings, light: &Light) -> Result<VirtualShadows, GpuError> {
        p.validate().map_err(|e| GpuError::Invalid(format!("virtual: {e}")))?;
        let (virtual_res, page_res, levels) = (p.virtual_res, p.page_res, p.levels);
        let extent0 = p.level0_extent as f32;
        // the light's projection at creation (the light never moves): chunk rectangles, levels
        let proto = Clipmap::for_light(light, &scene.bounds, scene.bounds.center(), levels, virtual_res, page_res, extent0);
        let levels_param = levels;
        let levels = proto.levels;
        let max = gpu.limits.max_texture_dimension_2d;
        let page_bytes = page_res as f64 * page_res as f64 * 4.0;
        let pool_mib = p.pool_mib;
        let static_mib = pool_mib * p.static_share;
        // the static copies come out of the pool, and only where something moves
        let moving = scene.dynamic_first < scene.triangle_count;
        let static_slots = if moving { atlas_shape((static_mib * 1048576.0 / page_bytes).floor() as u32, page_res, max) } else { (1, 0) };
        let slots = ((pool_mib * 1048576.0 - (static_slots.0 * static_slots.1) as f64 * page_bytes) / page_bytes).floor() as u32;
        let (cols, rows) = atlas_shape(slots, page_res, max);
        if rows == 0 {
            return Err(GpuError::Invalid(format!("virtual: pool_mib {pool_mib} holds no page of {page_res}^2 besides its static copies")));
        }
        let d = &gpu.device;
        let atlas = raster::depth_target(gpu, "virtual.atlas", cols * page_res, rows * page_res, 1, wgpu::TextureUsages::empty());
        let (static_cols, static_rows) = static_slots;
        let static_atlas = raster::depth_target(
            gpu,
            "virtual.static_atlas",
            static_cols * page_res,
            static_rows.max(1) * page_res,
            1,
            wgpu::TextureUsages::empty(),
        );
        let copy_offsets = gpu.storage("virtual.copy_offsets", (cols * rows) as u64 * 16);
        let (copy_layout, copy_pipeline) = copy_pipeline(gpu);
        let static_view = static_atlas.create_view(&Default::default());
        let copy_group = binding::group(
            d,
            "virtual.copy",
            &copy_layout,
            &[wgpu::BindingResource::TextureView(&static_view), copy_offsets.as_entire_binding()],
        );
        let pages_per_side = virtual_res / page_res;
        let table_len = (levels * pages_per_side * pages_per_side) as u64;
        let params = VirtualParams::zeroed_for(p, &proto, pages_per_side, page_res, cols);
        let uniform = gpu.uniform("virtual.params", &params);
        let requests = gpu.storage("virtual.requests", table_len * 4);
        let page_table = gpu.storage("virtual.page_table", table_len * 4);
        let page_mats = gpu.storage("virtual.page_view_proj", (cols * rows) as u64 * 64);
        let counts = gpu.storage("virtual.counts", (MAX_LEVELS as u64 + 1) * 4);
        let mark_layout = view_layout(gpu, "virtual.mark", &[binding::uniform(), binding::storage(false)]);
        let mark = gpu.compute_pipeline("virtual.mark", &mark_source(), "main", &[&mark_layout]);
        let eval_layout = view_layout(
            gpu,
            "virtual.eval",
            &[binding::uniform(), binding::storage(true), binding::texture_depth(), binding::storage(false)],
        );
        let eval = EvalPipelines::new(gpu, "virtual.eval", &eval_source(), &eval_layout, &[]);
        let page_layout = binding::layout(d, "virtual.page", wgpu::ShaderStages::VERTEX, &[binding::storage(true)]);
        let page_group = binding::group(d, "virtual.page", &page_layout, &[page_mats.as_entire_binding()]);
        let page_pipeline = raster::depth_pipeline(gpu, "virtual.page", &page_source(), &[&page_layout, &scene.layout], scene.has_cutouts);
        let clear_pipeline = clear_pipeline(gpu, &page_source(), &[&page_layout, &scene.layout]);
        // static chunks: bounded once here, at creation; moving ones: every frame (prepare)
        let mut chunks = Vec::new();
        let split = scene.dynamic_first.min(scene.triangle_count);
        if split > 0 {
            let b = ChunkBounds::new(gpu, scene, "virtual.static_bounds", 0, split, CHUNK_TRIANGLES);
            let mut enc = d.create_command_encoder(&Default::default());
            b.record(&mut enc, scene);
            gpu.submit(enc.finish());
            gpu.take_error()?;
            let boxes = ChunkBounds::parse(&gpu.read_buffer_as::<u32>(&b.boxes, b.count as usize * 6));
            for (i, w) in boxes.iter().enumerate() {
                let first = i as u32 * CHUNK_TRIANGLES;
                chunks.push(Chunk::new(first, (first + CHUNK_TRIANGLES).min(split), w, &proto));
            }
        }
        let dynamic_chunk0 = chunks.len();
        let dynamic = (split < scene.triangle_count)
            .then(|| ChunkBounds::new(gpu, scene, "virtual.dynamic_bounds", split, scene.triangle_count, DYNAMIC_CHUNK_TRIANGLES));
        if let Some(b) = &dynamic {
            for i in 0..b.count {
                let first = split + i * DYNAMIC_CHUNK_TRIANGLES;
                chunks.push(Chunk::new(first, (first + DYNAMIC_CHUNK_TRIANGLES).min(scene.triangle_count), &scene.bounds, &proto));
            }
        }
        let probe = gpu.storage("virtual.probe", table_len * 4 + dynamic.as_ref().map_or(0, |b| b.count as u64 * 24));
        let kernel_half = (p.pcf as f32 - 1.0) * 0.5;
        Ok(VirtualShadows {
            light: *light,
            levels_param,
            levels,
            mips: proto.mips,
            faces: proto.faces(),
            virtual_res,
            page_res,
            extent0,
            bias_scale: bias_scale(p.resolution_bias as f32),
            // the kernel, the normal offset's sideways shift, one texel of rounding
            reach: kernel_half + p.bias.normal_offset as f32 + 1.0,
            params,
            clipmap: None,
            cache: PageCache::new(cols * rows),
            alloc: Allocation::default(),
            requested: Vec::new(),
            frames: 0,
            rendered_total: 0,
            cols,
            rows,
            statics: StaticCopies::new(static_cols * static_rows),
            builds: Vec::new(),
            static_cols,
            static_atlas,
            copy_offsets,
            copy_group,
            copy_pipeline,
            triangles_drawn: 0,
            chunks,
            dynamic,
            dynamic_boxes: None,
            dynamic_chunk0,
            invalidated: 0,
            fallback_added: 0,
            invalidated_total: 0,
            probe,
            atlas,
            uniform,
            requests,
            page_table,
            page_mats,
            counts,
            mark_layout,
            mark,
            eval_layout,
            eval,
            page_group,
            page_pipeline,
            clear_pipeline,
        })
    }

    /// The clipmap of the last frame.
    pub fn clipmap(&self) -> Option<&Clipmap> {
        self.clipmap.as_ref()
    }

    /// The last frame's allocation (mapped, rendered, cached, fallen-back pages).
    pub fn allocation(&self) -> &Allocation {
        &self.alloc
    }

    /// How each page of the last frame's `allocation().render` was built (drawn whole, or from
    /// a static copy).
    pub fn builds(&self) -> &[Build] {
        &self.builds
    }

    /// The static copies of pages under moving geometry.
    pub fn statics(&self) -> &StaticCopies {
        &self.statics
    }

    /// The page pool and its resident pages.
    pub fn cache(&self) -> &PageCache {
        &self.cache
    }

    /// Resident pages the last frame dropped because a moving chunk swept over them.
    pub fn invalidated(&self) -> usize {
        self.invalidated
    }

    /// The pages requested in the last frame (priority order, from the GPU's marks).
    pub fn requested(&self) -> &[PageKey] {
        &self.requested
    }

    /// Forgets the pages over world box `b` at every level (moving geometry); returns how many
    /// resident pages were dropped.
    pub fn invalidate_box(&mut self, b: &Bounds) -> usize {
        let Some(c) = &self.clipmap else { return 0 };
        let keys: Vec<PageKey> = (0..self.levels).flat_map(|k| c.pages_touching(k, b)).collect();
        self.cache.invalidate(&keys)
    }
}

/// An atlas of at most `slots` pages in full rows (columns, rows), each side within `max`
/// texels: a power-of-two column count around sqrt(slots) when that holds as many pages as any
/// shape can, otherwise the squarest shape that holds the most (168 slots: 14 x 12, where 16
/// columns would hold 160).
fn atlas_shape(slots: u32, page_res: u32, max: u32) -> (u32, u32) {
    let side = (max / page_res).max(1);
    let fit = |c: u32| (c, (slots / c).min(side));
    let count = |(c, r): (u32, u32)| c * r;
    let pow2 = fit(((slots as f64).sqrt().ceil() as u32).next_power_of_two().min(side).max(1));
    let most = (1..=side).map(|c| count(fit(c))).max().unwrap_or(0);
    if count(pow2) == most {
        return pow2;
    }
    (1..=side).map(fit).filter(|s| count(*s) == most).min_by_key(|(c, r)| c.abs_diff(*r)).unwrap_or(pow2)
}

impl VirtualParams {
    fn zeroed_for(p: &VirtualSettings, proto: &Clipmap, n: u32, page_res: u32, cols: u32) -> VirtualParams {
        let levels = proto.levels;
        let mut v: VirtualParams = bytemuck::Zeroable::zeroed();
        v.dims = [levels, n, page_res, cols];
        v.bias = p.bias.packed();
        v.pcf = [p.pcf, 0, proto.mips, proto.faces()];
        if let Some((position, tan_half)) = proto.persp() {
            v.pcf[1] = if matches!(proto.projection, Projection::Cube { .. }) { 2 } else { 1 };
            v.spot = position.extend(tan_half).into();
        }
        for f in 0..proto.faces() {
            let (r, u, d) = proto.axes(f);
            for (i, a) in [r, u, d].iter().enumerate() {
                v.face_axes[3 * f as usize + i] = a.extend(0.0).into();
            }
        }
        v
    }
}

impl Technique for VirtualShadows {
    /// Marking on the GPU, one readback, the allocation and page table on the CPU.
    fn prepare(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        let c = Clipmap::for_light(
            &self.light,
            &f.scene.bounds,
            f.camera.position,
            self.levels_param,
            self.virtual_res,
            self.page_res,
            self.extent0,
        );
        let v = &mut self.params;
        v.right = c.right.extend(c.texel0_scale()).into();
        v.up = c.up.extend(c.inv_texel(0)).into();
        v.dir = c.dir.extend(c.z_near).into();
        v.view = [c.z_far, pixel_angle(f.camera.fov_y_deg, f.gbuffer.height), self.bias_scale, self.reach];
        // (a perspective map's origins are all 0: WGSL reads only the clipmap's, at most 24)
        for (k, o) in c.origins.iter().take(MAX_LEVELS).enumerate() {
            v.origins[k] = [o.x, o.y, 0, 0];
        }
        rec.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&self.params));
        let group =
            f.view_group(gpu, "virtual.mark", &self.mark_layout, &[self.uniform.as_entire_binding(), self.requests.as_entire_binding()]);
        let table_bytes = c.table_len() as u64 * 4;
        rec.stage("virtual.mark", |enc| {
            enc.clear_buffer(&self.requests, 0, None);
            gpu.dispatch_2d(enc, "virtual.mark", &self.mark, &[&group], f.gbuffer.width, f.gbuffer.height);
            enc.copy_buffer_to_buffer(&self.requests, 0, &self.probe, 0, table_bytes);
            if let Some(b) = &self.dynamic {
                b.record(enc, f.scene);
                enc.copy_buffer_to_buffer(&b.boxes, 0, &self.probe, table_bytes, b.count as u64 * 24);
            }
        });
        let words = c.table_len() + self.dynamic.as_ref().map_or(0, |b| b.count as usize * 6);
        let probe: Vec<u32> = rec.read_buffer_as(&self.probe, words, "virtual.readback");
        let t0 = std::time::Instant::now();
        let (flags, boxes) = probe.split_at(c.table_len());
        self.invalidated = 0;
        if self.dynamic.is_some() {
            let now = ChunkBounds::parse(boxes);
            // a chunk that moved invalidates the resident pages its old and new boxes cover
            if let Some(before) = &self.dynamic_boxes {
                for (a, b) in before.iter().zip(&now) {
                    if a != b {
                        let mut swept = *a;
                        swept.grow(b.min);
                        swept.grow(b.max);
                        self.invalidated += self.cache.invalidate_if(|k| c.page_overlaps(k, &swept));
                    }
                }
            }
            for (i, b) in now.iter().enumerate() {
                let ch = &mut self.chunks[self.dynamic_chunk0 + i];
                *ch = Chunk::new(ch.first, ch.end, b, &c);
            }
            self.dynamic_boxes = Some(now);
        }
        self.invalidated_total += self.invalidated as u64;
        // mark.wgsl: flags in bits 0-1 (1 requested, 2 a fallback candidate), samples above
        let pages = |keep: fn(u32) -> bool| -> Vec<PageKey> {
            flags.iter().enumerate().filter(|(_, f)| keep(**f)).map(|(i, _)| c.key_of_index(i)).collect()
        };
        let mut req = pages(|f| f & 1 != 0);
        req.sort();
        let cand = pages(|f| f & 3 == 2);
        let counts: Vec<(PageKey, u32)> =
            flags.iter().enumerate().filter(|(_, f)| **f >> 2 != 0).map(|(i, f)| (c.key_of_index(i), f >> 2)).collect();
        let demand = Demand::up_the_chain(&counts, c.levels, self.faces);
        let all = with_fallbacks(&req, &cand, self.cache.slots() as usize, self.faces, &demand);
        self.fallback_added = all.len() - req.len();
        self.alloc = self.cache.allocate_by(&all, &demand);
        self.requested = req;
        let mut table = vec![0u32; c.table_len()];
        for (k, s) in &self.alloc.mapped {
            table[c.table_index(k.level, glam::IVec2::new(k.x, k.y))] = s + 1;
        }
        rec.write_buffer(&self.page_table, 0, bytemuck::cast_slice(&table));
        let mats: Vec<[[f32; 4]; 4]> = self.alloc.render.iter().map(|(k, _)| c.page_view_proj(*k).to_cols_array_2d()).collect();
        rec.write_buffer(&self.page_mats, 0, bytemuck::cast_slice(&mats));
        let keys: Vec<PageKey> = self.alloc.render.iter().map(|(k, _)| *k).collect();
        let (chunks, moving0) = (&self.chunks, self.dynamic_chunk0);
        self.builds = self.statics.assign(&keys, |k| moving_over(chunks, moving0, &c, k));
        let pr = self.page_res as i32;
        let offsets: Vec<[i32; 4]> = self
            .alloc
            .render
            .iter()
            .zip(&self.builds)
            .map(|((_, slot), b)| match b {
                Build::Fill(s) | Build::Copy(s) => {
                    let (sc, c) = (self.static_cols, self.cols);
                    [((s % sc) as i32 - (slot % c) as i32) * pr, ((s / sc) as i32 - (slot / c) as i32) * pr, 0, 0]
                }
                Build::Full => [0; 4],
            })
            .collect();
        if !offsets.is_empty() {
            rec.write_buffer(&self.copy_offsets, 0, bytemuck::cast_slice(&offsets));
        }
        self.clipmap = Some(c);
        self.frames += 1;
        self.rendered_total += self.alloc.render.len() as u64;
        rec.cpu("virtual.allocate", t0.elapsed().as_secs_f64() * 1e3);
        Ok(())
    }

    /// The new pages (render.rs).
    fn render(&mut self, _gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        super::render::render(self, f, rec);
        Ok(())
    }

    fn evaluate(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        self.eval_pass(gpu, f, rec, false);
        Ok(())
    }

    fn analyze(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        self.eval_pass(gpu, f, rec, true);
        Ok(())
    }

    fn report(&mut self, gpu: &Gpu) -> TechniqueReport {
        super::report::report(self, gpu)
    }
}

impl VirtualShadows {
    fn eval_pass(&self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder, counting: bool) {
        let atlas_view = self.atlas.create_view(&Default::default());
        let group = f.view_group(
            gpu,
            "virtual.eval",
            &self.eval_layout,
            &[
                self.uniform.as_entire_binding(),
                self.page_table.as_entire_binding(),
                wgpu::BindingResource::TextureView(&atlas_view),
                self.counts.as_entire_binding(),
            ],
        );
        let stage = if counting { "virtual.analysis" } else { "virtual.evaluate" };
        self.eval.record(gpu, rec, stage, &self.counts, &group, f.gbuffer.width, f.gbuffer.height, counting);
    }
}

#[cfg(test)]
mod tests {
    use super::atlas_shape;

    #[test]
    fn atlas_shapes_hold_as_many_pages_as_fit() {
        // the default pool (192 pages) keeps its power-of-two shape
        assert_eq!(atlas_shape(192, 128, 16384), (16, 12));
        // the pool less its static copies: 168 pages, all of them (16 columns held 160)
        let (c, r) = atlas_shape(168, 128, 16384);
        assert_eq!((c * r, c.abs_diff(r)), (168, 2));
        assert_eq!(atlas_shape(24, 128, 16384), (8, 3));
        // a prime count: the most full rows can hold (worked out by hand), within the limit
        for (slots, max, most) in [(167, 16384, 166), (167, 2048, 165), (5, 256, 4), (1, 128, 1)] {
            let (c, r) = atlas_shape(slots, 128, max);
            assert!(c * 128 <= max && r * 128 <= max, "{slots} {max}: {c} x {r}");
            assert_eq!(c * r, most, "{slots} {max}: {c} x {r}");
        }
    }
}
