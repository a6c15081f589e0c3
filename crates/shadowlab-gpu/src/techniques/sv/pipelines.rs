//! sv pipelines: the compute passes (gather, facing, edges, evaluation) and the raster passes
//! (depth copy, volumes with two-sided stencil, stencil resolve).

use crate::shaders::compose;
use crate::technique::{compose_view, view_layout};
use crate::{binding, Gpu};

const PARAMS_WGSL: &str = include_str!("params.wgsl");
const SILHOUETTE_WGSL: &str = include_str!("silhouette.wgsl");
const VOLUME_WGSL: &str = include_str!("volume.wgsl");
const RESOLVE_WGSL: &str = include_str!("resolve.wgsl");

/// `params.wgsl` (`SvParams`), then `body`.
fn with_params(body: &str, with_scene: bool) -> String {
    compose(&format!("{PARAMS_WGSL}{body}"), with_scene)
}
const EVAL_WGSL: &str = include_str!("eval.wgsl");
const GATHER_WGSL: &str = include_str!("gather.wgsl");

pub fn shaders() -> Vec<(&'static str, String)> {
    vec![
        ("sv/silhouette.wgsl", with_params(SILHOUETTE_WGSL, true)),
        ("sv/volume.wgsl", with_params(VOLUME_WGSL, true)),
        ("sv/resolve.wgsl", with_params(RESOLVE_WGSL, false)),
        ("sv/eval.wgsl", compose_view(EVAL_WGSL, false)),
        ("sv/gather.wgsl", compose(GATHER_WGSL, true)),
    ]
}

pub struct Pipelines {
    pub sil_layout: wgpu::BindGroupLayout,
    pub facing: wgpu::ComputePipeline,
    pub edges: wgpu::ComputePipeline,
    pub vol_layout: wgpu::BindGroupLayout,
    pub sides: wgpu::RenderPipeline,
    pub caps_ccw: wgpu::RenderPipeline,
    pub caps_cw: wgpu::RenderPipeline,
    /// The same three draws with every fragment passing and no stencil writes, for counting the
    /// volumes' fill with an occlusion query (report only).
    pub fill: [wgpu::RenderPipeline; 3],
    pub resolve_layout: wgpu::BindGroupLayout,
    pub copy_depth: wgpu::RenderPipeline,
    pub lit: wgpu::RenderPipeline,
    pub eval_layout: wgpu::BindGroupLayout,
    pub eval: wgpu::ComputePipeline,
}

/// The format of the lit flag written where the stencil count is 0.
pub const LIT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R8Unorm;

/// z-fail counting: a volume face behind the receiver (depth test fails) counts +1 when it
/// leaves a volume (back face) and -1 when it enters one (front face), wrapping mod 256.
fn zfail_stencil() -> wgpu::StencilState {
    let face = |op| wgpu::StencilFaceState {
        compare: wgpu::CompareFunction::Always,
        fail_op: wgpu::StencilOperation::Keep,
        depth_fail_op: op,
        pass_op: wgpu::StencilOperation::Keep,
    };
    wgpu::StencilState {
        front: face(wgpu::StencilOperation::DecrementWrap),
        back: face(wgpu::StencilOperation::IncrementWrap),
        read_mask: 0xff,
        write_mask: 0xff,
    }
}

fn equal_zero_stencil() -> wgpu::StencilState {
    let face = wgpu::StencilFaceState { compare: wgpu::CompareFunction::Equal, ..wgpu::StencilFaceState::IGNORE };
    wgpu::StencilState { front: face, back: face, read_mask: 0xff, write_mask: 0 }
}

struct RasterDesc<'a> {
    label: &'a str,
    module: &'a wgpu::ShaderModule,
    layout: &'a wgpu::PipelineLayout,
    vs: &'a str,
    fs: Option<&'a str>,
    front_face: wgpu::FrontFace,
    unclipped: bool,
    depth_write: bool,
    depth_compare: wgpu::CompareFunction,
    stencil: wgpu::StencilState,
    color: Option<wgpu::TextureFormat>,
}

fn raster(gpu: &Gpu, depth_format: wgpu::TextureFormat, d: RasterDesc) -> wgpu::RenderPipeline {
    let targets = [d.color.map(wgpu::ColorTargetState::from)];
    gpu.device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(d.label),
        layout: Some(d.layout),
        vertex: wgpu::VertexState { module: d.module, entry_point: Some(d.vs), compilation_options: Default::default(), buffers: &[] },
        primitive: wgpu::PrimitiveState { cull_mode: None, front_face: d.front_face, unclipped_depth: d.unclipped, ..Default::default() },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: depth_format,
            depth_write_enabled: Some(d.depth_write),
            depth_compare: Some(d.depth_compare),
            stencil: d.stencil,
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: d.fs.map(|fs| wgpu::FragmentState {
            module: d.module,
            entry_point: Some(fs),
            compilation_options: Default::default(),
            targets: if d.color.is_some() { &targets } else { &[] },
        }),
        multiview_mask: None,
        cache: None,
    })
}

