//! Making a [`Warped`], in four stages a constructor calls in order: the knobs and the scene
//! checked into a [`Plan`] (plain data: sizes, capacities, the uniform; errors are returned
//! here), the [`Resources`] the plan sizes (textures and buffers), the [`Pipelines`] of the
//! passes (each made by its pass's file), and the map assembled from the three.

use shadowlab_core::light::Light;
use shadowlab_core::lightspace;
use shadowlab_core::techniques::dpsm::Hemisphere;

use super::layers::r32_array;
use super::{analyze, depth, eval, occluders, subdiv};
use super::{Groups, Knobs, Layers, Projection, Variant, WarpParams, Warped, DV_CROP, DV_CROP_CLOSED};
use crate::prefix_sum::PrefixSum;
use crate::scene_gpu::GpuScene;
use crate::technique::EvalPipelines;
use crate::{raster, Gpu, GpuError};

impl Warped {
    /// A planar warped map of a directional or spot light, with the knobs of `rtw`, `notw` or
    /// `notw-dv` ([`Knobs::rtw`], [`Knobs::notw`], [`Knobs::dv`]).
    pub fn new(gpu: &Gpu, scene: &GpuScene, k: &Knobs, light: &Light) -> Result<Warped, GpuError> {
        Warped::planar(gpu, scene, k, light, None)
    }

    /// `new`, drawing into layer `layer` of `layers` (warps, map, DV bounds and counts),
    /// evaluated with the others by the caller ([`super::LayerPasses`]).
    pub fn new_layer(gpu: &Gpu, scene: &GpuScene, k: &Knobs, light: &Light, layers: &Layers, layer: u32) -> Result<Warped, GpuError> {
        Warped::planar(gpu, scene, k, light, Some((layers, layer)))
    }

    fn planar(gpu: &Gpu, scene: &GpuScene, k: &Knobs, light: &Light, target: Option<(&Layers, u32)>) -> Result<Warped, GpuError> {
        let name = k.variant.name();
        let res = k.res;
        gpu.check_size(res, res, "shadow map")?;
        let lp = lightspace::fit(light, &scene.bounds, res).ok_or_else(|| {
            GpuError::Invalid(format!("{name} supports directional and spot lights (point lights: cube/paraboloid maps)"))
        })?;
        Warped::with_projection_in(gpu, scene, k, Projection::Planar(lp), name, target)
    }

    /// A warped map over `proj`, labelled `name` (wgpu labels, stage names `{name}.<stage>`),
    /// with knobs made for that kind of projection (a paraboloid's: [`Knobs::dpsm`],
    /// [`Knobs::dpsm_notw`]). The knobs also say whether the map is cropped to the desired view:
    /// `dpsm`'s is not (the plain, unwarped paraboloid map, rendered with subdivision). The
    /// caller has checked `res`.
    pub fn with_projection(gpu: &Gpu, scene: &GpuScene, k: &Knobs, proj: Projection, name: &'static str) -> Result<Warped, GpuError> {
        Warped::with_projection_in(gpu, scene, k, proj, name, None)
    }

    /// `with_projection`, drawing into layer `target.1` of `target.0` when given (as
    /// [`Warped::new_layer`]).
    pub fn with_projection_in(
        gpu: &Gpu,
        scene: &GpuScene,
        k: &Knobs,
        proj: Projection,
        name: &'static str,
        target: Option<(&Layers, u32)>,
    ) -> Result<Warped, GpuError> {
        let owner = target.filter(|(l, _)| l.owner_subdivides).map(|(l, _)| l);
        let listed = owner.map(|l| l.listed_texels());
        // one copy of the scene a layer in the owner's subdivision (Layers::repeating_scene)
        let copies = owner.filter(|l| l.repeats_scene).map_or(1, |l| l.count());
        let plan = Plan::new(k, proj, name, (scene.triangle_count, copies), gpu.limits.max_storage_buffer_binding_size, listed)?;
        // the map's own subdivision (else its owner's, LayerSubdivision)
        let own_subdiv = plan.subdiv && !target.is_some_and(|(l, _)| l.owner_subdivides);
        let resources = Resources::new(gpu, &plan, target, own_subdiv);
        let by_owner = target.is_some_and(|(l, _)| l.owner_reads_view);
        let occluders = target.map(|(l, i)| occluders::Target { depth: &l.occluders, layer: i, owner_pyramid: l.hzb.is_some() });
        let pipelines = Pipelines::new(gpu, scene, &plan, occluders, by_owner, own_subdiv);
        let scene =
            depth::SceneBinding { layout: scene.layout.clone(), cutouts: scene.has_cutouts, last: None, counting: Default::default() };
        Ok(Warped::assemble(plan, resources, pipelines, scene))
    }

