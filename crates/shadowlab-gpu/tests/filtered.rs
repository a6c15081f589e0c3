//! GPU tests of the filterable shadow maps (`vsm`, `esm`, `evsm`, `msm`, with and without
//! `sd`) against the `rt` reference.

use shadowlab_core::builtin::builtin;
use shadowlab_core::metrics::compare;
use shadowlab_core::params::TechniqueSpec;
use shadowlab_gpu::lab::{Lab, Run};

use crate::common::*;

fn run(lab: &Lab, v: &shadowlab_gpu::lab::View, spec: &str) -> Run {
    lab.run(v, &TechniqueSpec::parse(spec).unwrap(), 1).unwrap_or_else(|e| panic!("{spec}: {e}"))
}

fn fractional(r: &Run, mask: &[u32]) -> usize {
    r.visibility.iter().zip(mask).filter(|(x, m)| **m != 0 && **x > 0.01 && **x < 0.99).count()
}

/// A box on a plane has an exact shadow. At 2048^2 the 2x2 filter region is a few millimetres,
/// so every representation must agree with `rt` except within a texel or two of the edge.
#[test]
fn filtered_maps_at_high_resolution_match_rt_on_planebox() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("planebox").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 0, 256);
    let rt = lab.reference(&v, 1).unwrap();
    for (name, bytes_per_texel) in [("vsm", 8), ("esm", 4), ("evsm", 16), ("msm", 16)] {
        let r = run(&lab, &v, &format!("{name}:res=2048"));
        let a = agreement(&r.visibility, &rt.visibility, &v.mask);
        eprintln!("{name} 2048 on planebox: {a:.3}% agreement");
        if a < THRESHOLD_PLANEBOX {
            panic!("{name} 2048 agrees with rt on {a:.3}%; {}", save_images(&format!("{name}-planebox"), &v, &r, &rt));
        }
        assert_eq!(r.report.shadow_data_bytes, 2048 * 2048 * bytes_per_texel, "{name}");
        assert_eq!(r.report.counters["fetches_per_pixel"], 4.0);
        let s = r.report.sampling.as_ref().unwrap();
        assert!(s.used_texel_fraction > 0.0 && s.samples_per_used_texel_mean >= 1.0);
        assert_eq!(r.report.images.len(), 2);
    }
}
/// A correct implementation gives 99.99 % here (the few remaining pixels sit on the shadow's
/// outline); 99.9 % still catches a one-texel shift of the map or a wrong depth convention.
const THRESHOLD_PLANEBOX: f64 = 99.9;

const LEAK_MIN_PCT: f64 = 0.3;

/// Seed 004 figure 2: on `foliage` the lamp's cables in front of the lamp (one occluder in
/// front of another) make VSM leak light into the shadow; plain shadow mapping at the same
/// resolution does not leak there, and at high resolution (near) never.
#[test]
fn vsm_leaks_on_foliage_where_sm_does_not() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("foliage").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 0, 256);
    let rt = lab.reference(&v, 1).unwrap();
    let m = |r: &Run| compare(&r.visibility, &rt.visibility, &v.mask);
    // sm without bias or normal offset (like vsm's defaults): its false-lit pixels are only
    // occluders too thin for the map, never offsets
    let (vsm_run, sm_run) = (run(&lab, &v, "vsm"), run(&lab, &v, "sm:bias=0,normal_offset=0"));
    let (vsm, sm, sm_hi) = (m(&vsm_run), m(&sm_run), m(&run(&lab, &v, "sm:res=4096")));
    // leaks of the upper bound itself: lit for one, shadowed for rt and for the other on the
    // same 512^2 map (thin cables and fence wires that both miss cancel out)
    let only = |a: &Run, b: &Run| {
        let n = (0..v.mask.len())
            .filter(|&i| v.mask[i] != 0 && rt.visibility[i] < 0.5 && a.visibility[i] >= 0.5 && b.visibility[i] < 0.5)
            .count();
        100.0 * n as f64 / vsm.evaluated_pixels as f64
    };
    let (vsm_leaks, sm_leaks) = (only(&vsm_run, &sm_run), only(&sm_run, &vsm_run));
    eprintln!(
        "false-lit %: vsm {:.3}, sm {:.3}, sm 4096 {:.3}; vsm-only leaks {vsm_leaks:.3} %, sm-only {sm_leaks:.3} %",
        vsm.false_lit_pct, sm.false_lit_pct, sm_hi.false_lit_pct
    );
    assert!(vsm_leaks > LEAK_MIN_PCT && vsm_leaks > 3.0 * sm_leaks, "vsm {vsm:?} sm {sm:?}");
    assert!(vsm.false_lit_pct > sm.false_lit_pct, "vsm {vsm:?} sm {sm:?}");
    assert!(sm_hi.false_lit_pct < 0.25 * vsm.false_lit_pct, "sm 4096 {sm_hi:?}");
}

