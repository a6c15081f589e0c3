//! Seed inputs for the scene-file targets: the loader fixtures, the built-in scenes (their first
//! triangles) written as OBJ + MTL, glTF with a data-URI buffer and GLB, and small files from
//! ../shared/scenes when that directory exists. Each seed is a bundle (`fuzz.rs`: the main file,
//! then `\n@@ NAME\n` and each file it names).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use shadowlab_core::builtin::BUILTIN_SCENES;
use shadowlab_core::scene::Scene;

/// Triangles of each built-in scene kept in its seeds (seeds stay a few kilobytes).
pub const BUILTIN_TRIANGLES: usize = 48;
/// The built-in scenes: each target has one seed per scene.
pub const BUILTIN_COUNT: usize = BUILTIN_SCENES.len();
/// Files from ../shared/scenes larger than this are not seeds.
const MAX_SHARED_BYTES: u64 = 64 << 10;

pub struct Seed {
    pub name: String,
    pub bytes: Vec<u8>,
    /// Triangles it must load with (the built-in exports), None when it may fail.
    pub triangles: Option<usize>,
}

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../shadowlab-core/tests/fixtures")
}

/// `main` followed by the named files, as one bundle.
pub fn join(main: &[u8], more: &[(&str, Vec<u8>)]) -> Vec<u8> {
    let mut out = main.to_vec();
    for (name, bytes) in more {
        out.extend_from_slice(format!("\n@@ {name}\n").as_bytes());
        out.extend_from_slice(bytes);
    }
    out
}

fn read(p: &Path) -> Vec<u8> {
    std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// The first `n` triangles of `scene`.
fn head(scene: &Scene, n: usize) -> Vec<&shadowlab_core::scene::Vertex> {
    scene.vertices.iter().take(3 * n).collect()
}

pub fn obj_of(scene: &Scene, n: usize) -> (Vec<u8>, Vec<u8>) {
    let (mut obj, mut mtl) = (String::from("mtllib scene.mtl\n"), String::new());
    let verts = head(scene, n);
    for v in &verts {
        writeln!(obj, "v {:?} {:?} {:?}\nvt {:?} {:?}", v.pos[0], v.pos[1], v.pos[2], v.uv[0], 1.0 - v.uv[1]).unwrap();
    }
    let mut used = None;
    for (t, tri) in verts.chunks_exact(3).enumerate() {
        if used != Some(tri[0].material) {
            used = Some(tri[0].material);
            writeln!(obj, "usemtl m{}", tri[0].material).unwrap();
        }
        let i = 3 * t + 1;
        writeln!(obj, "f {i}/{i} {}/{} {}/{}", i + 1, i + 1, i + 2, i + 2).unwrap();
    }
    for (i, m) in scene.materials.iter().enumerate() {
        let c = m.base_color;
        writeln!(mtl, "newmtl m{i}\nKd {:?} {:?} {:?}\nd {:?}", c[0], c[1], c[2], c[3]).unwrap();
    }
    (obj.into_bytes(), mtl.into_bytes())
}

fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for c in bytes.chunks(3) {
        let w = (u32::from(c[0]) << 16) | (u32::from(*c.get(1).unwrap_or(&0)) << 8) | u32::from(*c.get(2).unwrap_or(&0));
        for k in 0..4 {
            out.push(if k <= c.len() { A[(w >> (18 - 6 * k) & 63) as usize] as char } else { '=' });
        }
    }
    out
}

/// glTF JSON and its binary buffer: one primitive per run of triangles with one material,
/// positions and texture coordinates not indexed. `uri` None: the GLB's own buffer.
fn gltf_parts(scene: &Scene, n: usize, uri: Option<&str>) -> (String, Vec<u8>) {
    let verts = head(scene, n);
    let mut bin = Vec::new();
    for v in &verts {
        v.pos.iter().for_each(|c| bin.extend_from_slice(&c.to_le_bytes()));
    }
    let uv_offset = bin.len();
    for v in &verts {
        v.uv.iter().for_each(|c| bin.extend_from_slice(&c.to_le_bytes()));
    }
    let (mut accessors, mut prims) = (Vec::new(), Vec::new());
    let mut start = 0;
    while start < verts.len() {
        let mat = verts[start].material;
        let mut end = start + 3;
        while end < verts.len() && verts[end].material == mat {
            end += 3;
        }
        let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
        for v in &verts[start..end] {
            for k in 0..3 {
                lo[k] = lo[k].min(v.pos[k]);
                hi[k] = hi[k].max(v.pos[k]);
            }
        }
        let a = accessors.len();
        accessors.push(serde_json::json!({"bufferView": 0, "byteOffset": 12 * start, "componentType": 5126, "count": end - start, "type": "VEC3", "min": lo, "max": hi}));
        accessors.push(
            serde_json::json!({"bufferView": 1, "byteOffset": 8 * start, "componentType": 5126, "count": end - start, "type": "VEC2"}),
        );
        prims.push(serde_json::json!({"attributes": {"POSITION": a, "TEXCOORD_0": a + 1}, "material": mat}));
        start = end;
    }
    let materials: Vec<_> = scene
        .materials
        .iter()
        .map(|m| {
            let mut j = serde_json::json!({"name": m.name, "pbrMetallicRoughness": {"baseColorFactor": m.base_color}, "doubleSided": m.double_sided});
            if let Some(c) = m.alpha_cutoff {
                j["alphaMode"] = "MASK".into();
                j["alphaCutoff"] = c.into();
            }
            j
        })
        .collect();
    let mut buffer = serde_json::json!({"byteLength": bin.len()});
    if let Some(u) = uri {
        buffer["uri"] = u.into();
    }
    let json = serde_json::json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": scene.name}],
        "meshes": [{"primitives": prims}],
        "materials": materials,
        "accessors": accessors,
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": uv_offset},
            {"buffer": 0, "byteOffset": uv_offset, "byteLength": bin.len() - uv_offset}
        ],
        "buffers": [buffer],
    });
    (json.to_string(), bin)
}

