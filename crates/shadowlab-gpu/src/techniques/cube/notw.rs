//! `cube-notw`: NoTW per cube face (seed 002 chapter 5.3, "CubeSM w/ warping"). Each face is
//! a 90 degree square perspective frustum, i.e. a spot light along the face axis, and is handled
//! by one `warp::Warped` (notw's passes, unchanged) drawing into its layer of shared array
//! textures (`warp::Layers`): one pass reduces every face's desired view from the view samples
//! on it (the same face rule as `cube`, eval_notw.wgsl), one counts them into the faces' count
//! maps (after each face's occluder map, `edge_importance`), one dispatch a step builds every
//! face's row and column warps from its count map, one subdivision cuts every face's triangles
//! (the faces' clipped triangles are one scene, a range a face: warp::LayerSubdivision), each
//! face's warped depth map draws its pieces, and one evaluation over the view reads each
//! sample's face. Nothing is read back during the frame: a face without view samples keeps its
//! warps and draws no pieces (the subdivision reads the count on the GPU), and the report reads
//! the counts after the frame.
//! `warp::fit`'s spot frustum adds one texel of margin on each side, so biased samples next to
//! an edge stay inside their face's map. Stored depth: as notw (post-projective per face).

use shadowlab_core::light::Light;
use shadowlab_core::metrics::sampling_stats;
use shadowlab_core::techniques::cube::FACES;

use super::{clip, point_position, CubeNotwSettings, FACES_WGSL};
use crate::frame::LightUniform;
use crate::record::Recorder;
use crate::scene_gpu::GpuScene;
use crate::technique::{FrameInputs, Technique, TechniqueReport};
use crate::techniques::warp::{self, Knobs, LayerPasses, LayerSubdivision, Layers, Warped};
use crate::{Gpu, GpuError};

const EVAL_NOTW_WGSL: &str = include_str!("eval_notw.wgsl");

/// The desired views, the count maps, the warps and the evaluation of every face
/// (warp/dv_layers.wgsl, warp/count_layers.wgsl, warp/analyze_layers.wgsl and
/// warp/eval_layers.wgsl, a face a layer: eval_notw.wgsl).
pub(super) fn layer_sources() -> [String; 4] {
    [
        warp::layered_dv_source(FACES_WGSL, EVAL_NOTW_WGSL),
        warp::layered_count_source(FACES_WGSL, EVAL_NOTW_WGSL),
        warp::layered_analysis_source(6),
        warp::layered_eval_source(FACES_WGSL, EVAL_NOTW_WGSL),
    ]
}

/// The names of the images of a face's `Warped` report that `cube-notw` passes on.
const FACE_IMAGES: &[&str] = &["count map before warping", "count map after warping", "warped shadow map", "row warping", "column warping"];

struct Face {
    warped: Warped,
    light: Light,
    light_buf: wgpu::Buffer,
}

pub struct CubeNotw {
    res: u32,
    /// Every face's triangles clipped to its frustum (clip.rs), face f's below `ends[f]`.
    scene: GpuScene,
    ends: [u32; 6],
    faces: Vec<Face>,
    /// Every face's subdivision (none with `subdiv=0`: each face draws its triangles).
    subdivision: Option<LayerSubdivision>,
    /// The faces' warps, maps, occluder maps, DV bounds, count maps and counts, a layer each.
    layers: Layers,
    /// The desired views, the count maps, the warps and the evaluation of every face.
    passes: LayerPasses,
}