    fn assemble(plan: Plan, r: Resources, p: Pipelines, scene: depth::SceneBinding) -> Warped {
        // this map's layer of each texture (the whole texture when it has its own)
        let layer_view = wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2),
            base_array_layer: r.layer,
            array_layer_count: Some(1),
            ..Default::default()
        };
        Warped {
            scene,
            groups: Groups { levels: (0..=r.level_uniforms.len()).map(|_| Default::default()).collect(), ..Default::default() },
            views: [&r.warp_x, &r.warp_y, &r.map].map(|t| t.create_view(&layer_view)),
            layer: r.layer,
            layered: r.layered,
            view_by_owner: r.view_by_owner,
            dv_offset: r.dv_offset,
            counts_offset: r.counts_offset,
            variant: plan.variant,
            label: plan.name,
            res: plan.res,
            pcf: plan.pcf,
            params: plan.params,
            uniform: r.uniform,
            dv: r.dv,
            work: r.work,
            work_offset: r.work_offset,
            fwork: r.fwork,
            fwork_offset: r.fwork_offset,
            warp_x: r.warp_x,
            warp_y: r.warp_y,
            map: r.map,
            counts: r.counts,
            pieces: r.pieces,
            counters: r.counters,
            queues: r.queues,
            owns_subdiv: true,
            owner_draw: None,
            range: None,
            dispatch: r.dispatch,
            level_uniforms: r.level_uniforms,
            prefix: p.prefix,
            analyze_layout: p.analyze_layout,
            analyze: p.analyze,
            lookup_layout: p.lookup_layout,
            depth_pipeline: p.depth_pipeline,
            flat_pipeline: p.flat_pipeline,
            occluders: p.occluders,
            split_layout: p.split_layout,
            split: p.split,
            eval_layout: p.eval_layout,
            eval: p.eval,
            sampler: p.sampler,
        }
    }
}

/// What one warped map needs, checked: no GPU object yet.
struct Plan {
    variant: Variant,
    name: &'static str,
    res: u32,
    pcf: u32,
    /// The uniform, as every pass reads it.
    params: WarpParams,
    /// Subdivision on; pieces it may add beyond the triangles; entries of each level queue and
    /// the bytes of its buffer (subdiv::queue_bytes).
    subdiv: bool,
    extra: u32,
    queue: u32,
    queue_bytes: u64,
    /// The occluder map and its pyramid (`cull_hidden`, `edge_importance`).
    occluders: bool,
}

impl Plan {
    /// `k` for `proj` over a scene of `tris` triangles, subdivided `copies` times (once per
    /// layer of an owner's subdivision over one scene, else 1), on a device whose storage
    /// bindings hold at most `max_binding` bytes. Errors: subdivision queues beyond that limit.
    /// `listed`: subdivided by its owner with other maps of these texels in all (the capacity of
    /// that subdivision).
    fn new(
        k: &Knobs,
        proj: Projection,
        name: &'static str,
        (tris, copies): (u32, u32),
        max_binding: u64,
        listed: Option<u64>,
    ) -> Result<Plan, GpuError> {
        let base = BaseProjection::of(proj, k.res);
        assert_eq!(k.paraboloid, base.kind != 0, "{name}: knobs made for another projection");
        let (subdiv, extra, queue) = subdiv::capacity(k, name, tris * copies, max_binding, listed)?;
        let params = uniform(k, &base, (tris, copies), extra);
        let queue_bytes = subdiv::queue_bytes(&params, queue, max_binding);
        let occluders = k.cull_hidden || k.edge_importance > 0;
        Ok(Plan { variant: k.variant, name, res: k.res, pcf: k.pcf, params, subdiv, extra, queue, queue_bytes, occluders })
    }

    fn warp_sizes(&self) -> [(u32, u32); 2] {
        self.variant.warp_sizes(self.res)
    }
}

/// The world -> base map projection as the uniform holds it.
struct BaseProjection {
    view_proj: glam::Mat4,
    /// World size of a texel of the uncropped map (perspective: per unit of depth).
    texel: f32,
    perspective: bool,
    /// `WarpParams::projection`: 0 planar, 1 + [`Hemisphere`] index.
    kind: u32,
}

impl BaseProjection {
    fn of(proj: Projection, res: u32) -> BaseProjection {
        let (view_proj, texel, perspective, kind) = match proj {
            Projection::Planar(lp) => (lp.view_proj, lp.texel, lp.perspective, 0),
            // 2/res of the map plane per texel: 2 (1 + n.z) / res radians (core techniques::dpsm)
            Projection::Paraboloid { view, hemisphere } => (view, 2.0 / res as f32, false, 1 + (hemisphere == Hemisphere::Back) as u32),
        };
        BaseProjection { view_proj, texel, perspective, kind }
    }
}

