//! A host renderer using shadowlab as a library: its own device, its own depth/normal pass,
//! `sm` and `lt` recorded into its encoder, one submit per frame, a PNG of the result.
//!
//!     cargo run --release -p shadowlab-gpu --example host_app -- [OUT.png]
//!
//! `tests/host.rs` runs [`run`] headless and checks its visibility against the lab's.

use shadowlab_core::builtin::builtin;
use shadowlab_core::bvh::Bvh;
use shadowlab_core::camera::Camera;
use shadowlab_core::light::Light;
use shadowlab_core::params::TechniqueSpec;
use shadowlab_core::scene::Scene;
use shadowlab_gpu::gbuffer::{MOTION_FORMAT, NORMAL_FORMAT, POSITION_FORMAT};
use shadowlab_gpu::host::HostView;
use shadowlab_gpu::record::Recorder;
use shadowlab_gpu::registry;
use shadowlab_gpu::scene_gpu::GpuScene;
use shadowlab_gpu::technique::run_frame;
use shadowlab_gpu::Gpu;
use wgpu::util::DeviceExt;

/// The host's own G-buffer shader: world position (w = linear depth) and the triangle's normal
/// facing the camera, zero motion (the camera holds still).
const HOST_WGSL: &str = r#"
struct Cam { view_proj: mat4x4<f32>, eye: vec4<f32> }
@group(0) @binding(0) var<uniform> cam: Cam;
struct V { @builtin(position) clip: vec4<f32>, @location(0) world: vec3<f32>, @location(1) @interpolate(flat) n: vec3<f32> }
@vertex fn vs(@location(0) p: vec3<f32>, @location(1) n: vec3<f32>) -> V {
    var o: V;
    o.clip = cam.view_proj * vec4<f32>(p, 1.0);
    o.world = p;
    o.n = n;
    return o;
}
struct G { @location(0) position: vec4<f32>, @location(1) normal: vec4<f32>, @location(2) motion: vec2<f32> }
@fragment fn fs(v: V) -> G {
    var n = v.n;
    if dot(n, cam.eye.xyz - v.world) < 0.0 { n = -n; }
    let c = cam.view_proj * vec4<f32>(v.world, 1.0);
    return G(vec4<f32>(v.world, c.w), vec4<f32>(n, 1.0), vec2<f32>(0.0));
}
"#;

/// What the host produced: per technique (`sm`, `lt`) the visibility of the last frame.
pub struct HostResult {
    pub width: u32,
    pub height: u32,
    pub camera: Camera,
    pub light: Light,
    pub visibility: Vec<(String, Vec<f32>)>,
    /// Submits per frame, counted by `Gpu::submit` (the frame's one, plus the readbacks).
    pub frame_submits: Vec<u64>,
}

/// Opens a device as a host would, with the limits the chosen techniques need.
pub fn open_device() -> Result<Gpu, String> {
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter = pollster::block_on(instance.request_adapter(&Default::default())).map_err(|e| e.to_string())?;
    // lt needs 10 storage buffers per stage (`shadowlab techniques` lists each one's needs); this
    // host's own G-buffer writes 40 bytes per pixel (WebGPU's default allows 32)
    let a = adapter.limits();
    let limits = wgpu::Limits {
        max_storage_buffers_per_shader_stage: a.max_storage_buffers_per_shader_stage.max(10),
        max_color_attachment_bytes_per_sample: a.max_color_attachment_bytes_per_sample,
        ..wgpu::Limits::default()
    };
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        label: Some("host"),
        required_limits: limits,
        ..Default::default()
    }))
    .map_err(|e| e.to_string())?;
    Gpu::from_device(device, queue, adapter.get_info()).map_err(|e| e.to_string())
}

