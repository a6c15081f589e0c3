//! Rasterising the scene: every raster pass draws the scene's vertex triples (`vs_main` reading
//! `vertices` from `scene.wgsl`, `fs_main`), without culling, into a Depth32Float target with a
//! less-than test. G-buffer and shadow-map passes share this.

use crate::Gpu;

pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// A pipeline drawing the scene with `source`'s `vs_main` / `fs_main` into `targets` + depth.
pub fn scene_pipeline(
    gpu: &Gpu,
    label: &str,
    source: &str,
    layouts: &[&wgpu::BindGroupLayout],
    targets: &[Option<wgpu::ColorTargetState>],
) -> wgpu::RenderPipeline {
    pipeline(gpu, label, source, layouts, targets, true, &[], DEPTH_TEST)
}

/// [`depth_pipeline_with`] with the depth test and writes off: every fragment that its
/// fragment stage keeps passes, for an occlusion query to count them (a report's counter).
pub fn counting_pipeline(
    gpu: &Gpu,
    label: &str,
    source: &str,
    layouts: &[&wgpu::BindGroupLayout],
    constants: &[(&str, f64)],
) -> wgpu::RenderPipeline {
    pipeline(gpu, label, source, layouts, &[], true, constants, (false, wgpu::CompareFunction::Always))
}

/// [`scene_pipeline`] with WGSL `override` constants (both stages: one module).
pub fn scene_pipeline_constants(
    gpu: &Gpu,
    label: &str,
    source: &str,
    layouts: &[&wgpu::BindGroupLayout],
    targets: &[Option<wgpu::ColorTargetState>],
    constants: &[(&str, f64)],
) -> wgpu::RenderPipeline {
    pipeline(gpu, label, source, layouts, targets, true, constants, DEPTH_TEST)
}

/// A depth-only scene pipeline: with a fragment stage (`fs_main`, the alpha cut-out test) only
/// where `scene.has_cutouts`; otherwise none, the same depths without fragment shading (llvmpipe
/// then runs no shader per fragment, as a GL depth pass with an empty fragment shader).
pub fn depth_pipeline(gpu: &Gpu, label: &str, source: &str, layouts: &[&wgpu::BindGroupLayout], has_cutouts: bool) -> wgpu::RenderPipeline {
    pipeline(gpu, label, source, layouts, &[], has_cutouts, &[], DEPTH_TEST)
}

/// A depth-only scene pipeline with a fragment stage where `fragment`, and WGSL `override`
/// constants for both stages.
pub fn depth_pipeline_with(
    gpu: &Gpu,
    label: &str,
    source: &str,
    layouts: &[&wgpu::BindGroupLayout],
    fragment: bool,
    constants: &[(&str, f64)],
) -> wgpu::RenderPipeline {
    pipeline(gpu, label, source, layouts, &[], fragment, constants, DEPTH_TEST)
}

/// The depth test of every scene pass: written, nearer wins.
const DEPTH_TEST: (bool, wgpu::CompareFunction) = (true, wgpu::CompareFunction::Less);

#[allow(clippy::too_many_arguments)]
fn pipeline(
    gpu: &Gpu,
    label: &str,
    source: &str,
    layouts: &[&wgpu::BindGroupLayout],
    targets: &[Option<wgpu::ColorTargetState>],
    fragment: bool,
    constants: &[(&str, f64)],
    (write, compare): (bool, wgpu::CompareFunction),
) -> wgpu::RenderPipeline {
    let module = gpu.shader(label, source);
    let layout = gpu.pipeline_layout(label, layouts);
    gpu.device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(&layout),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs_main"),
            compilation_options: wgpu::PipelineCompilationOptions { constants, ..Default::default() },
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(write),
            depth_compare: Some(compare),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: fragment.then_some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs_main"),
            compilation_options: wgpu::PipelineCompilationOptions { constants, ..Default::default() },
            targets,
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// Begins a render pass that clears `colors` (to transparent) and `depth` (to 1), both stored.
pub fn begin_pass<'e>(
    enc: &'e mut wgpu::CommandEncoder,
    label: &str,
    colors: &[&wgpu::TextureView],
    depth: &wgpu::TextureView,
) -> wgpu::RenderPass<'e> {
    begin_pass_with(enc, label, colors, wgpu::Color::TRANSPARENT, depth, wgpu::StoreOp::Store)
}

/// Begins a render pass that clears `colors` to `clear` and `depth` to 1; `depth_store`
/// `Discard` for passes whose depth only resolves visibility (maps written as colour).
pub fn begin_pass_with<'e>(
    enc: &'e mut wgpu::CommandEncoder,
    label: &str,
    colors: &[&wgpu::TextureView],
    clear: wgpu::Color,
    depth: &wgpu::TextureView,
    depth_store: wgpu::StoreOp,
) -> wgpu::RenderPass<'e> {
    let atts: Vec<Option<wgpu::RenderPassColorAttachment>> = colors
        .iter()
        .map(|v| {
            Some(wgpu::RenderPassColorAttachment {
                view: v,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Clear(clear), store: wgpu::StoreOp::Store },
            })
        })
        .collect();
    enc.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &atts,
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: depth,
            depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: depth_store }),
            stencil_ops: None,
        }),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

/// A `w x h x layers` 2D (array) texture of `format`, one mip level, one sample.
pub fn texture_2d(
    gpu: &Gpu,
    label: &str,
    w: u32,
    h: u32,
    layers: u32,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d { width: w, height: h, depth_or_array_layers: layers },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

/// A `w x h` render target of `format` that later passes sample, plus `extra_usage`.
pub fn render_target(
    gpu: &Gpu,
    label: &str,
    w: u32,
    h: u32,
    format: wgpu::TextureFormat,
    extra_usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    texture_2d(gpu, label, w, h, 1, format, wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING | extra_usage)
}

/// A `w x h x layers` Depth32Float target of the shadow passes: render attachment, sampled
/// (`texture_depth_2d[_array]`) and copyable for the report's pictures, plus `extra_usage`.
pub fn depth_target(gpu: &Gpu, label: &str, w: u32, h: u32, layers: u32, extra_usage: wgpu::TextureUsages) -> wgpu::Texture {
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_SRC | extra_usage;
    texture_2d(gpu, label, w, h, layers, DEPTH_FORMAT, usage)
}

/// The shadow maps' comparison sampler: `LessEqual` against the reference depth, nearest
/// texel (PCF is done with explicit taps), clamped to the edge.
pub fn comparison_sampler(gpu: &Gpu, label: &str) -> wgpu::Sampler {
    gpu.device.create_sampler(&wgpu::SamplerDescriptor {
        label: Some(label),
        compare: Some(wgpu::CompareFunction::LessEqual),
        mag_filter: wgpu::FilterMode::Nearest,
        min_filter: wgpu::FilterMode::Nearest,
        address_mode_u: wgpu::AddressMode::ClampToEdge,
        address_mode_v: wgpu::AddressMode::ClampToEdge,
        ..Default::default()
    })
}
