//! Fuzz targets for every input shadowlab-core parses (issue 41): technique spec strings, setup
//! files and scene files. The invariant: no panic, whatever the bytes; every other outcome is a value or
//! a clear error. Under `cargo test` bolero runs each target on random inputs for a moment;
//! `cargo bolero test TARGET --package shadowlab-fuzz --sanitizer NONE` runs libFuzzer
//! (docs/fuzz.md). The scene loaders (OBJ, MTL, glTF, GLB) read a bundle of files held in
//! memory (`bundle`); the viewer's saved views are setup files, read by `Setup::parse`.

use std::path::Path;

use bolero::check;
use shadowlab_core::bvh::Bvh;
use shadowlab_core::loaders::{self, InMemory, SceneTransform};
use shadowlab_core::params::TechniqueSpec;
use shadowlab_core::scene::Scene;
use shadowlab_core::setup::Setup;

mod seeds;

#[test]
fn technique_specs() {
    check!().for_each(|bytes: &[u8]| {
        if let Ok(text) = std::str::from_utf8(bytes) {
            if let Ok(spec) = TechniqueSpec::parse(text) {
                // what parses names a technique and keeps its text
                assert!(!spec.name.is_empty());
            }
        }
    });
}

fn setup(text: &str) {
    if let Ok(setup) = Setup::parse(text) {
        let _ = setup.validate();
    }
}

#[test]
fn setup_files() {
    check!().for_each(|bytes: &[u8]| {
        if let Ok(text) = std::str::from_utf8(bytes) {
            setup(text);
        }
    });
}

/// The shipped setups cut after every line, and with every line left out once: half-written
/// and hand-edited files, the inputs random bytes rarely reach (valid TOML, wrong content).
#[test]
fn shipped_setups_cut_and_thinned() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../setups");
    let mut files = 0;
    for e in std::fs::read_dir(&dir).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_none_or(|x| x != "toml") {
            continue;
        }
        let text = std::fs::read_to_string(&p).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        for i in 0..=lines.len() {
            setup(&lines[..i].join("\n"));
            let thinned: Vec<&str> = lines.iter().enumerate().filter(|(j, _)| *j != i).map(|(_, l)| *l).collect();
            setup(&thinned.join("\n"));
        }
        files += 1;
    }
    assert!(files >= 10, "only {files} setups under {}", dir.display());
}

// ---- scene files over bytes ----------------------------------------------------------------

/// One fuzz input as a set of files: the bytes up to the first `\n@@ NAME\n` line are the main
/// file `main`; each such line starts a file named NAME (an MTL, a texture, a buffer). Seeds are
/// real files joined this way, so that libFuzzer mutates names and references together.
fn bundle(bytes: &[u8], main: &str) -> InMemory {
    let mut files = InMemory::new();
    let mut name = main.to_string();
    let mut rest = bytes;
    loop {
        let Some(at) = rest.windows(4).position(|w| w == b"\n@@ ") else {
            files.insert(&name, rest.to_vec());
            return files;
        };
        files.insert(&name, rest[..at].to_vec());
        let after = &rest[at + 4..];
        let end = after.iter().position(|&b| b == b'\n').unwrap_or(after.len());
        name = String::from_utf8_lossy(&after[..end]).chars().take(200).collect();
        rest = &after[(end + 1).min(after.len())..];
    }
}

/// Loads `main` from `files`; what loads must be a scene every later stage can take: finite
/// positions, unit normals, materials and textures that exist, texels that match their sizes,
/// and a BVH that builds (or refuses clearly).
fn load_checked(files: &InMemory, main: &str) -> Option<Scene> {
    let scene = loaders::load_from(files, Path::new(main), &SceneTransform::default()).ok()?;
    assert!(!scene.vertices.is_empty() && scene.vertices.len() % 3 == 0);
    for v in &scene.vertices {
        assert!(v.pos.iter().all(|c| c.is_finite()), "non-finite position {:?}", v.pos);
        assert!(v.uv.iter().all(|c| c.is_finite()), "non-finite uv {:?}", v.uv);
        let n = glam::Vec3::from(v.normal).length();
        assert!((n - 1.0).abs() < 1e-3, "normal of length {n}");
        assert!((v.material as usize) < scene.materials.len(), "material {} of {}", v.material, scene.materials.len());
    }
    for m in &scene.materials {
        assert!(m.texture.is_none_or(|t| (t as usize) < scene.textures.len()));
    }
    for t in &scene.textures {
        assert_eq!(t.rgba.len(), 4 * t.width as usize * t.height as usize, "texture '{}'", t.name);
        assert!(t.width.max(t.height) <= loaders::MAX_TEXTURE_SIZE && t.width > 0 && t.height > 0);
    }
    if let Err(e) = Bvh::build(&scene) {
        assert!(!e.is_empty());
    }
    Some(scene)
}

