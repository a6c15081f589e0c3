//! The scene on the GPU: vertex triples, materials, packed texels and the BVH, as one bind
//! group (group 1 of every pass, `scene.wgsl`).
//!
//! Moving objects: triangles `dynamic_first..triangle_count` are rewritten by [`GpuScene::set_time`]
//! (one `write_buffer` of the dynamic vertex range), their vertices at the previous frame go
//! behind all the current ones in the same buffer (the G-buffer's motion vectors: one storage
//! buffer fewer a stage, WebGPU's default limit), and a second BVH over the dynamic triangles
//! only is rebuilt on the CPU (obvhs) and written behind the static one in the same node and
//! index buffers (fixed capacity: the dynamic triangle count never changes). `occluded()` in
//! `reference/trace.wgsl` traverses the static tree from node 0, then the dynamic one from
//! `scene_info.dynamic_root`. Without moving objects nothing of this exists or runs.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use shadowlab_core::bvh::{Bvh, BvhNode};
use shadowlab_core::scene::{Bounds, Scene, Vertex};
use wgpu::BufferUsages;

use crate::{binding, Gpu, GpuError};

/// WGSL `Material` (48 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuMaterial {
    pub base_color: [f32; 4],
    pub tex_offset: u32,
    pub tex_width: u32,
    pub tex_height: u32,
    pub flags: u32,
    pub alpha_cutoff: f32,
    pub _pad: [u32; 3],
}

/// WGSL `SceneInfo` (16 bytes): where the dynamic part starts.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct SceneInfo {
    pub triangle_count: u32,
    /// First dynamic triangle (== triangle_count without moving objects); also the number of
    /// static triangles: the static tree (root node 0) exists when it is > 0.
    pub dynamic_first: u32,
    /// Node index of the dynamic tree's root (== the static tree's node count).
    pub dynamic_root: u32,
    pub _pad: u32,
}

pub const MAT_TEXTURED: u32 = 1;
pub const MAT_MASKED: u32 = 2;
pub const MAT_DOUBLE_SIDED: u32 = 4;

pub struct GpuScene {
    pub vertices: wgpu::Buffer,
    pub layout: wgpu::BindGroupLayout,
    pub group: wgpu::BindGroup,
    pub triangle_count: u32,
    /// Whether any material is alpha-tested (`MAT_MASKED`); without, depth-only passes run
    /// with no fragment stage (the cut-out test could discard nothing).
    pub has_cutouts: bool,
    /// Whether any material is single-sided (its back faces are discarded in the G-buffer).
    pub single_sided: bool,
    /// Triangles `dynamic_first..triangle_count` are dynamic (moved by the scene's animations,
    /// rewritten every frame); `0..dynamic_first` are static. Equal to `triangle_count` for a
    /// scene without moving objects.
    pub dynamic_first: u32,
    pub bounds: Bounds,
    pub eps: f32,
    /// BVH bytes on the GPU: static tree plus the dynamic tree's fixed capacity.
    pub bvh_bytes: usize,
    pub texel_bytes: usize,
    /// `SceneInfo` uniform (binding 5).
    pub info: SceneInfo,
    nodes: wgpu::Buffer,
    prims: wgpu::Buffer,
    materials: wgpu::Buffer,
    texels: wgpu::Buffer,
    static_prims: u32,
    dynamic_node_capacity: usize,
}

