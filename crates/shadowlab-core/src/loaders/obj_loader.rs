use std::path::Path;
use glam::Mat4;
use super::LoadError;
use crate::scene::Scene;
pub fn load(path: &Path, _m: Mat4) -> Result<Scene, LoadError> { Err(LoadError::invalid(path, "todo")) }