/// The single-depth variants (gather 2x2, convert, interpolate) compute the same bilinear
/// moments as the full maps without blur; only the f32 rounding of the stored moments differs.
#[test]
fn single_depth_variants_agree_with_full_maps() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("courtyard").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 0, 256);
    for name in ["vsm", "esm", "evsm", "msm"] {
        let full = run(&lab, &v, &format!("{name}:blur=1"));
        let sd = run(&lab, &v, &format!("{name}:sd=true"));
        let m = compare(&sd.visibility, &full.visibility, &v.mask);
        assert!(100.0 - m.wrong_pct >= 99.9 && m.mae < 2e-3, "{name}: sd vs full {m:?}");
        assert_eq!(sd.report.shadow_data_bytes, 512 * 512 * 4);
        assert_eq!(sd.report.counters["texture_instructions_per_pixel"], 1.0);
        assert_eq!(sd.report.counters["bytes_read_per_pixel"], 16.0);
    }
}

/// Pre-filtering keeps the shadow right but softens its edge: blur=5 agrees with `rt` as well
/// as blur=1 (within a point), and has more fractional pixels.
#[test]
fn blur_softens_edges_and_keeps_the_shadow() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("planebox").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 0, 256);
    let rt = lab.reference(&v, 1).unwrap();
    for name in ["vsm", "evsm"] {
        let b1 = run(&lab, &v, &format!("{name}:res=1024,blur=1"));
        let b5 = run(&lab, &v, &format!("{name}:res=1024,blur=5"));
        let (a1, a5) = (agreement(&b1.visibility, &rt.visibility, &v.mask), agreement(&b5.visibility, &rt.visibility, &v.mask));
        assert!(a1 >= 98.0 && a5 >= 98.0, "{name}: blur 1 {a1:.3}%, blur 5 {a5:.3}%");
        let (f1, f5) = (fractional(&b1, &v.mask), fractional(&b5, &v.mask));
        assert!(f5 > f1 && f1 > 0, "{name}: fractional pixels blur 1 {f1}, blur 5 {f5}");
        assert_eq!(b5.report.counters["blur_width"], 5.0);
        assert!(b5.report.counters["blur_scratch_bytes"] > 0.0);
    }
}

#[test]
fn bad_filtered_requests_are_errors() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("room").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 0, 32);
    let e = lab.run(&v, &TechniqueSpec::parse("vsm:blur=4").unwrap(), 1).err().expect("even blur must fail");
    assert!(e.to_string().contains("odd"), "{e}");
    assert!(lab.run(&v, &TechniqueSpec::parse("esm:c_pos=3").unwrap(), 1).is_err());
    assert!(lab.run(&v, &TechniqueSpec::parse("esm:c=100").unwrap(), 1).is_err());
    let v = view(&lab, &scene, 1, 32); // point light
    let e = lab.run(&v, &TechniqueSpec::parse("msm").unwrap(), 1).err().expect("point light must fail");
    assert!(e.to_string().contains("point"), "{e}");
}

/// `mips=true`: the chain costs exactly 4/3 of the map (down to 1x1), the lookup reads 2x2 on
/// two levels, and where a pixel covers several texels the coarser level softens the edge
/// while the shadow stays right.
#[test]
fn mips_read_trilinearly_and_keep_the_shadow() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("planebox").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 0, 256);
    let rt = lab.reference(&v, 1).unwrap();
    for name in ["vsm", "msm"] {
        let plain = run(&lab, &v, &format!("{name}:res=1024"));
        let mips = run(&lab, &v, &format!("{name}:res=1024,mips=true"));
        let a = agreement(&mips.visibility, &rt.visibility, &v.mask);
        assert!(a >= 98.0, "{name} mips agrees with rt on {a:.3}%");
        let bpt = plain.report.counters["bytes_per_texel"] as u64;
        let chain: u64 = (0..11).map(|l| (1024u64 >> l).pow(2) * bpt).sum();
        assert_eq!(mips.report.shadow_data_bytes, chain);
        assert_eq!(mips.report.counters["mip_levels"], 11.0);
        assert_eq!(mips.report.counters["fetches_per_pixel"], 8.0);
        let (f0, f1) = (fractional(&plain, &v.mask), fractional(&mips, &v.mask));
        eprintln!("{name}: fractional pixels {f0} without mips, {f1} with; agreement {a:.3}%");
        assert!(f1 > f0, "{name}: mips did not soften anything ({f0} -> {f1})");
    }
}

