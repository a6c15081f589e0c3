//! Moving objects ("animations"): rigid motions of selected triangles over time.
//!
//! Time unit: **frames**. `t` is the frame index of a `compare --frames N` sequence (frame `k` is at
//! `t = start + k`, `start` = `--time`, default 0); periods are in frames. Every motion is the
//! identity at `t = 0`, so `Scene::vertices` always holds the pose at `t = 0` and a scene without
//! animations, or any scene at `t = 0`, is exactly the geometry that was loaded.
//!
//! Selection happens once, on load ([`apply`]): the selected triangles are moved to the end of
//! `Scene::vertices`, each animation's triangles contiguous, so that the dynamic triangles form
//! the range `dynamic_first..triangle_count` that the GPU rewrites every frame (and the range
//! `GpuScene::dynamic_first` promises to techniques that keep a static and a dynamic shadow map).
//! Static triangles keep their relative order.

use glam::{Mat4, Vec3};

pub use crate::motion::{Animation, Motion};
use serde::{Deserialize, Serialize};

use crate::scene::{Bounds, Scene, Vertex};

/// One `[[animations]]` entry of a setup (or of a built-in scene): which triangles move, and how.
/// A triangle is selected when its material is one of `materials` (if given) and its centroid
/// lies inside `inside = [[min], [max]]` (if given); at least one of the two is required.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AnimationSpec {
    pub name: String,
    #[serde(default)]
    pub materials: Vec<String>,
    #[serde(default)]
    pub inside: Option<[Vec3; 2]>,
    pub motion: Motion,
}

impl AnimationSpec {
    /// Checks what can be checked without the scene.
    pub fn validate(&self) -> Result<(), String> {
        let who = format!("animation '{}'", self.name);
        if self.name.trim().is_empty() {
            return Err("an animation needs a non-empty `name`".into());
        }
        if self.materials.is_empty() && self.inside.is_none() {
            return Err(format!("{who}: select triangles with `materials` and/or `inside`"));
        }
        if let Some([lo, hi]) = self.inside {
            if !(lo.is_finite() && hi.is_finite() && lo.cmple(hi).all()) {
                return Err(format!("{who}: `inside` needs finite [min, max] with min <= max"));
            }
        }
        self.motion.validate().map_err(|e| format!("{who}: {e}"))
    }
}

/// Selects the triangles of `specs`, moves them to the end of `scene.vertices` (after the
/// scene's existing animations) and records them in `scene.animations`. Errors: invalid spec,
/// unknown material, empty selection, duplicate name, or a triangle selected twice.
pub fn apply(scene: &mut Scene, specs: &[AnimationSpec]) -> Result<(), String> {
    if specs.is_empty() {
        return Ok(());
    }
    let n = scene.triangle_count();
    // owner[i] = index into `all` of the animation moving triangle i
    let mut owner: Vec<Option<usize>> = vec![None; n];
    let mut all: Vec<(String, Motion)> = Vec::new();
    for a in &scene.animations {
        owner[a.first..a.first + a.count].iter_mut().for_each(|o| *o = Some(all.len()));
        all.push((a.name.clone(), a.motion));
    }
    for spec in specs {
        spec.validate()?;
        let who = format!("animation '{}'", spec.name);
        if all.iter().any(|(name, _)| *name == spec.name) {
            return Err(format!("{who}: the name is used twice"));
        }
        let mut mats = Vec::new();
        for m in &spec.materials {
            let found: Vec<u32> = (0..scene.materials.len() as u32).filter(|&i| scene.materials[i as usize].name == *m).collect();
            if found.is_empty() {
                let mut names: Vec<&str> = scene.materials.iter().map(|m| m.name.as_str()).collect();
                names.sort();
                names.dedup();
                let shown = names.iter().take(40).copied().collect::<Vec<_>>().join("', '");
                return Err(format!("{who}: unknown material '{m}' (the scene has '{shown}')"));
            }
            mats.extend(found);
        }
        let id = all.len();
        let mut selected = 0usize;
        for (i, o) in owner.iter_mut().enumerate() {
            let v = &scene.vertices[3 * i..3 * i + 3];
            if !mats.is_empty() && !mats.contains(&v[0].material) {
                continue;
            }
            if let Some([lo, hi]) = spec.inside {
                let c = (Vec3::from(v[0].pos) + Vec3::from(v[1].pos) + Vec3::from(v[2].pos)) / 3.0;
                if !(c.cmpge(lo).all() && c.cmple(hi).all()) {
                    continue;
                }
            }
            if let Some(other) = *o {
                return Err(format!("{who}: triangle {i} is already moved by animation '{}'", all[other].0));
            }
            *o = Some(id);
            selected += 1;
        }
        if selected == 0 {
            return Err(format!("{who}: selects no triangles (check `materials` and `inside`)"));
        }
        all.push((spec.name.clone(), spec.motion));
    }
    let mut order: Vec<usize> = (0..n).filter(|&i| owner[i].is_none()).collect();
    let mut animations = Vec::new();
    for (id, (name, motion)) in all.into_iter().enumerate() {
        let first = order.len();
        order.extend((0..n).filter(|&i| owner[i] == Some(id)));
        animations.push(Animation { name, first, count: order.len() - first, motion });
    }
    let old = std::mem::take(&mut scene.vertices);
    scene.vertices = order.iter().flat_map(|&i| old[3 * i..3 * i + 3].iter().copied()).collect();
    scene.animations = animations;
    Ok(())
}

