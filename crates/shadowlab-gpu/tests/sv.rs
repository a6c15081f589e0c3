//! `sv` (shadow volumes) against the exact reference `rt`: the seeds' ground truth must agree
//! with ours.

use shadowlab_core::builtin::builtin;
use shadowlab_core::metrics::compare;
use shadowlab_core::params::TechniqueSpec;
use shadowlab_gpu::lab::Lab;

use crate::common::*;

#[test]
fn sv_agrees_with_rt_on_every_opaque_builtin_scene_and_light() {
    let Some(gpu) = gpu() else { return };
    let spec = TechniqueSpec::parse("sv").unwrap();
    for name in ["courtyard", "room", "planebox"] {
        let scene = builtin(name).unwrap();
        assert!(!scene.has_cutouts(), "{name} has cut-outs");
        let lab = Lab::new(&gpu, &scene).unwrap();
        for li in 0..scene.lights.len() {
            let v = view(&lab, &scene, li, 256);
            let rt = lab.reference(&v, 1).unwrap();
            let sv = lab.run(&v, &spec, 1).unwrap();
            let m = compare(&sv.visibility, &rt.visibility, &v.mask);
            eprintln!(
                "{name} light {li}: agree {:.4}% (false lit {:.4}%, false shadow {:.4}%) {:?}",
                100.0 - m.wrong_pct,
                m.false_lit_pct,
                m.false_shadow_pct,
                sv.report.counters
            );
            let lit = rt.visibility.iter().zip(&v.mask).filter(|(x, m)| **m != 0 && **x > 0.5).count();
            assert!(lit > 0 && (lit as u64) < m.evaluated_pixels, "{name} light {li}: no shadow or no light at all");
            if 100.0 - m.wrong_pct < 99.9 {
                panic!(
                    "{name} light {li}: sv agrees with rt on {:.4}%; {}",
                    100.0 - m.wrong_pct,
                    save_images(&format!("sv-{name}-{li}"), &v, &sv, &rt)
                );
            }
        }
    }
}

/// The GPU's silhouette and side counts equal the CPU's from the same edge list and facings
/// (shadowlab-core `edges`), for a directional, a spot and a point light.
#[test]
fn sv_silhouette_counts_match_the_cpu_edge_list() {
    use shadowlab_core::techniques::sv::{facing, EdgeList};
    let Some(gpu) = gpu() else { return };
    for (name, li) in [("courtyard", 0), ("room", 0), ("room", 1)] {
        let scene = builtin(name).unwrap();
        let lab = Lab::new(&gpu, &scene).unwrap();
        let v = view(&lab, &scene, li, 64);
        let sv = lab.run(&v, &TechniqueSpec::parse("sv").unwrap(), 1).unwrap();
        let pos: Vec<[f32; 3]> = scene.vertices.iter().map(|v| v.pos).collect();
        let list = EdgeList::build(&pos);
        let f: Vec<i32> = (0..scene.triangle_count()).map(|t| facing(scene.triangle(t), &scene.lights[li])).collect();
        let m: Vec<i32> = list.edges.iter().map(|e| list.multiplicity(e, &f)).collect();
        let sil = m.iter().filter(|m| **m != 0).count() as f64;
        let records: i32 = m.iter().map(|m| m.abs()).sum();
        let c = &sv.report.counters;
        assert_eq!(c["edges"], list.edges.len() as f64, "{name}");
        assert_eq!(c["silhouette_edges"], sil, "{name} light {li}");
        assert_eq!(c["side_records"], records as f64, "{name} light {li}");
        let per_record = if li == 0 && name == "courtyard" { 1.0 } else { 2.0 };
        assert_eq!(c["side_triangles"], records as f64 * per_record, "{name} light {li}: indirect vertex count");
        let casting = f.iter().filter(|f| **f != 0).count() as f64;
        assert_eq!(c["cap_triangles"], casting * per_record, "{name} light {li}");
        assert!(sil > 0.0 && sil < list.edges.len() as f64);
        // every pixel with geometry is covered at least by its own triangle's light cap
        let covered = v.position.iter().filter(|p| p[3] > 0.0).count() as f64;
        let fill = c["volume_fragments_per_pixel"] * (64 * 64) as f64;
        assert!(fill >= 0.99 * covered && fill > 0.0, "{name} light {li}: {fill} volume fragments, {covered} covered pixels");
    }
}

