//! Shader composition: every shader is `common.wgsl` + (optionally `scene.wgsl`, and for the
//! depth-only shadow passes `depth.wgsl`) + its own file.
//! [`crate::registry::shaders`] lists every composed shader so a CPU-only test validates each
//! with naga.

pub const COMMON: &str = include_str!("common.wgsl");
pub const SCENE: &str = include_str!("scene.wgsl");
pub const DEPTH: &str = include_str!("depth.wgsl");

/// The value of a boolean WGSL `override` in a pipeline's constants (wgpu takes every constant
/// as an f64).
pub fn flag(b: bool) -> f64 {
    if b {
        1.0
    } else {
        0.0
    }
}

/// `common.wgsl`, then `scene.wgsl` if `with_scene`, then `body`.
pub fn compose(body: &str, with_scene: bool) -> String {
    let mut s = String::from(COMMON);
    if with_scene {
        s.push_str(SCENE);
    }
    s.push_str(body);
    s
}

/// `common.wgsl`, `scene.wgsl`, `depth.wgsl` (vertex fetch and alpha cut-out of a depth-only
/// pass from a light), then `body` (its uniform and entry points).
pub fn compose_depth(body: &str) -> String {
    compose(&format!("{DEPTH}{body}"), true)
}