/// Spot lights: perspective map, stored depth = view depth / far (linear). Every representation
/// matches `rt` at high resolution on `room`'s spot light.
#[test]
fn spot_light_maps_at_high_resolution_match_rt() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("room").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 0, 128);
    let rt = lab.reference(&v, 1).unwrap();
    for spec in ["vsm:res=2048", "esm:res=2048", "evsm:res=2048", "msm:res=2048", "evsm:res=2048,sd=true"] {
        let r = run(&lab, &v, spec);
        let a = agreement(&r.visibility, &rt.visibility, &v.mask);
        eprintln!("{spec} on room (spot): {a:.3}% agreement");
        if a < 99.5 {
            panic!("{spec} on the spot light agrees with rt on {a:.3}%; {}", save_images("filtered-spot-room", &v, &r, &rt));
        }
    }
}

/// The WGSL of `moments.wgsl` (f32) against `shadowlab_core::techniques::filtered` (f64) on random 2x2
/// regions: both the full form (moments interpolated on the CPU, stored as f32) and the
/// single-depth gather form. Where the depths differ by at least 1e-3 the two must agree
/// closely; with near-equal depths f32 cancellation in `E[z^2] - E[z]^2` dominates (that is what
/// the minimum variance and moment bias are for), so there only the upper-bound property is
/// checked.
const MSM_F32_TOLERANCE: f64 = 0.1;