/// On foliage `sv` casts the alpha-masked leaves as solid: it matches the CPU reference on a copy
/// of the scene whose cut-outs are solid, and where it differs from `rt` the shadow ray crosses a
/// cut-out texel (rt lit, solid reference shadowed).
#[test]
fn sv_casts_cutouts_as_solid_on_foliage() {
    use shadowlab_core::bvh::{cpu_visibility, Bvh};
    let Some(gpu) = gpu() else { return };
    let scene = builtin("foliage").unwrap();
    assert!(scene.has_cutouts());
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 0, 256);
    let rt = lab.reference(&v, 1).unwrap();
    let sv = lab.run(&v, &TechniqueSpec::parse("sv").unwrap(), 1).unwrap();
    let mut solid = scene.clone();
    for m in &mut solid.materials {
        m.alpha_cutoff = None;
    }
    let bvh = Bvh::build(&solid).unwrap();
    let solid_ref = cpu_visibility(&bvh, &solid, &scene.lights[0], &v.position, &v.normal, &v.mask, lab.gscene.eps);
    let a = agreement(&sv.visibility, &solid_ref, &v.mask);
    assert!(a >= 99.9, "sv agrees with the solid-cut-out reference on {a:.4}%");
    let m = compare(&sv.visibility, &rt.visibility, &v.mask);
    eprintln!("foliage: sv vs rt {:.3}% wrong ({:.3}% false shadow); vs solid reference {a:.4}% agree", m.wrong_pct, m.false_shadow_pct);
    assert!(m.false_shadow_pct > 0.5, "the leaves' holes should make sv darker than rt");
    // every sv/rt difference is a cut-out difference (up to the 0.1% the agreement allows)
    let (mut diff, mut explained) = (0, 0);
    for (i, s) in solid_ref.iter().enumerate() {
        if v.mask[i] != 0 && (sv.visibility[i] >= 0.5) != (rt.visibility[i] >= 0.5) {
            diff += 1;
            explained += ((rt.visibility[i] >= 0.5) && *s < 0.5) as u32;
        }
    }
    assert!(explained as f64 >= 0.98 * diff as f64, "{explained} of {diff} differences explained by cut-outs");
    let masked = scene.vertices.chunks_exact(3).filter(|t| scene.materials[t[0].material as usize].alpha_cutoff.is_some()).count();
    assert_eq!(sv.report.counters["cutout_triangles"], masked as f64);
    assert!(masked > 0);
}

/// Finite extrusion (far = 1.5 scene diagonals, inside the camera's far plane on planebox) gives
/// the same shadows as infinite extrusion; the exact depth copy (depth_offset=0) too.
#[test]
fn sv_finite_extrusion_and_depth_offset_agree_with_rt() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("planebox").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 0, 256);
    let rt = lab.reference(&v, 1).unwrap();
    for spec in ["sv:far=1.5", "sv:depth_offset=0"] {
        let sv = lab.run(&v, &TechniqueSpec::parse(spec).unwrap(), 1).unwrap();
        let a = agreement(&sv.visibility, &rt.visibility, &v.mask);
        assert!(a >= 99.9, "{spec}: {a:.4}%");
    }
    let sv = lab.run(&v, &TechniqueSpec::parse("sv:far=1.5").unwrap(), 1).unwrap();
    assert_eq!(sv.report.counters["extrusion_infinite"], 0.0);
    assert!(sv.report.shadow_data_bytes > 256 * 256 * 5);
}

#[test]
fn sv_rejects_a_too_short_extrusion() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("planebox").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 0, 32);
    let err = lab.run(&v, &TechniqueSpec::parse("sv:far=0.5").unwrap(), 1).err().expect("far=0.5 must be rejected");
    assert!(err.to_string().contains("far=0.5"), "{err}");
}

