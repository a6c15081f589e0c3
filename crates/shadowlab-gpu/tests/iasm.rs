//! GPU tests of `iasm` (seed 001 chapter 3).

use glam::Vec2;
use shadowlab_core::builtin::builtin;
use shadowlab_core::params::{ParamSet, TechniqueSpec};
use shadowlab_core::techniques::iasm::{self as core, THESIS_RESOLUTIONS};
use shadowlab_gpu::lab::Lab;
use shadowlab_gpu::registry;
use shadowlab_gpu::techniques::iasm::{Iasm, IasmSettings, IasmStore};

use crate::common::*;

#[test]
fn iasm_buffer_matches_rt_on_planebox_and_memory_is_exact() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("planebox").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 0, 256);
    let rt = lab.reference(&v, 1).unwrap();
    let run = lab.run(&v, &TechniqueSpec::parse("iasm:store=buffer").unwrap(), 1).unwrap();
    let a = agreement(&run.visibility, &rt.visibility, &v.mask);
    if a < 99.0 {
        panic!("iasm agrees with rt on {a:.3}%; {}", save_images("iasm-planebox", &v, &run, &rt));
    }
    assert_eq!(run.report.shadow_data_bytes, 6_860_800);
    let c = &run.report.counters;
    let empty = c["empty_tiles"] as usize;
    let rendered: Vec<f64> = (0..16).map(|t| c[&format!("tile{t:02}.res")]).filter(|r| *r > 0.0).collect();
    assert_eq!(rendered.len() + empty, 16);
    assert!(!rendered.is_empty());
    // the rendered tiles got the top of the set, in rank order
    let mut sorted = rendered.clone();
    sorted.sort_by(|a, b| b.total_cmp(a));
    let want: Vec<f64> = THESIS_RESOLUTIONS[..rendered.len()].iter().map(|r| *r as f64).collect();
    assert_eq!(sorted, want);
    // empty tiles draw nothing; rendered ones draw something
    for t in 0..16 {
        let draws = c[&format!("tile{t:02}.draws")];
        assert_eq!(draws > 0.0, c[&format!("tile{t:02}.res")] > 0.0, "tile {t}");
    }
    assert_eq!(run.report.images.len(), 2);
}

#[test]
fn gpu_texel_index_matches_cpu_equations() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("planebox").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 0, 64);
    let values = registry::resolve(&TechniqueSpec::parse("iasm:store=buffer").unwrap(), Some(&v.light)).unwrap().values;
    let tech = Iasm::new(&gpu, &lab.gscene, &IasmSettings::from_values(&values), &v.light).unwrap();
    // a scrambled assignment
    let order = core::rank(&std::array::from_fn(|i| ((i * 11) % 16) as f64), &[false; 16]);
    let res = core::assign(&order, &THESIS_RESOLUTIONS);
    let off = core::offsets(&res);
    let mut uvs = Vec::new();
    let n = 1999;
    for y in 0..n {
        for x in (0..n).step_by(7) {
            uvs.push(Vec2::new((x as f32 + 0.37) / n as f32, (y as f32 + 0.61) / n as f32));
        }
    }
    uvs.extend([Vec2::ZERO, Vec2::new(0.25, 0.5), Vec2::new(0.999_999, 0.0), Vec2::new(0.5, 0.75)]);
    let got = tech.probe_indices(&gpu, &res, &uvs);
    let mut mismatches = 0;
    for (uv, (idx, tile)) in uvs.iter().zip(&got) {
        let (t, _) = core::tile_of(*uv);
        assert_eq!(*tile as usize, t, "tile of {uv}");
        if *idx != core::texel_index(*uv, &res, &off) {
            mismatches += 1;
        }
    }
    // f32 rounding may move a point on a texel border by one texel; none are expected here
    assert_eq!(mismatches, 0, "{mismatches} of {} indices differ", uvs.len());
}

#[test]
fn delayed_iasm_on_a_still_camera_equals_iasm_after_the_first_frame() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("courtyard").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 0, 256);
    let make = |spec: &str| {
        let shadowlab_gpu::registry::Resolved { info, values: p, .. } =
            registry::resolve(&TechniqueSpec::parse(spec).unwrap(), Some(&v.light)).unwrap();
        lab.instantiate(&shadowlab_gpu::registry::Resolved::new(info, p, spec), &v.light).unwrap()
    };
    let mut now = make("iasm");
    let mut late = make("iasm:delayed=true");
    let mut prev = None;
    for frame in 0..3 {
        let a = lab.step(&v, &mut now, false, 1).unwrap();
        let b = lab.step(&v, &mut late, false, 1).unwrap();
        assert_eq!(a.visibility, b.visibility, "frame {frame}");
        for t in 0..16 {
            let k = format!("tile{t:02}.res");
            assert_eq!(a.report.counters[&k], b.report.counters[&k], "frame {frame} {k}");
        }
        if let Some(p) = prev.replace(a.visibility.clone()) {
            assert_eq!(p, a.visibility, "still camera: frames differ");
        }
    }
}

