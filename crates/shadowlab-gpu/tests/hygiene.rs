//! Per-frame hygiene (issue 31): a recorded frame after the first creates no buffer and no bind
//! group. Uploads and readbacks come from the device wrapper's pools (`shadowlab_gpu::alloc`),
//! and every buffer is made through `Gpu::buffer` and counted there; every bind group is made
//! through `Gpu::bind_group`, counted, and kept by `binding::GroupCache` while its resources stay
//! the same objects (views made once with their textures).

use shadowlab_core::builtin::builtin;
use shadowlab_core::params::TechniqueSpec;
use shadowlab_gpu::lab::Lab;
use shadowlab_gpu::{registry, technique};

use crate::common::*;

#[test]
fn no_frame_after_the_first_creates_a_buffer() {
    let Some(gpu) = gpu() else { return };
    let mut offenders = Vec::new();
    let mut checked = 0;
    for (name, light) in [("planebox", 0), ("room", 0), ("room", 1)] {
        let scene = builtin(name).unwrap();
        let lab = Lab::new(&gpu, &scene).unwrap();
        let v = view(&lab, &scene, light, 64);
        let inputs = v.inputs(&lab.gscene);
        for info in registry::REGISTRY.iter().filter(|i| i.lights.contains(&v.light.kind())) {
            let r = registry::resolve(&TechniqueSpec::parse(info.name).unwrap(), Some(&v.light)).unwrap();
            let mut inst = lab.instantiate(&r, &v.light).unwrap();
            let mut created = Vec::new();
            let mut groups = Vec::new();
            for _ in 0..3 {
                let (b0, g0) = (gpu.buffers_created(), gpu.bind_groups_created());
                technique::submit_frame(inst.tech.as_mut(), &gpu, &inputs).unwrap();
                gpu.wait();
                created.push(gpu.buffers_created() - b0);
                groups.push(gpu.bind_groups_created() - g0);
            }
            eprintln!("{} ({name} light {light}): bind groups a frame {groups:?}", info.name);
            gpu.take_error().unwrap();
            // frame 1 may fill the pools; frames 2 and 3 reuse them
            if created[1..].iter().any(|&n| n > 0) {
                offenders.push(format!("{} ({name} light {light}): buffers {created:?}", info.name));
            }
            if groups[1..].iter().any(|&n| n > 0) {
                offenders.push(format!("{} ({name} light {light}): bind groups {groups:?}", info.name));
            }
            checked += 1;
        }
    }
    assert!(checked >= 20, "only {checked} techniques checked");
    assert!(offenders.is_empty(), "made per frame (frames 1-3): {offenders:#?}");
}

#[test]
fn the_lab_counts_the_dispatches_of_one_frame() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("planebox").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 0, 64);
    // known from the code: `sm` and `rt` evaluate in one compute dispatch each, their maps
    // (sm) and rays (rt's trace is that dispatch) need no other; three timed repetitions must
    // not add up
    for (spec, expected) in [("sm", 1.0), ("rt", 1.0)] {
        let run = lab.run(&v, &TechniqueSpec::parse(spec).unwrap(), 3).unwrap();
        assert_eq!(run.report.counters.get("dispatches_per_frame"), Some(&expected), "{spec}");
    }
    let rtw = lab.run(&v, &TechniqueSpec::parse("rtw").unwrap(), 2).unwrap();
    let n = rtw.report.counters["dispatches_per_frame"];
    assert!(n > 6.0, "rtw's desired view, importance, prefix sums, subdivision and evaluation: {n}");
}

/// `file:line` of every line of the crate's sources (but `allowed`) that calls one of `calls`.
fn calls_outside(calls: &[&str], allowed: &str) -> Vec<String> {
    let src = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut found = Vec::new();
    let mut stack = vec![src];
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "rs") && !p.ends_with(allowed) {
                let text = std::fs::read_to_string(&p).unwrap();
                for (i, line) in text.lines().enumerate() {
                    if calls.iter().any(|c| line.contains(c)) {
                        found.push(format!("{}:{}", p.display(), i + 1));
                    }
                }
            }
        }
    }
    found
}

#[test]
fn every_buffer_is_made_through_the_counting_wrapper() {
    // device.create_buffer outside alloc.rs would escape the count above
    let found = calls_outside(&[".create_buffer(", ".create_buffer_init("], "alloc.rs");
    assert!(found.is_empty(), "buffers made around Gpu::buffer: {found:?}");
}

#[test]
fn every_dispatch_is_counted() {
    // the lab's `dispatches_per_frame` counts Gpu::dispatch and Gpu::dispatch_indirect
    let found = calls_outside(&[".dispatch_workgroups(", ".dispatch_workgroups_indirect("], "alloc.rs");
    assert!(found.is_empty(), "dispatches around Gpu::dispatch: {found:?}");
}
