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
    // clip distances: the paraboloid depth pass's variant for devices that have them
    Validator::new(ValidationFlags::all(), Capabilities::CLIP_DISTANCES)
        .validate(&module)
        .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(src)));
    module
}

#[test]
fn every_shader_validates() {
    let all = shadowlab_gpu::registry::shaders();
    assert!(all.len() >= 6);
    for (name, src) in &all {
        parse(name, src);
    }
}

#[test]
fn every_shader_validates_with_its_uniforms_as_storage() {
    // lavapipe binds uniform buffers as read-only storage (shadowlab_gpu::quirks): the same
    // shaders must validate that way, and every such buffer keep its size and layout
    let mut rewritten = 0;
    for (name, src) in shadowlab_gpu::registry::shaders() {
        let as_storage = shadowlab_gpu::quirks::wgsl(&src, true);
        let (a, b) = (parse(&name, &src), parse(&name, &as_storage));
        let (mut la, mut lb) = (naga::proc::Layouter::default(), naga::proc::Layouter::default());
        la.update(a.to_ctx()).unwrap();
        lb.update(b.to_ctx()).unwrap();
        for (_, g) in a.global_variables.iter().filter(|(_, g)| g.space == naga::AddressSpace::Uniform) {
            let (_, h) = b.global_variables.iter().find(|(_, h)| h.name == g.name).unwrap();
            assert_eq!(h.space, naga::AddressSpace::Storage { access: naga::StorageAccess::LOAD }, "{name}: {:?}", g.name);
            assert_eq!(la[g.ty].size, lb[h.ty].size, "{name}: {:?} changes size", g.name);
            assert_eq!(a.types[g.ty].inner, b.types[h.ty].inner, "{name}: {:?} changes type", g.name);
            rewritten += 1;
        }
    }
    assert!(rewritten > 20, "only {rewritten} uniform buffers seen");
}

#[test]
fn every_entry_point_survives_its_pipeline_constants() {
    // wgpu resolves `override`s per entry point when it makes a pipeline (naga's
    // process_overrides), which re-validates the module: naga 30 rejects there some functions the
    // plain validation accepts (a `let` of a constant array in an entry point that also sees an
    // override: ExpressionAlreadyInScope). Every entry point of every shader, with each override
    // that has no default set to 0 and to 1.
    let mut specialised = 0;
    for (name, src) in shadowlab_gpu::registry::shaders() {
        let m = parse(&name, &src);
        let info = Validator::new(ValidationFlags::all(), Capabilities::CLIP_DISTANCES).validate(&m).unwrap();
        for value in [0.0, 1.0] {
            let mut constants = naga::back::PipelineConstants::default();
            for (_, o) in m.overrides.iter().filter(|(_, o)| o.init.is_none()) {
                constants.insert(o.name.clone().expect("overrides are named"), value);
            }
            for ep in &m.entry_points {
                naga::back::pipeline_constants::process_overrides(&m, &info, Some((ep.stage, &ep.name)), &constants)
                    .unwrap_or_else(|e| panic!("{name} {}: {e:?}", ep.name));
                specialised += !m.overrides.is_empty() as usize;
            }
        }
    }
    assert!(specialised > 20, "only {specialised} entry points with overrides seen");
}