/// z-fail is robust to the camera standing inside a shadow volume (where z-pass counting would
/// be off by one everywhere): planebox with the camera in the box's shadow, for the directional
/// light and for a point light.
#[test]
fn sv_agrees_with_rt_with_the_camera_inside_a_shadow_volume() {
    use glam::Vec3;
    use shadowlab_core::camera::Camera;
    use shadowlab_core::light::Light;
    let Some(gpu) = gpu() else { return };
    let mut scene = builtin("planebox").unwrap();
    let inside_box = Vec3::new(0.3, 0.8, 0.3);
    let lp = Vec3::new(-2.0, 3.0, -1.2);
    scene.lights = vec![Light::Directional { direction: Vec3::new(0.5, -1.0, 0.3) }, Light::Point { position: lp }];
    let lab = Lab::new(&gpu, &scene).unwrap();
    for (li, eye) in [(0, inside_box + 0.5 * Vec3::new(0.5, -1.0, 0.3)), (1, inside_box + 0.15 * (inside_box - lp))] {
        assert!(eye.x > 0.5, "the eye must be outside the box");
        let ray = shadowlab_core::bvh::shadow_ray(&scene.lights[li], eye, Vec3::Y, 0.0);
        assert!(shadowlab_core::bvh::occluded(&lab.bvh, &scene, &ray), "light {li}: the eye must be in shadow");
        let cam = Camera::new(eye, Vec3::new(3.0, 0.0, 1.5), 70.0, 0.02, 50.0);
        let v = lab.view(&cam, &cam, &scene.lights[li], 256, 256).unwrap();
        let rt = lab.reference(&v, 1).unwrap();
        let sv = lab.run(&v, &TechniqueSpec::parse("sv").unwrap(), 1).unwrap();
        let lit = rt.visibility.iter().zip(&v.mask).filter(|(x, m)| **m != 0 && **x > 0.5).count();
        let evaluated = v.mask.iter().filter(|m| **m != 0).count();
        assert!(lit > 1000 && lit + 1000 < evaluated, "light {li}: need both light and shadow in view ({lit} of {evaluated} lit)");
        let a = agreement(&sv.visibility, &rt.visibility, &v.mask);
        if a < 99.9 {
            panic!("light {li}: camera in shadow: sv agrees with rt on {a:.4}%; {}", save_images(&format!("sv-inside-{li}"), &v, &sv, &rt));
        }
    }
}

/// Non-manifold and open geometry on the GPU: three blades sharing one edge (multiplicity up to
/// 3), a single-sided open quad wound away from the light, a closed box, over a floor.
#[test]
fn sv_agrees_with_rt_on_a_fin_and_open_surfaces() {
    use glam::{Vec2, Vec3};
    use shadowlab_core::builtin::MeshBuilder;
    use shadowlab_core::camera::Camera;
    use shadowlab_core::light::Light;
    use shadowlab_core::scene::Material;
    let Some(gpu) = gpu() else { return };
    let mut b = MeshBuilder::default();
    let m = b.material(Material::solid("grey", [0.7, 0.7, 0.7]));
    b.quad(Vec3::new(-6.0, 0.0, 6.0), Vec3::new(12.0, 0.0, 0.0), Vec3::new(0.0, 0.0, -12.0), Vec2::ONE, m);
    let (a, e) = (Vec3::new(-1.0, 1.5, 0.0), Vec3::new(1.0, 1.5, 0.0));
    let uv = [Vec2::ZERO; 3];
    b.tri([a, e, Vec3::new(0.0, 2.5, 0.0)], uv, m);
    b.tri([e, a, Vec3::new(0.0, 2.2, 0.8)], uv, m);
    b.tri([a, e, Vec3::new(0.0, 1.0, -0.9)], uv, m);
    // open quad, wound so its normal points down (away from the lights above)
    b.quad(Vec3::new(2.0, 1.2, -1.0), Vec3::new(0.0, 0.0, 1.5), Vec3::new(1.5, 0.0, 0.0), Vec2::ONE, m);
    b.cuboid(Vec3::new(-3.0, 0.0, -2.0), Vec3::new(-2.2, 0.8, -1.2), m);
    let cam = Camera::new(Vec3::new(2.0, 9.0, 9.0), Vec3::new(0.5, 0.0, 0.5), 55.0, 0.1, 60.0);
    let lights = vec![
        Light::Directional { direction: Vec3::new(0.3, -1.0, 0.2) },
        Light::Point { position: Vec3::new(-1.0, 5.0, -1.5) },
        Light::Spot { position: Vec3::new(1.0, 6.0, 2.0), direction: Vec3::new(-0.1, -1.0, -0.3), cone_deg: 50.0 },
    ];
    let scene = b.finish("fin", cam, lights, vec![]);
    let lab = Lab::new(&gpu, &scene).unwrap();
    for li in 0..scene.lights.len() {
        let v = view(&lab, &scene, li, 256);
        let rt = lab.reference(&v, 1).unwrap();
        let sv = lab.run(&v, &TechniqueSpec::parse("sv").unwrap(), 1).unwrap();
        let c = &sv.report.counters;
        assert_eq!((c["edges_nonmanifold"], c["edges_open"] > 0.0), (1.0, true));
        let lit = rt.visibility.iter().zip(&v.mask).filter(|(x, m)| **m != 0 && **x > 0.5).count();
        assert!(lit > 0 && (lit as u64) < compare(&sv.visibility, &rt.visibility, &v.mask).evaluated_pixels);
        let a = agreement(&sv.visibility, &rt.visibility, &v.mask);
        if a < 99.9 {
            panic!("fin light {li}: sv agrees with rt on {a:.4}%; {}", save_images(&format!("sv-fin-{li}"), &v, &sv, &rt));
        }
    }
}