impl Pipelines {
    pub fn new(gpu: &Gpu, scene_layout: &wgpu::BindGroupLayout, depth_format: wgpu::TextureFormat, unclipped: bool) -> Pipelines {
        use binding::{storage, texture_depth, texture_float, uniform};
        use wgpu::CompareFunction as C;
        let d = &gpu.device;
        let c = wgpu::ShaderStages::COMPUTE;
        let sil_types =
            [uniform(), uniform(), storage(true), storage(true), storage(false), storage(false), storage(false), storage(false)];
        let sil_layout = binding::layout(d, "sv.silhouettes", c, &sil_types);
        let sil_src = with_params(SILHOUETTE_WGSL, true);
        let facing = gpu.compute_pipeline("sv.facing", &sil_src, "facing_main", &[&sil_layout, scene_layout]);
        let edges = gpu.compute_pipeline("sv.edges", &sil_src, "edges_main", &[&sil_layout, scene_layout]);

        let vf = wgpu::ShaderStages::VERTEX_FRAGMENT;
        let vol_layout =
            binding::layout(d, "sv.volumes", vf, &[uniform(), uniform(), uniform(), storage(true), storage(true), storage(true)]);
        let vol_module = gpu.shader("sv.volumes", &with_params(VOLUME_WGSL, true));
        let vol_pl = gpu.pipeline_layout("sv.volumes", &[&vol_layout, scene_layout]);
        let volume = |label, vs, front_face, count_only: bool| {
            raster(
                gpu,
                depth_format,
                RasterDesc {
                    label,
                    module: &vol_module,
                    layout: &vol_pl,
                    vs,
                    fs: None,
                    front_face,
                    unclipped,
                    depth_write: false,
                    depth_compare: if count_only { C::Always } else { C::Less },
                    stencil: if count_only { wgpu::StencilState::default() } else { zfail_stencil() },
                    color: None,
                },
            )
        };
        let sides = volume("sv.sides", "vs_sides", wgpu::FrontFace::Ccw, false);
        let caps_ccw = volume("sv.caps_ccw", "vs_caps_ccw", wgpu::FrontFace::Ccw, false);
        let caps_cw = volume("sv.caps_cw", "vs_caps_cw", wgpu::FrontFace::Cw, false);
        let fill = [
            volume("sv.fill_sides", "vs_sides", wgpu::FrontFace::Ccw, true),
            volume("sv.fill_caps_ccw", "vs_caps_ccw", wgpu::FrontFace::Ccw, true),
            volume("sv.fill_caps_cw", "vs_caps_cw", wgpu::FrontFace::Cw, true),
        ];

        let resolve_layout = binding::layout(d, "sv.resolve", vf, &[texture_depth(), uniform()]);
        let res_module = gpu.shader("sv.resolve", &with_params(RESOLVE_WGSL, false));
        let res_pl = gpu.pipeline_layout("sv.resolve", &[&resolve_layout]);
        let full = |label, fs, depth_write, stencil, color| {
            raster(
                gpu,
                depth_format,
                RasterDesc {
                    label,
                    module: &res_module,
                    layout: &res_pl,
                    vs: "vs_full",
                    fs: Some(fs),
                    front_face: wgpu::FrontFace::Ccw,
                    unclipped: false,
                    depth_write,
                    depth_compare: C::Always,
                    stencil,
                    color,
                },
            )
        };
        let copy_depth = full("sv.copy_depth", "fs_depth", true, wgpu::StencilState::default(), None);
        let lit = full("sv.lit", "fs_lit", false, equal_zero_stencil(), Some(LIT_FORMAT));

        let eval_layout = view_layout(gpu, "sv.eval", &[texture_float()]);
        let eval = gpu.compute_pipeline("sv.eval", &compose_view(EVAL_WGSL, false), "main", &[&eval_layout]);
        Pipelines {
            sil_layout,
            facing,
            edges,
            vol_layout,
            sides,
            caps_ccw,
            caps_cw,
            fill,
            resolve_layout,
            copy_depth,
            lit,
            eval_layout,
            eval,
        }
    }

    /// The scene's vertex positions (xyz) read back for the edge list.
    pub fn gather_positions(gpu: &Gpu, scene: &crate::scene_gpu::GpuScene) -> Vec<[f32; 3]> {
        let n = scene.triangle_count as u64 * 3;
        let out = gpu.storage("sv.gather", n * 16);
        let layout = binding::layout(&gpu.device, "sv.gather", wgpu::ShaderStages::COMPUTE, &[binding::storage(false)]);
        let group = binding::group(gpu, "sv.gather", &layout, &[out.as_entire_binding()]);
        let pipe = gpu.compute_pipeline("sv.gather", &compose(GATHER_WGSL, true), "main", &[&layout, &scene.layout]);
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        dispatch_1d(gpu, &mut enc, "sv.gather", &pipe, &[&group, &scene.group], n as u32);
        gpu.submit(enc.finish());
        let p: Vec<[f32; 4]> = gpu.read_buffer_as(&out, n as usize);
        p.into_iter().map(|v| [v[0], v[1], v[2]]).collect()
    }
}

/// One thread per item in groups of 64, spread over y beyond 65535 groups (the shaders fold
/// the index back with `num_workgroups`).
pub fn dispatch_1d(
    gpu: &Gpu,
    enc: &mut wgpu::CommandEncoder,
    label: &str,
    pipe: &wgpu::ComputePipeline,
    groups: &[&wgpu::BindGroup],
    n: u32,
) {
    if n == 0 {
        return;
    }
    let g = n.div_ceil(64);
    let x = g.min(65535);
    let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(label), timestamp_writes: None });
    pass.set_pipeline(pipe);
    for (i, b) in groups.iter().enumerate() {
        pass.set_bind_group(i as u32, *b, &[]);
    }
    gpu.dispatch(&mut pass, [x, g.div_ceil(x), 1]);
}