/// The host frame loop: `frames` frames of `scene`'s camera and light 0 at `size` x `size`.
pub fn run(gpu: &Gpu, scene: &Scene, size: u32, frames: usize) -> Result<HostResult, Box<dyn std::error::Error>> {
    let (camera, light) = (scene.camera, scene.lights[0]);
    let bvh = Bvh::build(scene)?;
    let gscene = GpuScene::from_scene(gpu, scene, &bvh)?;
    let view = HostView::new(gpu, &gscene, size, size)?;

    // the host's own geometry and pass
    let verts: Vec<[f32; 6]> = scene
        .vertices
        .chunks_exact(3)
        .flat_map(|t| {
            // the triangle's geometric normal, stored on its vertices
            let n = t[0].normal;
            t.iter().map(move |v| [v.pos[0], v.pos[1], v.pos[2], n[0], n[1], n[2]])
        })
        .collect();
    let vb = gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("host.vertices"),
        contents: bytemuck::cast_slice(&verts),
        usage: wgpu::BufferUsages::VERTEX,
    });
    let mut cam = [0f32; 20];
    cam[..16].copy_from_slice(&camera.view_proj(size, size).to_cols_array());
    cam[16..19].copy_from_slice(&camera.position.to_array());
    let ub = gpu.uniform("host.camera", &cam);
    // the host's own pass, compiled by wgpu as the host would (not through shadowlab's
    // `Gpu::shader`, which adapts uniform buffers to the adapter: shadowlab_gpu::quirks)
    let module = gpu.device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("host.gbuffer"),
        source: wgpu::ShaderSource::Wgsl(HOST_WGSL.into()),
    });
    let layout = gpu.device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("host.camera"),
        entries: &[wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
            ty: wgpu::BindingType::Buffer { ty: wgpu::BufferBindingType::Uniform, has_dynamic_offset: false, min_binding_size: None },
            count: None,
        }],
    });
    let group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("host.camera"),
        layout: &layout,
        entries: &[wgpu::BindGroupEntry { binding: 0, resource: ub.as_entire_binding() }],
    });
    let attrs = wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3];
    let pipeline = gpu.device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("host.gbuffer"),
        layout: Some(&gpu.pipeline_layout("host.gbuffer", &[&layout])),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs"),
            compilation_options: Default::default(),
            buffers: &[Some(wgpu::VertexBufferLayout { array_stride: 24, step_mode: wgpu::VertexStepMode::Vertex, attributes: &attrs })],
        },
        primitive: Default::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: shadowlab_gpu::raster::DEPTH_FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Less),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs"),
            compilation_options: Default::default(),
            targets: &[Some(POSITION_FORMAT.into()), Some(NORMAL_FORMAT.into()), Some(MOTION_FORMAT.into())],
        }),
        multiview_mask: None,
        cache: None,
    });

    // the techniques, through the registry, each with its own visibility buffer
    let mut techs = Vec::new();
    for name in ["sm", "lt"] {
        let spec = registry::resolve(&TechniqueSpec::parse(name)?, Some(&light))?;
        let vis = gpu.storage(&format!("host.visibility.{name}"), size as u64 * size as u64 * 4);
        techs.push((name.to_string(), spec.info.create(gpu, &gscene, &spec.values, &light)?, vis));
    }

    let g = &view.gbuffer;
    let targets: Vec<wgpu::TextureView> = [&g.position, &g.normal, &g.motion].iter().map(|t| t.create_view(&Default::default())).collect();
    let depth = g.depth.create_view(&Default::default());
    let mut frame_submits = Vec::new();
    for _ in 0..frames {
        let before = gpu.submit_count();
        let mut enc = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("host.frame") });
        {
            let color = |v| {
                Some(wgpu::RenderPassColorAttachment {
                    view: v,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT), store: wgpu::StoreOp::Store },
                })
            };
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("host.gbuffer"),
                color_attachments: &[color(&targets[0]), color(&targets[1]), color(&targets[2])],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &depth,
                    depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Store }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(0, &group, &[]);
            pass.set_vertex_buffer(0, vb.slice(..));
            pass.draw(0..verts.len() as u32, 0..1);
        }
        let mut rec = Recorder::new(gpu, &mut enc);
        view.record_view(gpu, &mut rec, &camera, &camera, &light)?;
        for (_, t, vis) in &mut techs {
            run_frame(t.as_mut(), gpu, &view.inputs(&gscene, camera, camera, light, vis), &mut rec)?;
        }
        rec.finish();
        gpu.submit(enc.finish());
        frame_submits.push(gpu.submit_count() - before);
        gpu.take_error()?;
    }
    let visibility = techs.iter().map(|(name, _, vis)| (name.clone(), gpu.read_buffer_as::<f32>(vis, (size * size) as usize))).collect();
    Ok(HostResult { width: size, height: size, camera, light, visibility, frame_submits })
}

#[allow(dead_code)]
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args().nth(1).unwrap_or_else(|| "host_app.png".into());
    let gpu = open_device()?;
    let scene = builtin("courtyard").ok_or("no built-in courtyard")?;
    let r = run(&gpu, &scene, 512, 4)?;
    // sm on the left half, lt on the right, as grey visibility
    let (w, h) = (r.width as usize, r.height as usize);
    let mut rgba = vec![0u8; w * h * 4];
    for y in 0..h {
        for x in 0..w {
            let v = if x < w / 2 { &r.visibility[0].1 } else { &r.visibility[1].1 };
            let g = (v[y * w + x].clamp(0.0, 1.0) * 255.0) as u8;
            rgba[(y * w + x) * 4..][..4].copy_from_slice(&[g, g, g, 255]);
        }
    }
    image::save_buffer(&out, &rgba, w as u32, h as u32, image::ExtendedColorType::Rgba8)?;
    println!("{out}: sm | lt visibility, {} frames, submits per frame {:?}", r.frame_submits.len(), r.frame_submits);
    Ok(())
}
