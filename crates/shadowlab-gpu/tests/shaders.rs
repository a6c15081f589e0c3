//! CPU-only: every composed shader parses and validates with naga, every .wgsl file in the crate
//! is part of some composed shader, and the structs shared with Rust have the same layout.

use std::mem::{offset_of, size_of};

use naga::valid::{Capabilities, ValidationFlags, Validator};
use shadowlab_core::bvh::BvhNode;
use shadowlab_core::scene::Vertex;
use shadowlab_gpu::frame::{FrameUniform, LightUniform};
use shadowlab_gpu::scene_gpu::GpuMaterial;
use shadowlab_gpu::techniques::sm::SmParams;

fn parse(name: &str, src: &str) -> naga::Module {
    let module = naga::front::wgsl::parse_str(src).unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(src)));
    Validator::new(ValidationFlags::all(), Capabilities::empty())
        .validate(&module)
        .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(src)));
    module
}

#[test]
fn every_shader_validates() {
    let all = shadowlab_gpu::shaders::all();
    assert!(all.len() >= 6);
    for (name, src) in &all {
        parse(name, src);
    }
}

#[test]
fn every_wgsl_file_is_composed_somewhere() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let composed: String = shadowlab_gpu::shaders::all().into_iter().map(|(_, s)| s).collect();
    let mut stack = vec![root];
    let mut seen = 0;
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "wgsl") {
                let text = std::fs::read_to_string(&p).unwrap();
                assert!(composed.contains(&text), "{} is not part of shaders::all(), so it is never validated", p.display());
                seen += 1;
            }
        }
    }
    assert!(seen >= 7, "found only {seen} wgsl files");
}

/// (size, [(member, offset)]) of a WGSL struct as naga lays it out.
fn layout(module: &naga::Module, name: &str) -> (u32, Vec<(String, u32)>) {
    for (_, ty) in module.types.iter() {
        if ty.name.as_deref() == Some(name) {
            if let naga::TypeInner::Struct { members, span } = &ty.inner {
                return (*span, members.iter().map(|m| (m.name.clone().unwrap_or_default(), m.offset)).collect());
            }
        }
    }
    panic!("struct {name} not found");
}

fn check(module: &naga::Module, name: &str, size: usize, offsets: &[(&str, usize)]) {
    let (span, members) = layout(module, name);
    assert_eq!(span as usize, size, "{name}: WGSL size {span} != Rust size {size}");
    for (m, off) in offsets {
        let (_, o) = members.iter().find(|(n, _)| n == m).unwrap_or_else(|| panic!("{name}.{m} missing in WGSL"));
        assert_eq!(*o as usize, *off, "{name}.{m}: WGSL offset {o} != Rust offset {off}");
    }
}

#[test]
fn shared_struct_layouts_match_rust() {
    let all = shadowlab_gpu::shaders::all();
    let get = |n: &str| parse(n, &all.iter().find(|(name, _)| *name == n).unwrap().1);
    let rt = get("rt.wgsl");
    check(
        &rt,
        "Vertex",
        size_of::<Vertex>(),
        &[
            ("pos", offset_of!(Vertex, pos)),
            ("material", offset_of!(Vertex, material)),
            ("normal", offset_of!(Vertex, normal)),
            ("uv", offset_of!(Vertex, uv)),
        ],
    );
    check(
        &rt,
        "Material",
        size_of::<GpuMaterial>(),
        &[
            ("base_color", 0),
            ("tex_offset", offset_of!(GpuMaterial, tex_offset)),
            ("flags", offset_of!(GpuMaterial, flags)),
            ("alpha_cutoff", offset_of!(GpuMaterial, alpha_cutoff)),
        ],
    );
    check(
        &rt,
        "BvhNode",
        size_of::<BvhNode>(),
        &[
            ("min", 0),
            ("prim_count", offset_of!(BvhNode, prim_count)),
            ("max", offset_of!(BvhNode, max)),
            ("first_index", offset_of!(BvhNode, first_index)),
        ],
    );
    check(
        &rt,
        "Frame",
        size_of::<FrameUniform>(),
        &[
            ("prev_view_proj", offset_of!(FrameUniform, prev_view_proj)),
            ("camera_pos", offset_of!(FrameUniform, camera_pos)),
            ("size", offset_of!(FrameUniform, size)),
        ],
    );
    check(
        &rt,
        "LightU",
        size_of::<LightUniform>(),
        &[
            ("direction", offset_of!(LightUniform, direction)),
            ("kind", offset_of!(LightUniform, kind)),
            ("cos_cone", offset_of!(LightUniform, cos_cone)),
            ("eps", offset_of!(LightUniform, eps)),
        ],
    );
    for sm in ["sm/depth.wgsl", "sm/eval.wgsl"] {
        check(&get(sm), "SmParams", size_of::<SmParams>(), &[("texel", offset_of!(SmParams, texel)), ("bias", offset_of!(SmParams, bias))]);
    }
}

#[test]
fn warp_struct_layouts_match_rust() {
    use shadowlab_gpu::prefix_sum::ScanParams;
    use shadowlab_gpu::techniques::warp::WarpParams;
    let all = shadowlab_gpu::shaders::all();
    let get = |n: &str| parse(n, &all.iter().find(|(name, _)| *name == n).unwrap().1);
    for w in ["warp/analyze.wgsl", "warp/depth.wgsl", "warp/subdiv.wgsl", "warp/eval.wgsl"] {
        check(
            &get(w),
            "WarpParams",
            size_of::<WarpParams>(),
            &[
                ("texel", offset_of!(WarpParams, texel)),
                ("bias", offset_of!(WarpParams, bias)),
                ("cfg", offset_of!(WarpParams, cfg)),
                ("imp", offset_of!(WarpParams, imp)),
                ("ints", offset_of!(WarpParams, ints)),
                ("flags", offset_of!(WarpParams, flags)),
            ],
        );
    }
    check(
        &get("prefix_sum/scan.wgsl"),
        "ScanParams",
        size_of::<ScanParams>(),
        &[
            ("len", offset_of!(ScanParams, len)),
            ("elem_step", offset_of!(ScanParams, elem_step)),
            ("in_base", offset_of!(ScanParams, in_base)),
            ("out_base", offset_of!(ScanParams, out_base)),
            ("input_f32", offset_of!(ScanParams, input_f32)),
        ],
    );
}