impl CubeNotw {
    /// The six faces, each a `notw` map of `p.notw` (its window checked against `res` by
    /// [`CubeNotwSettings`]'s rules).
    pub fn new(gpu: &Gpu, scene: &GpuScene, p: &CubeNotwSettings, light: &Light) -> Result<CubeNotw, GpuError> {
        let position = point_position("cube-notw", light)?;
        let res = p.notw.res;
        gpu.check_size(res, res, "cube face")?;
        let knobs = Knobs::notw(&p.notw);
        // near plane of lightspace::fit's spot frustum; clip a little in front of it and a few
        // texels outside the map's square (fit adds one texel of margin)
        let far = scene.bounds.corners().iter().map(|c| (*c - position).length()).fold(0.0f32, f32::max);
        let near = (far * 1e-3).max(1e-4);
        let (faces_scene, ends) = clip::faces_scene(gpu, scene, position, 2.0 * near, 1.0 + 8.0 / res as f32);
        let subdivides = knobs.subdiv > 0.0;
        let layers = Layers::new(gpu, "cube-notw", &knobs, 6, true, subdivides);
        let mut faces = Vec::with_capacity(6);
        for (f, face) in FACES.iter().enumerate() {
            // one face = a spot light along the axis whose fitted frustum is the face's square
            let light = Light::Spot { position, direction: face.n, cone_deg: 45.0 };
            let mut warped = Warped::new_layer(gpu, &faces_scene, &knobs, &light, &layers, f as u32)?;
            warped.draw_triangles(if f == 0 { 0 } else { ends[f - 1] }..ends[f]);
            let light_buf = gpu.uniform(&format!("cube-notw.light{f}"), &LightUniform::new(&light, scene.eps));
            faces.push(Face { warped, light, light_buf });
        }
        let maps: Vec<&Warped> = faces.iter().map(|f| &f.warped).collect();
        let passes = LayerPasses::new(gpu, "cube-notw", &layers, &maps, FACES_WGSL, EVAL_NOTW_WGSL);
        let subdivision =
            subdivides.then(|| LayerSubdivision::new(gpu, "cube-notw", &layers, &passes, &maps, &faces_scene, &ends)).transpose()?;
        if let Some(s) = &subdivision {
            for (f, face) in faces.iter_mut().enumerate() {
                face.warped.draw_owner_pieces(s.draw(f));
            }
        }
        Ok(CubeNotw { res, scene: faces_scene, ends, faces, subdivision, layers, passes })
    }

    /// View samples per face of the last frame (+x, -x, +y, -y, +z, -z): the sixth words of
    /// the faces' DV bounds, read back.
    pub fn face_samples(&self, gpu: &Gpu) -> [u32; 6] {
        let stride = (self.layers.dv_stride() / 4) as usize;
        let bounds: Vec<u32> = gpu.read_buffer_as(self.layers.dv(), 6 * stride);
        std::array::from_fn(|f| bounds[f * stride + 5])
    }

    /// The `Warped` of face `f` (its warps, count maps and map, for tests and pictures).
    pub fn face(&self, f: usize) -> &Warped {
        &self.faces[f].warped
    }

    /// Runs `step` on every face, with that face's inputs (its scene and light), and records the
    /// stages summed over the faces as `cube-notw.*`.
    pub(super) fn each_face(
        &mut self,
        gpu: &Gpu,
        f: &FrameInputs,
        rec: &mut Recorder,
        step: impl Fn(&mut Warped, &Gpu, &FrameInputs, &mut Recorder) -> Result<(), GpuError>,
    ) -> Result<(), GpuError> {
        let outer = rec.set_rename(Some(("notw.".into(), "cube-notw.".into())));
        let mut result = Ok(());
        for face in self.faces.iter_mut() {
            let fi = FrameInputs {
                scene: &self.scene,
                gbuffer: f.gbuffer,
                light: face.light,
                camera: f.camera,
                prev_camera: f.prev_camera,
                light_buf: &face.light_buf,
                frame: f.frame,
                visibility: f.visibility,
            };
            result = step(&mut face.warped, gpu, &fi, rec);
            if result.is_err() {
                break;
            }
        }
        rec.set_rename(outer);
        result
    }

    /// The faces' warps from the view: every face's desired view (stage `desired_view`), the
    /// occluder maps (`edge_importance`), every face's count map and warps (stage
    /// `importance_map`; faces without samples keep theirs).
    pub(super) fn fit_warps(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        self.passes.reduce_dv(gpu, f, rec, &self.layers);
        self.each_face(gpu, f, rec, |w, gpu, fi, rec| {
            w.draw_occluders(gpu, fi, rec);
            Ok(())
        })?;
        self.passes.count(gpu, f, rec, &self.layers);
        self.passes.analyze(gpu, rec, &self.layers);
        Ok(())
    }