impl GpuScene {
    /// Uploads `scene` with `bvh` as the static tree: a BVH over triangles
    /// `0..scene.dynamic_first()` (`Bvh::build_range`; `Bvh::build` when nothing moves). Moving
    /// objects start at t = 0.
    pub fn new(gpu: &Gpu, scene: &Scene, bvh: &Bvh) -> Result<GpuScene, GpuError> {
        let dynamic_first = scene.dynamic_first();
        let tri_count = scene.triangle_count();
        let dyn_tris = tri_count - dynamic_first;
        if bvh.prim_indices.len() != dynamic_first || bvh.prim_indices.iter().any(|&p| p as usize >= dynamic_first) {
            return Err(GpuError::Invalid(format!(
                "GpuScene::new needs the static BVH over triangles 0..{dynamic_first} (got one over {} triangles)",
                bvh.prim_indices.len()
            )));
        }
        let mut texels: Vec<u32> = Vec::new();
        let mut offsets = Vec::new();
        for t in &scene.textures {
            offsets.push(texels.len() as u32);
            texels.extend(t.rgba.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])));
        }
        let materials: Vec<GpuMaterial> = scene
            .materials
            .iter()
            .map(|m| {
                let (off, w, h) = m.texture.map_or((0, 1, 1), |t| {
                    let tex = &scene.textures[t as usize];
                    (offsets[t as usize], tex.width, tex.height)
                });
                let bit = |on: bool, b: u32| if on { b } else { 0 };
                let flags = bit(m.texture.is_some(), MAT_TEXTURED)
                    | bit(m.alpha_cutoff.is_some(), MAT_MASKED)
                    | bit(m.double_sided, MAT_DOUBLE_SIDED);
                GpuMaterial {
                    base_color: m.base_color,
                    tex_offset: off,
                    tex_width: w,
                    tex_height: h,
                    flags,
                    alpha_cutoff: m.alpha_cutoff.unwrap_or(0.0),
                    _pad: [0; 3],
                }
            })
            .collect();
        let max = gpu.limits.max_storage_buffer_binding_size as usize;
        // the current vertices, then the dynamic ones again: their previous frame's (set_time)
        let mut all_vertices = scene.vertices.clone();
        all_vertices.extend_from_slice(&scene.vertices[3 * dynamic_first..]);
        let vbytes = std::mem::size_of_val(all_vertices.as_slice());
        let dynamic_node_capacity = if dyn_tris > 0 { Bvh::max_nodes(dyn_tris) } else { 0 };
        let node_count = bvh.nodes.len() + dynamic_node_capacity;
        for (what, bytes) in [("vertex data", vbytes), ("texture data", texels.len() * 4), ("BVH", node_count * 32)] {
            if bytes > max {
                return Err(GpuError::Invalid(format!("scene {what} is {bytes} bytes, over this device's storage binding limit of {max}")));
            }
        }
        let st = BufferUsages::STORAGE | BufferUsages::COPY_DST;
        let vertices =
            gpu.buffer_init("scene.vertices", bytemuck::cast_slice(&all_vertices), st | BufferUsages::VERTEX | BufferUsages::COPY_SRC);
        let mats = gpu.buffer_init("scene.materials", bytemuck::cast_slice(&materials), st);
        let tex = gpu.buffer_init("scene.texels", bytemuck::cast_slice(&texels), st);
        // static tree first, then room for the dynamic one (written by `set_time`)
        let mut all_nodes = bvh.nodes.clone();
        all_nodes.resize(node_count, BvhNode::default());
        let mut all_prims = bvh.prim_indices.clone();
        all_prims.resize(bvh.prim_indices.len() + dyn_tris, 0);
        let nodes = gpu.buffer_init("scene.bvh_nodes", bytemuck::cast_slice(&all_nodes), st);
        let prims = gpu.buffer_init("scene.prim_indices", bytemuck::cast_slice(&all_prims), st);
        let info = SceneInfo {
            triangle_count: tri_count as u32,
            dynamic_first: dynamic_first as u32,
            dynamic_root: bvh.nodes.len() as u32,
            _pad: 0,
        };
        let info_buf = gpu.uniform("scene.info", &info);
        let vis = wgpu::ShaderStages::VERTEX_FRAGMENT | wgpu::ShaderStages::COMPUTE;
        let mut types = [binding::storage(true); 6];
        types[5] = binding::uniform();
        let layout = binding::layout(&gpu.device, "scene", vis, &types);
        let group = binding::group(
            gpu,
            "scene",
            &layout,
            &[
                vertices.as_entire_binding(),
                mats.as_entire_binding(),
                tex.as_entire_binding(),
                nodes.as_entire_binding(),
                prims.as_entire_binding(),
                info_buf.as_entire_binding(),
            ],
        );
        let g = GpuScene {
            vertices,
            layout,
            group,
            triangle_count: tri_count as u32,
            has_cutouts: scene.has_cutouts(),
            single_sided: scene.materials.iter().any(|m| !m.double_sided),
            dynamic_first: dynamic_first as u32,
            bounds: scene.swept_bounds(),
            eps: scene.ray_epsilon(),
            bvh_bytes: bvh.bytes() + dynamic_node_capacity * std::mem::size_of::<BvhNode>() + dyn_tris * 4,
            texel_bytes: texels.len() * 4,
            info,
            nodes,
            prims,
            materials: mats,
            texels: tex,
            static_prims: bvh.prim_indices.len() as u32,
            dynamic_node_capacity,
        };
        g.set_time(gpu, scene, 0.0, 0.0)?;
        Ok(g)
    }

    /// The scene on the GPU with the BVH its ray tracing needs: `full` (a BVH over the whole
    /// scene) when nothing moves, else one over the static triangles (the moving ones get a
    /// tree of their own each frame). What the lab and a host both use.
    pub fn from_scene(gpu: &Gpu, scene: &Scene, full: &Bvh) -> Result<GpuScene, GpuError> {
        let d = scene.dynamic_first();
        if d == scene.triangle_count() {
            return GpuScene::new(gpu, scene, full);
        }
        let static_bvh = if d == 0 { Bvh::empty() } else { Bvh::build_range(scene, 0..d).map_err(GpuError::Invalid)? };
        GpuScene::new(gpu, scene, &static_bvh)
    }

    /// The current vertices (3 per triangle), read back from the GPU.
    pub fn read_vertices(&self, gpu: &Gpu) -> Vec<Vertex> {
        gpu.read_buffer_as(&self.vertices, self.triangle_count as usize * 3)
    }

    /// A static scene of other triangles (3 vertices each; e.g. this scene's clipped to a
    /// frustum) drawn with this scene's materials and texels. It has no BVH: for raster passes
    /// only, never for ray tracing.
    pub fn with_triangles(&self, gpu: &Gpu, label: &str, triangles: &[Vertex]) -> GpuScene {
        let placeholder = [Vertex::zeroed(); 3];
        let tris = if triangles.is_empty() { &placeholder[..] } else { triangles };
        let count = if triangles.is_empty() { 0 } else { tris.len() as u32 / 3 };
        let st = BufferUsages::STORAGE | BufferUsages::COPY_DST;
        let vertices =
            gpu.buffer_init(&format!("{label}.vertices"), bytemuck::cast_slice(tris), st | BufferUsages::VERTEX | BufferUsages::COPY_SRC);
        let nodes = gpu.buffer_init(&format!("{label}.no_bvh"), bytemuck::cast_slice(&[BvhNode::default()]), st);
        let prims = gpu.storage(&format!("{label}.no_prims"), 16);
        let info = SceneInfo { triangle_count: count, dynamic_first: count, dynamic_root: 0, _pad: 0 };
        let info_buf = gpu.uniform(&format!("{label}.info"), &info);
        let group = binding::group(
            gpu,
            label,
            &self.layout,
            &[
                vertices.as_entire_binding(),
                self.materials.as_entire_binding(),
                self.texels.as_entire_binding(),
                nodes.as_entire_binding(),
                prims.as_entire_binding(),
                info_buf.as_entire_binding(),
            ],
        );
        GpuScene {
            vertices,
            layout: self.layout.clone(),
            group,
            triangle_count: count,
            has_cutouts: self.has_cutouts,
            single_sided: self.single_sided,
            dynamic_first: count,
            bounds: self.bounds,
            eps: self.eps,
            bvh_bytes: 0,
            texel_bytes: self.texel_bytes,
            info,
            nodes,
            prims,
            materials: self.materials.clone(),
            texels: self.texels.clone(),
            static_prims: 0,
            dynamic_node_capacity: 0,
        }
    }

    /// Whether the scene has moving objects.
    pub fn is_animated(&self) -> bool {
        self.dynamic_first < self.triangle_count
    }

    /// Moves the dynamic triangles to time `t` (frames) with their previous positions at
    /// `prev_t` (motion vectors), and rebuilds and uploads the dynamic BVH. Queue writes only:
    /// they take effect with the next submission. Nothing happens without moving objects.
    pub fn set_time(&self, gpu: &Gpu, scene: &Scene, t: f32, prev_t: f32) -> Result<(), GpuError> {
        if !self.is_animated() {
            return Ok(());
        }
        if scene.dynamic_first() != self.dynamic_first as usize || scene.triangle_count() != self.triangle_count as usize {
            return Err(GpuError::Invalid("GpuScene::set_time: not the scene this GpuScene was made from".into()));
        }
        if !(t.is_finite() && prev_t.is_finite()) {
            return Err(GpuError::Invalid(format!("animation time must be finite (t = {t}, previous {prev_t})")));
        }
        let moved = scene.animated_vertices(t);
        let prev = scene.animated_vertices(prev_t);
        let tris: Vec<[Vec3; 3]> = moved.chunks_exact(3).map(|v| [v[0].pos.into(), v[1].pos.into(), v[2].pos.into()]).collect();
        let dynamic = Bvh::from_triangles(&tris, self.dynamic_first).map_err(GpuError::Invalid)?;
        if dynamic.nodes.len() > self.dynamic_node_capacity {
            return Err(GpuError::Invalid(format!(
                "dynamic BVH has {} nodes, over its capacity of {}",
                dynamic.nodes.len(),
                self.dynamic_node_capacity
            )));
        }
        let node_size = std::mem::size_of::<BvhNode>() as u64;
        let q = &gpu.queue;
        let vertex_size = std::mem::size_of::<shadowlab_core::scene::Vertex>() as u64;
        q.write_buffer(&self.vertices, self.dynamic_first as u64 * 3 * vertex_size, bytemuck::cast_slice(&moved));
        // behind every current vertex (scene.wgsl `previous_position`)
        q.write_buffer(&self.vertices, self.triangle_count as u64 * 3 * vertex_size, bytemuck::cast_slice(&prev));
        let nodes = dynamic.relocated_nodes(self.info.dynamic_root, self.static_prims);
        q.write_buffer(&self.nodes, self.info.dynamic_root as u64 * node_size, bytemuck::cast_slice(&nodes));
        q.write_buffer(&self.prims, self.static_prims as u64 * 4, bytemuck::cast_slice(&dynamic.prim_indices));
        Ok(())
    }
}