/// glTF with its buffer as a base64 data URI.
pub fn gltf_of(scene: &Scene, n: usize) -> Vec<u8> {
    let (_, bin) = gltf_parts(scene, n, None);
    let uri = format!("data:application/octet-stream;base64,{}", base64(&bin));
    gltf_parts(scene, n, Some(&uri)).0.into_bytes()
}

pub fn glb_of(scene: &Scene, n: usize) -> Vec<u8> {
    let (json, bin) = gltf_parts(scene, n, None);
    let mut json = json.into_bytes();
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    let mut bin = bin;
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out
}

fn files_in(dir: &Path, ext: &str) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|d| {
            d.filter_map(|e| e.ok().map(|e| e.path())).filter(|p| p.extension().is_some_and(|x| x.eq_ignore_ascii_case(ext))).collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

/// ../shared/scenes/*/FILE.ext no larger than [`MAX_SHARED_BYTES`] (none when it is absent).
fn shared(ext: &str) -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes");
    let mut out = Vec::new();
    for d in std::fs::read_dir(&root).into_iter().flatten().flatten() {
        out.extend(files_in(&d.path(), ext).into_iter().filter(|p| p.metadata().is_ok_and(|m| m.len() <= MAX_SHARED_BYTES)));
    }
    out.sort();
    out
}

fn seed(name: impl Into<String>, bytes: Vec<u8>, triangles: Option<usize>) -> Seed {
    Seed { name: name.into(), bytes, triangles }
}

/// Seeds of a target (`obj_files`, `mtl_files`, `gltf_files`, `glb_files`).
pub fn seeds(target: &str) -> Vec<Seed> {
    let fx = fixtures();
    let tex: Vec<(String, Vec<u8>)> =
        files_in(&fx.join("tex"), "png").iter().map(|p| (format!("tex/{}", p.file_name().unwrap().to_string_lossy()), read(p))).collect();
    let mut out = Vec::new();
    for b in BUILTIN_SCENES {
        let scene = (b.build)();
        let n = BUILTIN_TRIANGLES.min(scene.triangle_count());
        let (obj, mtl) = obj_of(&scene, n);
        match target {
            "obj_files" => out.push(seed(format!("builtin-{}", b.name), join(&obj, &[("scene.mtl", mtl)]), Some(n))),
            "mtl_files" => out.push(seed(format!("builtin-{}", b.name), mtl, None)),
            "gltf_files" => out.push(seed(format!("builtin-{}", b.name), gltf_of(&scene, n), Some(n))),
            "glb_files" => out.push(seed(format!("builtin-{}", b.name), glb_of(&scene, n), Some(n))),
            _ => panic!("no seeds for {target}"),
        }
    }
    let ext = match target {
        "obj_files" => "obj",
        "mtl_files" => "mtl",
        "gltf_files" => "gltf",
        _ => "glb",
    };
    for p in [files_in(&fx, ext), files_in(&fx.join("malformed"), ext), shared(ext)].concat() {
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        let bytes = read(&p);
        let bytes = match (target, name.as_str()) {
            // the OBJ fixture's MTL names textures in three spellings (tex\, TEX/, tex/)
            ("obj_files", "quad.obj") => {
                let more: Vec<(&str, Vec<u8>)> = [("quad.mtl", read(&fx.join("quad.mtl")))]
                    .into_iter()
                    .chain(tex.iter().map(|(n, b)| (n.as_str(), b.clone())))
                    .collect();
                join(&bytes, &more)
            }
            ("mtl_files", _) => bytes,
            // a shared scene's OBJ with its MTL of the same name (textures left out: large)
            ("obj_files", _) if p.with_extension("mtl").is_file() => {
                let mtl = p.with_extension("mtl");
                join(&bytes, &[(&mtl.file_name().unwrap().to_string_lossy(), read(&mtl))])
            }
            _ => join(&bytes, &tex.iter().map(|(n, b)| (n.as_str(), b.clone())).collect::<Vec<_>>()),
        };
        out.push(seed(name, bytes, None));
    }
    out
}