/// The uniform of the knobs over `base`, with the subdivision's triangles (`copies` of a scene of
/// `tris`) and extra pieces.
fn uniform(k: &Knobs, base: &BaseProjection, (tris, copies): (u32, u32), extra: u32) -> WarpParams {
    WarpParams {
        light_view_proj: base.view_proj.to_cols_array_2d(),
        texel_world: base.texel,
        perspective: base.perspective as u32 as f32,
        res: k.res as f32,
        pcf: k.pcf as f32,
        bias: k.bias[0],
        slope_bias: k.bias[1],
        normal_offset: k.bias[2],
        max_slope: k.bias[3],
        dv_margin: k.dv_margin,
        dv_mode: match (k.crop, k.close_cracks) {
            (false, _) => 0.0,
            (true, false) => DV_CROP,
            (true, true) => DV_CROP_CLOSED,
        },
        warped: (k.variant != Variant::Dv) as u32 as f32,
        window: k.window as f32,
        w_dv: k.w_dv,
        w_eye: k.w_eye,
        blur: k.blur as f32,
        subdiv: k.subdiv,
        triangles: tris * copies,
        subdiv_levels: k.subdiv_levels,
        extra_capacity: extra,
        rtw_importance: (k.variant == Variant::Rtw) as u32,
        interp: k.interp as u32,
        mix: k.mix,
        exact_depth: k.exact_depth as u32,
        projection: base.kind,
        strength: k.strength,
        bias_mode: k.bias_mode as f32,
        footprint_cap: k.footprint_cap,
        depth_clamp: k.depth_clamp as f32,
        min_piece: k.min_piece,
        exact_inverse: if k.exact_inverse { 1.0 } else { 0.0 },
        cull_hidden: if k.cull_hidden { 1.0 } else { 0.0 },
        tent: if k.tent { 1.0 } else { 0.0 },
        edge_importance: k.edge_importance,
        depth_split: k.depth_split,
        exact_tol: k.exact_tol,
        tessellate: k.tessellate,
        scene_triangles: tris,
        pad0: 0,
        pad1: 0,
        pad2: 0,
    }
}

/// The textures and buffers of a plan.
struct Resources {
    warp_x: wgpu::Texture,
    warp_y: wgpu::Texture,
    map: wgpu::Texture,
    work: wgpu::Buffer,
    work_offset: u64,
    fwork: wgpu::Buffer,
    fwork_offset: u64,
    pieces: wgpu::Buffer,
    queues: [wgpu::Buffer; 2],
    counters: wgpu::Buffer,
    level_uniforms: Vec<wgpu::Buffer>,
    uniform: wgpu::Buffer,
    dv: wgpu::Buffer,
    counts: wgpu::Buffer,
    dispatch: wgpu::Buffer,
    /// The map's layer of the three textures, and its byte offsets in `dv` and `counts` (0
    /// for a map with its own).
    layer: u32,
    layered: bool,
    view_by_owner: bool,
    dv_offset: u64,
    counts_offset: u64,
}