#[test]
fn atlas_store_matches_buffer_store_and_rt() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("courtyard").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 0, 256);
    let buf = lab.run(&v, &TechniqueSpec::parse("iasm:store=buffer").unwrap(), 1).unwrap();
    let atl = lab.run(&v, &TechniqueSpec::parse("iasm").unwrap(), 1).unwrap();
    assert_eq!(IasmSettings::from_values(&atl.params).store, IasmStore::Atlas, "atlas is the default store");
    // the same tiles, frusta and depths; only where the depth lives differs
    let a = agreement(&atl.visibility, &buf.visibility, &v.mask);
    assert!(a >= 99.9, "atlas and buffer agree on {a:.3}%");
    for t in 0..16 {
        let k = format!("tile{t:02}.res");
        assert_eq!(atl.report.counters[&k], buf.report.counters[&k], "{k}");
    }
    // 2048 x 1024 depth texels (buddy-packed thesis set) against the buffer's exact set
    assert_eq!(atl.report.shadow_data_bytes, 2048 * 1024 * 4);
    assert_eq!(buf.report.shadow_data_bytes, 6_860_800);
    let rt = lab.reference(&v, 1).unwrap();
    let a = agreement(&atl.visibility, &rt.visibility, &v.mask);
    assert!(a >= 99.0, "atlas iasm agrees with rt on {a:.3}% of courtyard");
}

#[test]
fn samples_outside_the_square_are_counted_and_lit() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("planebox").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 0, 128);
    // a 2 m square ahead of the camera cannot hold the whole 10 m plane in view
    let run = lab.run(&v, &TechniqueSpec::parse("iasm:fit=fixed,size=2").unwrap(), 1).unwrap();
    let c = &run.report.counters;
    let inside: f64 = (0..16).map(|t| c[&format!("tile{t:02}.samples")]).sum();
    let evaluated = v.mask.iter().filter(|m| **m != 0).count() as f64;
    assert!(c["outside_samples"] > 0.0);
    assert_eq!(inside + c["outside_samples"], evaluated);
    // the same placement on the CPU: every sample clearly outside it is lit
    let shadowlab_core::light::Light::Directional { direction } = v.light else { panic!() };
    let cam = scene.camera;
    let p = core::place(direction, cam.position, (cam.target - cam.position).normalize(), 2.0, Some(2.0 / 64.0), core::Anchor::Circle);
    let mut outside = 0;
    for (i, pos) in v.position.iter().enumerate() {
        let uv = p.uv(glam::Vec3::from_slice(&pos[..3]));
        if v.mask[i] != 0 && (uv.min_element() < -1e-3 || uv.max_element() > 1.0 + 1e-3) {
            outside += 1;
            assert_eq!(run.visibility[i], 1.0, "pixel {i} outside the square is not lit");
        }
    }
    assert!(outside as f64 <= c["outside_samples"] && outside as f64 > 0.9 * c["outside_samples"]);
}

#[test]
fn analysis_matches_a_cpu_recount_of_samples_and_importance() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("courtyard").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 0, 256);
    let run = lab.run(&v, &TechniqueSpec::parse("iasm:fit=fixed").unwrap(), 1).unwrap();
    let c = &run.report.counters;
    let shadowlab_core::light::Light::Directional { direction } = v.light else { panic!() };
    let cam = scene.camera;
    let fwd = (cam.target - cam.position).normalize();
    let side = c["square_side"] as f32;
    let p = core::place(direction, cam.position, fwd, side, Some(side / 64.0), core::Anchor::Circle);
    let (mut n, mut imp) = ([0u64; 16], [0f64; 16]);
    for (i, pos) in v.position.iter().enumerate() {
        let q = glam::Vec3::from_slice(&pos[..3]);
        let uv = p.uv(q);
        if v.mask[i] == 0 || uv.min_element() < 0.0 || uv.max_element() >= 1.0 {
            continue;
        }
        let t = core::tile_of(uv).0;
        n[t] += 1;
        // equation 3.1 with m = 4, k = half the side (the defaults), in the GPU's 1/64 steps
        imp[t] += (core::importance((q - cam.position).dot(fwd), 4.0, 0.5 * side) as f64 * 64.0).round() / 64.0;
    }
    assert!(n.iter().sum::<u64>() > 10_000);
    for t in 0..16 {
        let (gn, gi) = (c[&format!("tile{t:02}.samples")], c[&format!("tile{t:02}.importance")]);
        // f32 differences may move a sample lying on a tile border: allow 0.5 % of the tile
        let tol = 1.0 + 0.005 * n[t] as f64;
        assert!((gn - n[t] as f64).abs() <= tol, "tile {t}: GPU {gn} samples, CPU {}", n[t]);
        assert!((gi - imp[t]).abs() <= 5.0 * tol, "tile {t}: GPU importance {gi}, CPU {}", imp[t]);
    }
}