#[test]
fn every_wgsl_file_is_composed_somewhere() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let composed: String = shadowlab_gpu::registry::shaders().into_iter().map(|(_, s)| s).collect();
    let mut stack = vec![root];
    let mut seen = 0;
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "wgsl") {
                let text = std::fs::read_to_string(&p).unwrap();
                assert!(composed.contains(&text), "{} is not part of registry::shaders(), so it is never validated", p.display());
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

/// `(name, offset)` of each listed field of a Rust struct.
macro_rules! fields {
    ($t:ty; $($f:ident),+ $(,)?) => { &[$((stringify!($f), offset_of!($t, $f))),+] };
}

/// [`check`], and every WGSL member is one of `offsets` (each value has its own named field).
fn check_all(module: &naga::Module, name: &str, size: usize, offsets: &[(&str, usize)]) {
    check(module, name, size, offsets);
    let (_, members) = layout(module, name);
    for (m, _) in &members {
        assert!(offsets.iter().any(|(n, _)| n == m), "{name}.{m}: a WGSL member the Rust side does not name");
    }
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
    let all = shadowlab_gpu::registry::shaders();
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
fn mdsm_params_layout_matches_wgsl() {
    use shadowlab_gpu::techniques::mdsm::MdsmParams;
    let all = shadowlab_gpu::registry::shaders();
    for name in ["mdsm/select.wgsl", "mdsm/eval.wgsl"] {
        let src = &all.iter().find(|(n, _)| *n == name).unwrap_or_else(|| panic!("{name} not composed")).1;
        check_all(
            &parse(name, src),
            "MdsmParams",
            size_of::<MdsmParams>(),
            fields!(MdsmParams; light_view_proj, texel, bias, n, region, select, region_bias),
        );
    }
}

#[test]
fn sv_struct_layouts_match_rust() {
    use shadowlab_core::techniques::sv::Edge;
    use shadowlab_gpu::techniques::sv::SvParams;
    let all = shadowlab_gpu::registry::shaders();
    let get = |n: &str| parse(n, &all.iter().find(|(name, _)| *name == n).unwrap().1);
    for f in ["sv/silhouette.wgsl", "sv/volume.wgsl", "sv/resolve.wgsl"] {
        let f = get(f);
        check_all(
            &f,
            "SvParams",
            size_of::<SvParams>(),
            fields!(SvParams; triangles, edges, side_vertices, depth_offset, extrude, pad0, pad1, pad2),
        );
    }
    for f in ["sv/silhouette.wgsl", "sv/volume.wgsl"] {
        let offsets = [("a", 0), ("b", offset_of!(Edge, b)), ("first", offset_of!(Edge, first)), ("count", offset_of!(Edge, count))];
        check(&get(f), "Edge", size_of::<Edge>(), &offsets);
    }
}

#[test]
fn csm_and_reduce_layouts_match_rust() {
    use shadowlab_gpu::reduce::ReduceParams;
    use shadowlab_gpu::techniques::csm::{CascadeU, CsmParams};
    let all = shadowlab_gpu::registry::shaders();
    let get = |n: &str| parse(n, &all.iter().find(|(name, _)| *name == n).unwrap().1);
    let eval = get("csm/eval.wgsl");
    check(&eval, "Cascade", size_of::<CascadeU>(), &[("view_proj", 0), ("info", offset_of!(CascadeU, info))]);
    check_all(
        &eval,
        "CsmParams",
        size_of::<CsmParams>(),
        fields!(CsmParams; cascades, count, res, pcf, blend, bias, normal_offset, max_slope, pad0),
    );
    check(&get("csm/depth.wgsl"), "CsmDepth", size_of::<[[f32; 4]; 4]>(), &[("view_proj", 0)]);
    check(&get("reduce/reduce.wgsl"), "ReduceParams", size_of::<ReduceParams>(), &[("channel", 0)]);
}

#[test]
fn iasm_layouts_match_wgsl() {
    use shadowlab_gpu::techniques::iasm::{FitParams, IasmParams, TileParams};
    let all = shadowlab_gpu::registry::shaders();
    let get = |n: &str| parse(n, &all.iter().find(|(name, _)| *name == n).unwrap().1);
    for n in ["iasm/analysis.wgsl", "iasm/eval.wgsl", "iasm/eval_atlas.wgsl", "iasm/probe.wgsl"] {
        check(
            &get(n),
            "IasmParams",
            size_of::<IasmParams>(),
            &[
                ("up", offset_of!(IasmParams, up)),
                ("dir", offset_of!(IasmParams, dir)),
                ("imp", offset_of!(IasmParams, imp)),
                ("res", offset_of!(IasmParams, res)),
                ("off", offset_of!(IasmParams, off)),
                ("near", offset_of!(IasmParams, near)),
                ("far", offset_of!(IasmParams, far)),
                ("slot", offset_of!(IasmParams, slot)),
            ],
        );
    }
    for n in ["iasm/render.wgsl", "iasm/atlas.wgsl"] {
        check(&get(n), "TileParams", size_of::<TileParams>(), &[("tile", offset_of!(TileParams, tile))]);
    }
    check_all(
        &get("iasm/fit.wgsl"),
        "FitParams",
        size_of::<FitParams>(),
        fields!(FitParams; margin, min_side, prev, div, shrink, steps, pad0, pad1, fracs),
    );
}

#[test]
fn filtered_and_blur_layouts_match_rust() {
    use shadowlab_gpu::blur::BlurParams;
    use shadowlab_gpu::techniques::filtered::FilteredParams;
    let all = shadowlab_gpu::registry::shaders();
    let get = |n: &str| parse(n, &all.iter().find(|(name, _)| *name == n).unwrap().1);
    for f in ["filtered/render.wgsl", "filtered/eval.wgsl"] {
        check_all(
            &get(f),
            "FilteredParams",
            size_of::<FilteredParams>(),
            fields!(FilteredParams; light_view_proj, texel_world, perspective, res, inv_far, kind, single_depth, mip_levels, pad0,
                min_variance, esm_c, evsm_c_pos, evsm_c_neg, moment_bias, depth_bias, normal_offset, pad1),
        );
    }
    for b in ["blur/blur.wgsl (r32float)", "blur/blur.wgsl (rgba32float)"] {
        check(
            &get(b),
            "BlurParams",
            size_of::<BlurParams>(),
            &[("dir", offset_of!(BlurParams, dir)), ("half", offset_of!(BlurParams, half)), ("sigma", offset_of!(BlurParams, sigma))],
        );
    }
}

#[test]
fn min_sm_reduce_layout_matches_rust() {
    use shadowlab_gpu::techniques::min_sm::MsfReduce;
    let all = shadowlab_gpu::registry::shaders();
    let src = &all.iter().find(|(n, _)| *n == "min_sm/reduce.wgsl").expect("min_sm/reduce.wgsl listed").1;
    check(
        &parse("min_sm/reduce.wgsl", src),
        "MsfReduce",
        size_of::<MsfReduce>(),
        &[("mode", offset_of!(MsfReduce, mode)), ("prev", offset_of!(MsfReduce, prev))],
    );
}

#[test]
fn warp_struct_layouts_match_rust() {
    use shadowlab_gpu::prefix_sum::ScanParams;
    use shadowlab_gpu::techniques::warp::WarpParams;
    let all = shadowlab_gpu::registry::shaders();
    let get = |n: &str| parse(n, &all.iter().find(|(name, _)| *name == n).unwrap().1);
    let layered = [
        "cube/eval_notw.wgsl (desired views)",
        "cube/eval_notw.wgsl (count maps)",
        "cube/eval_notw.wgsl (evaluation)",
        "warp/analyze_layers.wgsl (six faces)",
        "dpsm/eval_maps.wgsl (desired views)",
        "dpsm/eval_maps.wgsl (count maps)",
        "dpsm/eval_maps.wgsl (evaluation)",
        "warp/analyze_layers.wgsl (two hemispheres)",
    ];
    for w in ["warp/analyze.wgsl", "warp/depth.wgsl", "warp/subdiv.wgsl", "warp/eval.wgsl"].into_iter().chain(layered) {
        check_all(
            &get(w),
            "WarpParams",
            size_of::<WarpParams>(),
            fields!(WarpParams; light_view_proj, texel_world, perspective, res, pcf, bias, slope_bias, normal_offset, max_slope,
                dv_margin, dv_mode, warped, window, w_dv, w_eye, blur, subdiv, triangles, subdiv_levels, extra_capacity,
                rtw_importance, interp, mix, exact_depth, projection, strength, bias_mode, footprint_cap, depth_clamp, min_piece, exact_inverse, cull_hidden, tent, edge_importance, depth_split, exact_tol, tessellate, scene_triangles, pad0, pad1, pad2),
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

#[test]
fn scene_info_layout_matches_wgsl() {
    use shadowlab_gpu::scene_gpu::SceneInfo;
    let all = shadowlab_gpu::registry::shaders();
    for name in ["rt.wgsl", "gbuffer.wgsl"] {
        let src = &all.iter().find(|(n, _)| *n == name).unwrap_or_else(|| panic!("{name} not composed")).1;
        check(
            &parse(name, src),
            "SceneInfo",
            size_of::<SceneInfo>(),
            &[
                ("triangle_count", offset_of!(SceneInfo, triangle_count)),
                ("dynamic_first", offset_of!(SceneInfo, dynamic_first)),
                ("dynamic_root", offset_of!(SceneInfo, dynamic_root)),
            ],
        );
    }
}

#[test]
fn cube_layouts_match_wgsl() {
    use shadowlab_gpu::techniques::cube::{CubeFace, CubeParams};
    let all = shadowlab_gpu::registry::shaders();
    let get = |n: &str| parse(n, &all.iter().find(|(name, _)| *name == n).unwrap_or_else(|| panic!("{n} not composed")).1);
    check(
        &get("cube/depth.wgsl"),
        "CubeFace",
        size_of::<CubeFace>(),
        &[("light", offset_of!(CubeFace, light)), ("face", offset_of!(CubeFace, face))],
    );
    check_all(
        &get("cube/eval.wgsl"),
        "CubeParams",
        size_of::<CubeParams>(),
        fields!(CubeParams; position, far, res, pcf, near, pad0, bias),
    );
}

#[test]
fn lt_params_layout_matches_wgsl() {
    use shadowlab_gpu::techniques::lt::{LevelU, LtParams, TraceParams};
    let all = shadowlab_gpu::registry::shaders();
    let get = |n: &str| parse(n, &all.iter().find(|(name, _)| *name == n).unwrap_or_else(|| panic!("{n} not composed")).1);
    check_all(
        &get("lt/classify.wgsl"),
        "LtParams",
        size_of::<LtParams>(),
        fields!(LtParams; levels, layers, perspective, res, inv_far, technique, base, frame, flags, min_variance, esm_c,
            evsm_c_pos, evsm_c_neg, moment_bias, depth_bias, normal_offset, eps, depth_tol, normal_cos, mask_bits, pad0),
    );
    check(&get("lt/classify.wgsl"), "Level", size_of::<LevelU>(), &[("info", offset_of!(LevelU, info))]);
    for n in ["lt/trace.wgsl", "lt/args.wgsl"] {
        check(&get(n), "TraceParams", size_of::<TraceParams>(), &[("cfg", offset_of!(TraceParams, cfg))]);
    }
}

/// WebGPU's default limit of storage buffers per shader stage; `TechniqueInfo::needs` and
/// `storage_buffers` must declare more where a technique's pipelines bind more (the reference,
/// `rt`, binds 8 since the scene's previous-frame vertices share its vertex buffer). The count is the storage buffers a
/// module declares (its bind group layouts declare the same bindings, and the limit counts
/// the layout's bindings, used or not).
const DEFAULT_STORAGE_BUFFERS: usize = 8;

/// Shader folders (or files) and the registry techniques whose pipelines they are.
const FOLDERS: &[(&str, &[&str])] =
    &[("lt", &["lt", "ltt", "hybrid-pcf"]), ("warp", &["rtw", "notw", "dpsm", "dpsm-notw", "cube-notw"]), ("sv", &["sv"])];

#[test]
fn techniques_declare_the_storage_buffers_they_need_beyond_the_default() {
    let mut most: std::collections::BTreeMap<String, usize> = Default::default();
    for (name, src) in shadowlab_gpu::registry::shaders() {
        let module = naga::front::wgsl::parse_str(&src).unwrap();
        let n = module.global_variables.iter().filter(|(_, g)| matches!(g.space, naga::AddressSpace::Storage { .. })).count();
        let folder = name.split('/').next().unwrap().to_string();
        if n > DEFAULT_STORAGE_BUFFERS {
            let m = most.entry(folder).or_default();
            *m = (*m).max(n);
        }
    }
    for (folder, n) in &most {
        let Some((_, names)) = FOLDERS.iter().find(|(f, _)| f == folder) else {
            panic!("{folder} binds {n} storage buffers (WebGPU's default is {DEFAULT_STORAGE_BUFFERS}): add it to FOLDERS and declare it in TechniqueInfo::needs");
        };
        for t in shadowlab_gpu::registry::REGISTRY.iter().filter(|t| names.contains(&t.name)) {
            let want = format!("{n} storage buffers per shader stage");
            assert!(t.needs.contains(&want), "{} binds {n} storage buffers ({folder}); its needs say: {:?}", t.name, t.needs);
            assert_eq!(t.storage_buffers as usize, *n, "{}: TechniqueInfo::storage_buffers", t.name);
        }
    }
    assert_eq!(most.len(), FOLDERS.len(), "a folder of FOLDERS no longer needs more than the default: {most:?}");
}

#[test]
fn sdsm_layout_matches_wgsl() {
    use shadowlab_gpu::techniques::csm::SdsmReduce;
    let all = shadowlab_gpu::registry::shaders();
    let get = |n: &str| parse(n, &all.iter().find(|(name, _)| *name == n).unwrap().1);
    check_all(
        &get("csm/sdsm_bounds.wgsl"),
        "SdsmReduce",
        size_of::<SdsmReduce>(),
        fields!(SdsmReduce; light_view, near, far, count, lambda, steps, pad0, pad1, pad2),
    );
}

#[test]
fn virtual_params_layout_matches_rust() {
    use shadowlab_gpu::techniques::virtual_sm::VirtualParams;
    let all = shadowlab_gpu::registry::shaders();
    let get = |n: &str| parse(n, &all.iter().find(|(name, _)| *name == n).unwrap().1);
    let f = fields!(VirtualParams; right, up, dir, view, dims, bias, pcf, spot, face_axes, origins);
    check_all(&get("virtual_sm/mark.wgsl"), "VirtualParams", size_of::<VirtualParams>(), f);
    check_all(&get("virtual_sm/eval.wgsl"), "VirtualParams", size_of::<VirtualParams>(), f);
}

/// The layout checks above are written by hand, one per GPU struct; this keeps them complete:
/// every `#[repr(C)]` struct in the crate's sources (the structs shared with WGSL) is named in
/// a check in this file, so a new technique's uniform cannot be left out.
#[test]
fn every_repr_c_struct_has_a_layout_check() {
    fn rs_files(dir: &std::path::Path, out: &mut Vec<std::path::PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                rs_files(&p, out);
            } else if p.extension().is_some_and(|x| x == "rs") {
                out.push(p);
            }
        }
    }
    let this = include_str!("shaders.rs");
    let checks = &this[..this.find("fn every_repr_c_struct_has_a_layout_check").unwrap()];
    let mut files = Vec::new();
    rs_files(&std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src"), &mut files);
    let mut found = Vec::new();
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        for (i, _) in text.match_indices("#[repr(C)]") {
            let after = &text[i..];
            let s = after.find("struct ").expect("a struct follows #[repr(C)]") + "struct ".len();
            let name: String = after[s..].chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
            let named = checks.match_indices(name.as_str()).any(|(j, _)| {
                let before = checks[..j].chars().last().is_none_or(|c| !c.is_alphanumeric() && c != '_');
                let next = checks[j + name.len()..].chars().next().is_none_or(|c| !c.is_alphanumeric() && c != '_');
                before && next
            });
            assert!(named, "{}: #[repr(C)] struct {name} has no layout check in tests/shaders.rs", f.display());
            found.push(name);
        }
    }
    assert!(found.len() >= 20, "only {} GPU structs found: {found:?}", found.len());
}
