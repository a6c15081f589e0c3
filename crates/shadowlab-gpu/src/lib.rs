//! shadowlab-gpu: the wgpu side of shadowlab.
//!
//! Data flows one way: [`scene_gpu::GpuScene`] (buffers, BVH) -> [`gbuffer`] (position, normal,
//! albedo, motion, evaluation mask) -> a [`technique::Technique`], one of
//! [`registry::REGISTRY`] (its shadow data, then a visibility buffer) -> [`reference`] `rt`
//! visibility on the same samples -> [`shade`].
//! [`lab::Lab`] runs that flow for one view and hands back what metrics and reports need.

pub mod alloc;
pub mod binding;
pub mod blur;
pub mod context;
pub mod frame;
pub mod gbuffer;
pub mod host;
pub mod lab;
pub mod prefix_sum;
pub mod quirks;
pub mod raster;
pub mod record;
pub mod reduce;
pub mod reference;
pub mod registry;
pub mod scene_gpu;
pub mod shade;
pub mod shaders;
pub mod technique;
pub mod techniques;
pub mod timing;
#[cfg(target_arch = "wasm32")]
pub mod web;

pub use context::{Gpu, GpuError};