impl Resources {
    /// The plan's resources; with `target` its warps, map, DV bounds and counts (and the count
    /// map and analysis scratch where the owner analyses) are that layer of shared ones
    /// ([`Layers`]); without `own_subdiv` no subdivision buffers (a word each).
    fn new(gpu: &Gpu, plan: &Plan, target: Option<(&Layers, u32)>, own_subdiv: bool) -> Resources {
        let (name, res, queue) = (plan.name, plan.res, plan.queue);
        let n = res as u64 * res as u64;
        let [wx, wy] = plan.warp_sizes();
        let tris = plan.params.triangles as u64;
        let levels = subdiv::level_count(&plan.params);
        let (warp_x, warp_y, map, dv, counts, layer, dv_offset, counts_offset) = match target {
            Some((l, i)) => {
                let fits = l.res == res
                    && i < l.count()
                    && (l.warp_x.width(), l.warp_x.height()) == wx
                    && (l.warp_y.width(), l.warp_y.height()) == wy;
                assert!(fits, "{name}: layer {i} of layers made for other knobs");
                (
                    l.warp_x.clone(),
                    l.warp_y.clone(),
                    l.map.clone(),
                    l.dv.clone(),
                    l.counts.clone(),
                    i,
                    i as u64 * l.dv_stride,
                    i as u64 * n * 4,
                )
            }
            None => (
                r32_array(gpu, &format!("{name}.warp_x"), wx, 1),
                r32_array(gpu, &format!("{name}.warp_y"), wy, 1),
                raster::depth_target(gpu, &format!("{name}.map"), res, res, 1, wgpu::TextureUsages::empty()),
                gpu.storage(&format!("{name}.dv"), 32),
                gpu.storage(&format!("{name}.counts"), n * 4),
                0,
                0,
                0,
            ),
        };
        let words = plan.variant.work_words(res);
        let shared =
            target.and_then(|(l, i)| Some((l.work.as_ref()?, l.fwork.as_ref()?, i as u64 * l.work_stride, i as u64 * l.fwork_stride)));
        let (work, work_offset, fwork, fwork_offset) = match shared {
            Some((w, fw, wo, fo)) => (w.clone(), wo, fw.clone(), fo),
            None => (gpu.storage(&format!("{name}.work"), words[0] * 4), 0, gpu.storage(&format!("{name}.fwork"), words[1] * 4), 0),
        };
        Resources {
            warp_x,
            warp_y,
            map,
            layer,
            layered: target.is_some(),
            view_by_owner: target.is_some_and(|(l, _)| l.owner_reads_view),
            dv_offset,
            counts_offset,
            work,
            work_offset,
            fwork,
            fwork_offset,
            pieces: gpu.storage(&format!("{name}.pieces"), (tris + plan.extra as u64) * 16 * own_subdiv as u64),
            queues: [0, 1].map(|i| gpu.storage(&format!("{name}.queue{i}"), plan.queue_bytes * own_subdiv as u64)),
            counters: subdiv::counters_buffer(gpu, &format!("{name}.counters"), 0),
            level_uniforms: if own_subdiv { subdiv::level_uniforms(gpu, name, levels, queue) } else { Vec::new() },
            uniform: gpu.uniform(&format!("{name}.params"), &plan.params),
            dv,
            counts,
            dispatch: subdiv::dispatch_buffer(gpu, &format!("{name}.dispatch")),
        }
    }
}

/// Every pass's layouts and pipelines, in the order the passes run.
struct Pipelines {
    analyze_layout: wgpu::BindGroupLayout,
    analyze: Vec<(&'static str, wgpu::ComputePipeline)>,
    lookup_layout: wgpu::BindGroupLayout,
    depth_pipeline: wgpu::RenderPipeline,
    flat_pipeline: Option<wgpu::RenderPipeline>,
    occluders: Option<occluders::Occluders>,
    split_layout: Option<wgpu::BindGroupLayout>,
    split: Option<Vec<wgpu::ComputePipeline>>,
    eval_layout: wgpu::BindGroupLayout,
    eval: EvalPipelines,
    sampler: wgpu::Sampler,
    prefix: PrefixSum,
}

impl Pipelines {
    /// `occluders`: where the occluder map (and pyramid) draws (else its own); `by_owner`: the
    /// map's analysis is its owner's (no analysis pipelines); `own_subdiv`: the map subdivides
    /// (else no subdivision pipelines).
    fn new(gpu: &Gpu, scene: &GpuScene, plan: &Plan, occluders: Option<occluders::Target>, by_owner: bool, own_subdiv: bool) -> Pipelines {
        let name = plan.name;
        let (analyze_layout, analyze) = analyze::pipelines(gpu, name, plan.variant, &plan.params, !by_owner);
        let (lookup_layout, depth_pipeline) = depth::pipeline(gpu, name, scene, &plan.params);
        // subdivided by the owner, whose lists hold the flat pieces apart (subdiv_layers.rs)
        let flat = plan.subdiv && !own_subdiv && super::subdiv_layers::flat_split(&plan.params);
        let flat_pipeline =
            flat.then(|| depth::pipeline_in(gpu, name, scene, &WarpParams { exact_depth: 0, ..plan.params }, &lookup_layout));
        let occluders =
            plan.occluders.then(|| occluders::Occluders::new(gpu, name, plan.res, &plan.params, &lookup_layout, scene, occluders));
        let (split_layout, split) = own_subdiv.then(|| subdiv::pipelines(gpu, name, scene, &plan.params)).unzip();
        let (eval_layout, eval) = eval::pipelines(gpu, name, &plan.params);
        let sampler = eval::sampler(gpu);
        let prefix = PrefixSum::new(gpu);
        Pipelines {
            analyze_layout,
            analyze,
            lookup_layout,
            depth_pipeline,
            flat_pipeline,
            occluders,
            split_layout,
            split,
            eval_layout,
            eval,
            sampler,
            prefix,
        }
    }
}