    /// Every face's warped depth map (stage `shadow_map`), after one subdivision of all faces
    /// (stage `subdivide`; with `cull_hidden` after each face's occluder map).
    pub(super) fn draw_maps(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        if self.subdivision.is_some() {
            self.each_face(gpu, f, rec, |w, gpu, fi, rec| {
                w.draw_hidden_occluders(gpu, fi, rec);
                Ok(())
            })?;
        }
        if let Some(s) = &self.subdivision {
            s.record(gpu, rec, &self.scene.group);
        }
        self.each_face(gpu, f, rec, |w, gpu, fi, rec| w.render(gpu, fi, rec))
    }

    /// The evaluation of every face in one pass (`final_pass`); with `counting` the lab's
    /// analysis variant (each face's samples per warped texel, in its slice of the counts).
    pub(super) fn eval_pass(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder, counting: bool) -> Result<(), GpuError> {
        self.passes.record(gpu, f, rec, &self.layers, counting);
        Ok(())
    }

    /// The faces' reports summed (memory, exact-depth fragments) or named per face (samples,
    /// clipped triangles, pieces, sampling fractions, pictures), the subdivision's counters over
    /// all faces, sampling over the six faces.
    pub(super) fn face_report(&mut self, gpu: &Gpu) -> TechniqueReport {
        let n = (self.res * self.res) as usize;
        let mut r = TechniqueReport::default();
        let pieces = self.subdivision.as_ref().map(|s| s.report(gpu, 6 * n, &mut r));
        let mut after = Vec::with_capacity(6 * n);
        let mut active = 0;
        let samples = self.face_samples(gpu);
        for (i, face) in self.faces.iter_mut().enumerate() {
            let name = FACES[i].name;
            r.counters.insert(format!("view_samples_face_{name}"), samples[i] as f64);
            let start = if i == 0 { 0 } else { self.ends[i - 1] };
            r.counters.insert(format!("clipped_triangles_face_{name}"), (self.ends[i] - start) as f64);
            if samples[i] == 0 {
                // no samples: no pieces drawn this frame, nothing to report but its memory
                after.extend(std::iter::repeat_n(0, n));
                r.shadow_data_bytes += n as u64 * 4 + face.warped.warp_bytes() + 32;
                continue;
            }
            active += 1;
            if let Some(p) = &pieces {
                // where the pieces go
                r.counters.insert(format!("subdiv_pieces_face_{name}"), p[i] as f64);
            }
            let fr = face.warped.report(gpu);
            r.shadow_data_bytes += fr.shadow_data_bytes;
            r.degraded.extend(fr.degraded.iter().map(|d| format!("face {name}: {d}")));
            after.extend(face.warped.read_counts_final(gpu));
            for (k, v) in fr.counters {
                if k == "fetches_per_pixel" {
                    r.counters.insert(k, v);
                } else if k == "exact_depth_fragments" {
                    *r.counters.entry(k).or_default() += v;
                } else if k.ends_with("fraction") || k.ends_with("warp") {
                    r.counters.insert(format!("{k}_face_{name}"), v);
                }
            }
            for img in fr.images.into_iter().filter(|img| FACE_IMAGES.iter().any(|p| img.name.starts_with(p))) {
                r.images.push(crate::technique::NamedImage { name: format!("face {name}: {}", img.name), ..img });
            }
        }
        r.counters.insert("faces_rendered".into(), active as f64);
        // the faces' exact-depth fragments (each one inversion of its warp), per texel of the six
        let frags = *r.counters.entry("exact_depth_fragments".into()).or_default();
        r.counters.insert("exact_depth_fragments_per_texel".into(), frags / (6 * n) as f64);
        // every face's buffers, rendered this frame or not, and the subdivision's
        let faces: u64 = self.faces.iter().map(|f| f.warped.scratch_bytes()).sum();
        r.counters.insert("scratch_bytes".into(), (faces + self.subdivision.as_ref().map_or(0, |s| s.bytes())) as f64);
        r.counters.insert("warp_bytes_per_face".into(), 8.0 * n as f64);
        r.counters.insert("warp_bytes".into(), 6.0 * 8.0 * n as f64);
        r.counters.insert("shadow_map_texels".into(), 6.0 * n as f64);
        r.sampling = Some(sampling_stats(&after));
        r
    }
}
