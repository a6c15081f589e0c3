//! shadowlab-core: the GPU-free half of shadowlab. Scene model, loaders, setup files, cameras,
//! lights, the BVH and its CPU traversal (the reference's cross-check), metrics, technique
//! parameters, and the CPU halves of techniques.

pub mod anim;
pub mod builtin;
pub mod bvh;
pub mod camera;
pub mod flip;
pub mod light;
pub mod lightspace;
pub mod loaders;
pub mod metrics;
pub mod motion;
pub mod params;
pub mod scene;
pub mod setup;
pub mod techniques;