/// `v` moved by the rigid transform `m` (position and face normal; a rotation keeps the
/// normal's length, so it is not renormalised and the identity returns `v` bit for bit).
pub fn move_vertex(v: &Vertex, m: &Mat4) -> Vertex {
    if *m == Mat4::IDENTITY {
        return *v;
    }
    let pos = m.transform_point3(Vec3::from(v.pos));
    let normal = m.transform_vector3(Vec3::from(v.normal));
    Vertex { pos: pos.into(), normal: normal.into(), ..*v }
}

/// Conservative world bounds of the triangles `anim` moves over all time: positions sampled
/// over the period, padded by the largest sagitta of the arcs between samples (rotations).
pub fn swept_bounds(scene: &Scene, anim: &Animation) -> Bounds {
    const SAMPLES: usize = 64;
    let mut b = Bounds::EMPTY;
    let verts = &scene.vertices[3 * anim.first..3 * (anim.first + anim.count)];
    let mut max_radius = 0f32;
    let pivot = match anim.motion {
        Motion::Sway { pivot, axis, .. } => Some((pivot, axis.normalize())),
        Motion::Orbit { center, axis, .. } => Some((center, axis.normalize())),
        Motion::Translate { .. } => None,
    };
    for k in 0..=SAMPLES {
        let m = anim.motion.transform(anim.motion.period() * k as f32 / SAMPLES as f32);
        for v in verts {
            b.grow(m.transform_point3(Vec3::from(v.pos)));
        }
    }
    if let Some((p, axis)) = pivot {
        for v in verts {
            let d = Vec3::from(v.pos) - p;
            max_radius = max_radius.max((d - axis * d.dot(axis)).length());
        }
        let step = anim.motion.max_angle_step(SAMPLES);
        let pad = max_radius * (1.0 - (step * 0.5).cos()) + 1e-6;
        b.min -= Vec3::splat(pad);
        b.max += Vec3::splat(pad);
    }
    b
}

/// The scene over time (its moving objects at time `t`, in frames).
impl Scene {
    /// First dynamic (animated) triangle; `triangle_count()` when nothing moves.
    pub fn dynamic_first(&self) -> usize {
        self.animations.iter().map(|a| a.first).min().unwrap_or(self.triangle_count())
    }
    /// The dynamic vertices (`3 * dynamic_first()..`) at time `t` (frames): positions and face
    /// normals moved by each animation's transform. Empty when nothing moves.
    pub fn animated_vertices(&self, t: f32) -> Vec<Vertex> {
        let mut out = Vec::with_capacity(self.vertices.len() - 3 * self.dynamic_first());
        let mut anims: Vec<&Animation> = self.animations.iter().collect();
        anims.sort_by_key(|a| a.first);
        for a in anims {
            let m = a.motion.transform(t);
            out.extend(self.vertices[3 * a.first..3 * (a.first + a.count)].iter().map(|v| move_vertex(v, &m)));
        }
        out
    }
    /// A copy of the scene with the moving objects where they are at time `t` (the CPU
    /// reference of an animated frame: `Bvh::build(&scene.at_time(t))`).
    pub fn at_time(&self, t: f32) -> Scene {
        let mut s = self.clone();
        let first = 3 * self.dynamic_first();
        s.vertices.truncate(first);
        s.vertices.extend(self.animated_vertices(t));
        s
    }
    /// Bounds of the geometry over all time (static bounds grown by every animation's sweep);
    /// equal to `bounds()` without animations.
    pub fn swept_bounds(&self) -> Bounds {
        let mut b = self.bounds();
        for a in &self.animations {
            let s = swept_bounds(self, a);
            b.grow(s.min);
            b.grow(s.max);
        }
        b
    }
}

#[cfg(test)]
#[path = "anim_tests.rs"]
mod tests;
