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
fn every_buffer_is_made_through_the_counting_wrapper() {
    // device.create_buffer outside alloc.rs would escape the count above
    let src = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut found = Vec::new();
    let mut stack = vec![src];
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "rs") && !p.ends_with("alloc.rs") {
                let text = std::fs::read_to_string(&p).unwrap();
                for (i, line) in text.lines().enumerate() {
                    if line.contains(".create_buffer(") || line.contains(".create_buffer_init(") {
                        found.push(format!("{}:{}", p.display(), i + 1));
                    }
                }
            }
        }
    }
    assert!(found.is_empty(), "buffers made around Gpu::buffer: {found:?}");
}