/// The targets over scene files: the bytes of one input, loaded and checked.
fn scene_target(target: &str, bytes: &[u8]) -> Option<Scene> {
    match target {
        "obj_files" => load_checked(&bundle(bytes, "scene.obj"), "scene.obj"),
        // MTL text under a fixed OBJ that uses its materials (random bytes rarely write `mtllib`)
        "mtl_files" => {
            let obj = b"mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl a\nf 1/1 2/2 3/3\nusemtl b\nf 3/3 2/2 1/1";
            load_checked(&bundle(&seeds::join(obj, &[("m.mtl", bytes.to_vec())]), "scene.obj"), "scene.obj")
        }
        "gltf_files" => load_checked(&bundle(bytes, "scene.gltf"), "scene.gltf"),
        "glb_files" => load_checked(&bundle(bytes, "scene.glb"), "scene.glb"),
        _ => unreachable!("no target {target}"),
    }
}

const SCENE_TARGETS: [&str; 4] = ["obj_files", "mtl_files", "gltf_files", "glb_files"];

#[test]
fn obj_files() {
    check!().for_each(|bytes: &[u8]| {
        scene_target("obj_files", bytes);
    });
}

#[test]
fn mtl_files() {
    check!().for_each(|bytes: &[u8]| {
        scene_target("mtl_files", bytes);
    });
}

#[test]
fn gltf_files() {
    check!().for_each(|bytes: &[u8]| {
        scene_target("gltf_files", bytes);
    });
}

#[test]
fn glb_files() {
    check!().for_each(|bytes: &[u8]| {
        scene_target("glb_files", bytes);
    });
}

/// Every seed passes its target's checks, and the built-in scenes written as OBJ, glTF and GLB
/// load back with their triangles, positions bit for bit. With `SHADOWLAB_FUZZ_SEED=1` the seeds
/// are also written to each target's corpus (`tests/__fuzz__/TARGET/corpus`) for a campaign.
#[test]
fn seeds_load_as_written() {
    let write = std::env::var_os("SHADOWLAB_FUZZ_SEED").is_some();
    for target in SCENE_TARGETS {
        let seeds = seeds::seeds(target);
        assert!(seeds.len() >= 8, "{target}: {} seeds", seeds.len());
        let mut loaded = 0;
        for s in &seeds {
            let scene = scene_target(target, &s.bytes);
            loaded += usize::from(scene.is_some());
            if let Some(n) = s.triangles {
                let scene = scene.unwrap_or_else(|| panic!("{target}: seed {} does not load", s.name));
                assert_eq!(scene.triangle_count(), n, "{target}: seed {}", s.name);
                let name = s.name.strip_prefix("builtin-").unwrap();
                let original = shadowlab_core::builtin::builtin(name).unwrap();
                for (a, b) in scene.vertices.iter().zip(&original.vertices) {
                    assert_eq!(a.pos.map(f32::to_bits), b.pos.map(f32::to_bits), "{target}: seed {}", s.name);
                }
            }
            if write {
                let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/__fuzz__").join(target).join("corpus");
                std::fs::create_dir_all(&dir).unwrap();
                std::fs::write(dir.join(format!("seed-{}", s.name)), &s.bytes).unwrap();
            }
        }
        assert!(loaded >= seeds::BUILTIN_COUNT, "{target}: only {loaded} of {} seeds load", seeds.len());
    }
}

/// The inputs that once failed a target (checked in under `tests/__fuzz__/TARGET/crashes`, which
/// bolero replays too) pass it now: no panic, and what loads keeps the invariants.
#[test]
fn found_crashes_stay_fixed() {
    let mut n = 0;
    for target in SCENE_TARGETS {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/__fuzz__").join(target).join("crashes");
        for e in std::fs::read_dir(&dir).into_iter().flatten() {
            let path = e.unwrap().path();
            scene_target(target, &std::fs::read(&path).unwrap());
            n += 1;
        }
    }
    // glTF and GLB: buffer floats whose products overflowed the normal (NaN normals); an image
    // with neither uri nor bufferView (the gltf crate's Image::source panicked); a tiny triangle
    // whose subnormal cross product normalised to a length of 1.15
    assert!(n >= 5, "{n} regression inputs");
}

/// Files in memory resolve as on disk: the OBJ fixture, whose MTL names its textures with
/// backslashes, in another case and with options, loads from a bundle as from its directory.
#[test]
fn a_bundle_loads_like_the_directory() {
    let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shadowlab-core/tests/fixtures");
    let disk = loaders::load(&fixtures.join("quad.obj"), &SceneTransform::default()).unwrap();
    let seed = seeds::seeds("obj_files").into_iter().find(|s| s.name == "quad.obj").unwrap();
    let mem = scene_target("obj_files", &seed.bytes).unwrap();
    assert!(mem.report.warnings.is_empty(), "{:?}", mem.report.warnings);
    assert_eq!((mem.triangle_count(), mem.materials.len(), mem.textures.len()), (13, 7, 4));
    assert_eq!(format!("{:?}", mem.materials), format!("{:?}", disk.materials));
    for (a, b) in mem.textures.iter().zip(&disk.textures) {
        assert_eq!((a.width, a.height, &a.rgba), (b.width, b.height, &b.rgba));
    }
    assert_eq!(bytemuck_positions(&mem), bytemuck_positions(&disk));
}

fn bytemuck_positions(s: &Scene) -> Vec<[u32; 3]> {
    s.vertices.iter().map(|v| v.pos.map(f32::to_bits)).collect()
}