#[test]
fn wgsl_moment_functions_match_the_cpu_math() {
    use shadowlab_core::techniques::filtered::*;
    use shadowlab_gpu::binding;
    let Some(gpu) = gpu() else { return };
    const KERNEL: &str = r#"
struct Case { m: vec4<f32>, z: vec4<f32>, w: vec4<f32>, d: f32, kind: u32, pad0: u32, pad1: u32 }
@group(0) @binding(0) var<storage, read> cases: array<Case>;
@group(0) @binding(1) var<storage, read_write> out: array<vec2<f32>>;
@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.y * 256u + id.x;
    if i >= arrayLength(&cases) { return; }
    let c = cases[i];
    var r = vec2<f32>(0.0);
    switch c.kind {
        case 0u: { r = vec2<f32>(vsm_visibility(c.m, c.d, 1e-10), vsm_visibility_gather(c.z, c.w, c.d, 1e-10)); }
        case 1u: { r = vec2<f32>(esm_visibility(c.m, c.d, 80.0), esm_visibility_gather(c.z, c.w, c.d, 80.0)); }
        case 2u: { r = vec2<f32>(evsm_visibility(c.m, c.d, 20.0, 5.0, 1e-10), evsm_visibility_gather(c.z, c.w, c.d, 20.0, 5.0, 1e-10)); }
        default: { r = vec2<f32>(msm_visibility(c.m, c.d, 3e-6), msm_visibility_gather(c.z, c.w, c.d, 3e-6)); }
    }
    out[i] = r;
}
"#;
    #[repr(C)]
    #[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
    struct Case {
        m: [f32; 4],
        z: [f32; 4],
        w: [f32; 4],
        d: f32,
        kind: u32,
        pad: [u32; 2],
    }
    let mut seed = 0x2545_F491_4F6C_DD1Du64;
    let mut rnd = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let (mut cases, mut cpu, mut pcfs, mut separated) = (vec![], vec![], vec![], vec![]);
    for i in 0..256 * 64 {
        let kind = (i % 4) as u32;
        let (a, b) = (rnd(), rnd());
        let z: Vec<f64> = (0..4).map(|_| if rnd() < 0.5 { a } else { b } + 1e-3 * (rnd() - 0.5)).map(|x: f64| x.clamp(0.0, 1.0)).collect();
        let (fx, fy) = (rnd(), rnd());
        let w = [(1.0 - fx) * fy, fx * fy, fx * (1.0 - fy), (1.0 - fx) * (1.0 - fy)];
        let d = [rnd(), a + 0.01, b + 0.01, a.max(b) + 0.05][(rnd() * 4.0) as usize].min(1.0);
        let (m, v): ([f64; 4], f64) = match kind {
            0 => {
                let m = filter(&z, &w, vsm_moments);
                ([m[0], m[1], 0.0, 0.0], vsm_visibility(m, d, DEFAULT_MIN_VARIANCE))
            }
            1 => {
                let m = filter(&z, &w, |x| [esm_moment(x, 80.0)]);
                ([m[0], 0.0, 0.0, 0.0], esm_visibility(m[0], d, 80.0))
            }
            2 => {
                let m = filter(&z, &w, |x| evsm_moments(x, 20.0, 5.0));
                (m, evsm_visibility(m, d, 20.0, 5.0, DEFAULT_MIN_VARIANCE))
            }
            _ => {
                let m = filter(&z, &w, msm_moments);
                (m, msm_visibility(m, d, DEFAULT_MOMENT_BIAS))
            }
        };
        let f = |x: &[f64]| [x[0] as f32, x[1] as f32, x[2] as f32, x[3] as f32];
        cases.push(Case { m: f(&m), z: f(&z), w: f(&w), d: d as f32, kind, pad: [0; 2] });
        cpu.push(v);
        pcfs.push(pcf(&z, &w, d));
        separated.push((a - b).abs() > 1e-2);
    }
    let src = format!("{}{KERNEL}", shadowlab_gpu::techniques::filtered::MOMENTS_WGSL);
    let input = gpu.buffer_init("cases", bytemuck::cast_slice(&cases), wgpu::BufferUsages::STORAGE);
    let out = gpu.storage("out", cases.len() as u64 * 8);
    let layout = binding::layout(&gpu.device, "t", wgpu::ShaderStages::COMPUTE, &[binding::storage(true), binding::storage(false)]);
    let group = binding::group(&gpu, "t", &layout, &[input.as_entire_binding(), out.as_entire_binding()]);
    let pipeline = gpu.compute_pipeline("moments-test", &src, "main", &[&layout]);
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    gpu.dispatch_2d(&mut enc, "moments-test", &pipeline, &[&group], 256, 64);
    gpu.queue.submit([enc.finish()]);
    gpu.take_error().unwrap();
    let got: Vec<[f32; 2]> = gpu.read_buffer_as(&out, cases.len());
    for kind in 0..4 {
        let idx: Vec<usize> = (0..cases.len()).filter(|i| cases[*i].kind == kind).collect();
        // MSM: f32 Hankel solves of two-cluster regions are ill-conditioned (the bias of 3e-6 is
        // near the f32 resolution of the 4th moment): wider tolerance, 1 % of cases allowed
        let tol = if kind == 3 { MSM_F32_TOLERANCE } else { 0.01 };
        let (mut far_a, mut far_b, mut n_sep, mut below, mut worst) = (0, 0, 0, 0.0f64, 0.0f64);
        for &i in &idx {
            let [a, b] = got[i];
            below = below.max(pcfs[i] - b as f64);
            if separated[i] {
                n_sep += 1;
                far_a += ((a as f64 - cpu[i]).abs() > tol) as usize;
                far_b += ((b as f64 - cpu[i]).abs() > tol) as usize;
                worst = worst.max((b as f64 - cpu[i]).abs());
            }
        }
        eprintln!(
            "kind {kind}: {far_a}/{n_sep} full and {far_b}/{n_sep} gather off by > {tol}; worst gather {worst:.3}; gather below PCF by {below:.2e} at most"
        );
        // measured (lavapipe): VSM 2, ESM 0, EVSM 0 of ~4000 beyond 0.01; MSM 20 beyond 0.1
        let allowed = if kind == 3 { n_sep / 100 } else { n_sep / 1000 };
        assert!(far_a <= allowed && far_b <= allowed, "kind {kind}: {far_a}, {far_b} of {n_sep} differ from the CPU");
        assert!(below <= 5e-3, "kind {kind}: GPU gather visibility below PCF by {below}");
    }
}
