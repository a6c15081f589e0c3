//! Wavefront OBJ + MTL.
//!
//! Geometry goes through `tobj` (triangulated as fans, separate position/texcoord indices);
//! MTL files are read here, because `tobj`'s MTL parser keeps `map_Kd` options in the file
//! name and panics on short colour lines (`Kd 1 1`).
//!
//! - Positions go through the user matrix `m`; texture v is flipped (`v' = 1 - v`) so that
//!   the origin is the image's top-left, as in glTF.
//! - Material: `Kd` -> base colour, `d` -> base colour alpha, `map_Kd` -> texture, `map_d` ->
//!   the texture's alpha (its alpha channel if it has one, else its luminance; resampled to
//!   the diffuse texture's size; a white texture when there is no `map_Kd`).
//!   A material is alpha-tested (cutoff 0.5) when it has a loaded `map_d`, when its diffuse
//!   texture has any alpha < 255, or when `d < 1`. OBJ materials are double-sided.
//! - Texture paths are relative to the MTL file's directory (then the OBJ's); Windows
//!   backslashes, `map_*` options and case mismatches are handled. Textures are shared
//!   between materials that reference the same files.
//! - A missing MTL file or texture is a warning in `scene.report.warnings`, never an error.
//!   Faces without a (known) material get [`DEFAULT_MATERIAL_COLOR`].

use std::cell::RefCell;
use std::collections::HashMap;
use std::path::{Component, Path, PathBuf};

use glam::{Mat4, Vec2, Vec3};
use image::{DynamicImage, GrayImage};

use super::{texture_from_image, Files, LoadError, MAX_TEXTURE_SIZE};
use crate::camera::Camera;
use crate::scene::{LoadReport, Material, Scene, Texture, TriangleSink};

/// Colour of faces that use no material (or one the MTL files do not define).
pub const DEFAULT_MATERIAL_COLOR: [f32; 3] = [0.8, 0.8, 0.8];
/// Alpha-test threshold for cut-out OBJ materials (three.js' `alphaTest = 0.5` for the same assets).
pub const OBJ_ALPHA_CUTOFF: f32 = 0.5;
/// At most this many MTL syntax warnings per file are listed (then a count).
const MAX_MTL_WARNINGS: usize = 8;

pub fn load(files: &dyn Files, path: &Path, m: Mat4) -> Result<Scene, LoadError> {
    let bytes = files.read(path).map_err(|e| LoadError::invalid(path, format!("cannot open OBJ file: {e}")))?;
    if bytes.is_empty() {
        return Err(LoadError::invalid(path, "empty OBJ file"));
    }
    // tobj multiplies out-of-range indices without overflow checks (a panic in debug builds),
    // so face indices are checked here first; this also gives the line number.
    check_face_indices(&bytes).map_err(|e| LoadError::invalid(path, e))?;
    let obj_dir = path.parent().map(Path::to_path_buf).unwrap_or_default();

    let mtl = RefCell::new(MtlState { files, materials: Vec::new(), warnings: Vec::new() });
    // more fields exist when tobj's `merging`/`reordering` features are on
    #[allow(clippy::needless_update)]
    let options =
        tobj::LoadOptions { triangulate: true, single_index: false, ignore_points: true, ignore_lines: true, ..Default::default() };
    let (models, _) = tobj::load_obj_buf(&mut &bytes[..], &options, |lib| mtl.borrow_mut().load_lib(&obj_dir, lib))
        .map_err(|e| LoadError::invalid(path, located(&bytes, &options, &e)))?;
    let MtlState { materials: mtl_materials, warnings, .. } = mtl.into_inner();

    if models.iter().all(|md| md.mesh.indices.is_empty()) {
        return Err(LoadError::invalid(path, "OBJ file has no faces"));
    }

    // Materials: one per MTL material (tobj's material ids index this list), default last.
    let mut textures = TextureCache::new(files);
    let mut materials: Vec<Material> = mtl_materials.iter().map(|mm| build_material(mm, &obj_dir, &mut textures)).collect();
    let mut default_material: Option<u32> = None;

    let mut sink = TriangleSink::default();
    let flip_winding = m.determinant() < 0.0;
    for model in &models {
        let mesh = &model.mesh;
        if mesh.indices.is_empty() {
            continue;
        }
        let material = match mesh.material_id.filter(|&id| id < materials.len()) {
            Some(id) => id as u32,
            None => *default_material.get_or_insert_with(|| {
                materials.push(Material::solid("default", DEFAULT_MATERIAL_COLOR));
                (materials.len() - 1) as u32
            }),
        };
        let positions: Vec<Vec3> = mesh.positions.chunks_exact(3).map(|p| m.transform_point3(Vec3::new(p[0], p[1], p[2]))).collect();
        let texcoords: Vec<Vec2> = mesh.texcoords.chunks_exact(2).map(|t| Vec2::new(t[0], 1.0 - t[1])).collect();
        let has_uv = !mesh.texcoord_indices.is_empty();
        if has_uv && mesh.texcoord_indices.len() != mesh.indices.len() {
            return Err(LoadError::invalid(path, format!("object '{}': texture coordinate indices do not match faces", model.name)));
        }
        for (t, tri) in mesh.indices.chunks_exact(3).enumerate() {
            let mut p = [Vec3::ZERO; 3];
            let mut uv = [Vec2::ZERO; 3];
            for k in 0..3 {
                p[k] = *positions
                    .get(tri[k] as usize)
                    .ok_or_else(|| LoadError::invalid(path, format!("object '{}': vertex index out of range", model.name)))?;
                if has_uv {
                    let ti = mesh.texcoord_indices[3 * t + k] as usize;
                    uv[k] = *texcoords.get(ti).ok_or_else(|| {
                        LoadError::invalid(path, format!("object '{}': texture coordinate index out of range", model.name))
                    })?;
                }
            }
            if flip_winding {
                p.swap(1, 2);
                uv.swap(1, 2);
            }
            sink.push(p, uv, material);
        }
    }

    let TriangleSink { vertices, report } = sink;
    Ok(Scene {
        name: path.file_stem().and_then(|s| s.to_str()).unwrap_or("scene").to_string(),
        vertices,
        materials,
        textures: textures.textures,
        camera: Camera::new(Vec3::ONE, Vec3::ZERO, 60.0, 0.1, 100.0),
        lights: Vec::new(),
        camera_path: Vec::new(),
        transform: Mat4::IDENTITY,
        animations: Vec::new(),
        report: LoadReport { warnings: [warnings, textures.warnings].concat(), ..report },
    })
}

/// tobj's error `e` with the line it comes from: the first line `n` such that the file's first
/// `n` lines fail to parse (tobj's errors are about one line and what precedes it, so this is
/// where it stopped). Only on the error path: about log2(lines) parses of a prefix.
fn located(bytes: &[u8], options: &tobj::LoadOptions, e: &tobj::LoadError) -> String {
    let ends: Vec<usize> = bytes.iter().enumerate().filter(|(_, b)| **b == b'\n').map(|(i, _)| i + 1).chain([bytes.len()]).collect();
    let fails = |n: usize| tobj::load_obj_buf(&mut &bytes[..ends[n - 1]], options, |_| Ok(Default::default())).is_err();
    let (mut lo, mut hi) = (1usize, ends.len());
    if !fails(hi) {
        return format!("malformed OBJ: {e}");
    }
    while lo < hi {
        let mid = lo + (hi - lo) / 2;
        if fails(mid) {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    let start = if lo > 1 { ends[lo - 2] } else { 0 };
    let text = String::from_utf8_lossy(&bytes[start..ends[lo - 1]]);
    let text: String = text.trim().chars().take(60).collect();
    format!("line {lo}: malformed OBJ: {e} ('{text}')")
}

/// Checks that every index of every `f`/`l` statement refers to an element defined before it
/// (1-based, or negative relative to the current count), as the OBJ format requires.
fn check_face_indices(text: &[u8]) -> Result<(), String> {
    const KINDS: [&str; 3] = ["vertex positions", "texture coordinates", "normals"];
    let mut counts = [0i64; 3];
    for (line_no, line) in text.split(|&b| b == b'\n').enumerate() {
        let mut words = line.split(u8::is_ascii_whitespace).filter(|w| !w.is_empty());
        match words.next() {
            Some(b"v") => counts[0] += 1,
            Some(b"vt") => counts[1] += 1,
            Some(b"vn") => counts[2] += 1,
            Some(b"f") | Some(b"l") => {
                for word in words {
                    for (k, part) in word.split(|&b| b == b'/').enumerate().take(3) {
                        // unparsable parts are left to tobj, which reports a parse error
                        let Some(x) = std::str::from_utf8(part).ok().and_then(|s| s.parse::<i64>().ok()) else {
                            continue;
                        };
                        let n = counts[k];
                        if x == 0 || x > n || x < -n {
                            return Err(format!("line {}: face index {x} out of bounds ({n} {} defined so far)", line_no + 1, KINDS[k]));
                        }
                    }
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// One `newmtl` block, as far as shadowlab uses it.
#[derive(Clone, Debug, Default)]
struct MtlMaterial {
    name: String,
    kd: Option<[f32; 3]>,
    d: Option<f32>,
    map_kd: Option<String>,
    map_d: Option<String>,
    /// Directory of the MTL file (texture paths are relative to it).
    dir: PathBuf,
}

struct MtlState<'f> {
    files: &'f dyn Files,
    /// All materials of all `mtllib`s, in the order tobj numbers them.
    materials: Vec<MtlMaterial>,
    warnings: Vec<String>,
}

impl MtlState<'_> {
    /// tobj's material loader: parses one `mtllib` statement's file(s). Never fails (a missing
    /// or unreadable MTL is a warning), so that the geometry still loads.
    fn load_lib(&mut self, obj_dir: &Path, lib: &Path) -> tobj::MTLLoadResult {
        let lib_str = lib.to_string_lossy();
        // `mtllib a.mtl b.mtl` is legal; a single name with spaces is common too.
        let mut names = vec![lib_str.to_string()];
        if resolve_path(self.files, &lib_str, &[obj_dir.to_path_buf()]).is_none() && lib_str.contains(char::is_whitespace) {
            names = lib_str.split_whitespace().map(str::to_string).collect();
        }
        let mut tobj_materials = Vec::new();
        let mut map: Vec<(String, usize)> = Vec::new();
        for name in names {
            let Some(file) = resolve_path(self.files, &name, &[obj_dir.to_path_buf()]) else {
                self.warnings.push(format!(
                    "material library '{name}' not found next to the OBJ file; its materials are replaced by the default material"
                ));
                continue;
            };
            let text = match self.files.read(&file) {
                Ok(bytes) => String::from_utf8_lossy(&bytes).into_owned(),
                Err(e) => {
                    self.warnings.push(format!("material library '{}' cannot be read ({e}); using the default material", file.display()));
                    continue;
                }
            };
            let dir = file.parent().map(Path::to_path_buf).unwrap_or_default();
            for mm in parse_mtl(&text, &file, dir, &mut self.warnings) {
                map.push((mm.name.clone(), tobj_materials.len()));
                tobj_materials.push(tobj::Material { name: mm.name.clone(), ..Default::default() });
                self.materials.push(mm);
            }
        }
        // Later definitions of a name win, as in tobj's own MTL loader.
        Ok((tobj_materials, map.into_iter().collect()))
    }
}

/// Parses the MTL statements shadowlab uses (`newmtl`, `Kd`, `d`, `map_Kd`, `map_d`); others are ignored.
fn parse_mtl(text: &str, file: &Path, dir: PathBuf, warnings: &mut Vec<String>) -> Vec<MtlMaterial> {
    let mut out: Vec<MtlMaterial> = Vec::new();
    let mut problems: Vec<String> = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = raw.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let (keyword, rest) = split_word(line);
        let keyword = keyword.to_ascii_lowercase();
        if keyword == "newmtl" {
            let name = rest.trim();
            out.push(MtlMaterial { name: name.to_string(), dir: dir.clone(), ..Default::default() });
            if name.is_empty() {
                problems.push(format!("line {}: newmtl without a name", i + 1));
            }
            continue;
        }
        if !matches!(keyword.as_str(), "kd" | "d" | "map_kd" | "map_d") {
            continue;
        }
        let Some(cur) = out.last_mut() else {
            problems.push(format!("line {}: '{keyword}' before any newmtl", i + 1));
            continue;
        };
        match keyword.as_str() {
            "kd" => match parse_floats(rest) {
                Some(v) if v.len() == 1 => cur.kd = Some([v[0]; 3]),
                Some(v) if v.len() == 3 => cur.kd = Some([v[0], v[1], v[2]]),
                _ => problems.push(format!("line {}: cannot read 'Kd {}'", i + 1, rest.trim())),
            },
            "d" => {
                let value = rest.trim().strip_prefix("-halo").unwrap_or(rest).trim();
                match value.parse::<f32>() {
                    Ok(d) if d.is_finite() => cur.d = Some(d.clamp(0.0, 1.0)),
                    _ => problems.push(format!("line {}: cannot read 'd {}'", i + 1, rest.trim())),
                }
            }
            _ => {
                let name = strip_map_options(rest);
                if name.is_empty() {
                    problems.push(format!("line {}: '{keyword}' without a file name", i + 1));
                } else if keyword == "map_kd" {
                    cur.map_kd = Some(name.to_string());
                } else {
                    cur.map_d = Some(name.to_string());
                }
            }
        }
    }
    let n = problems.len();
    for p in problems.into_iter().take(MAX_MTL_WARNINGS) {
        warnings.push(format!("{}: {p} (ignored)", file.display()));
    }
    if n > MAX_MTL_WARNINGS {
        warnings.push(format!("{}: {} more MTL problems ignored", file.display(), n - MAX_MTL_WARNINGS));
    }
    out
}

fn split_word(s: &str) -> (&str, &str) {
    let s = s.trim_start();
    match s.find(char::is_whitespace) {
        Some(i) => (&s[..i], &s[i..]),
        None => (s, ""),
    }
}

/// Whitespace-separated numbers; None if any token is not a finite number.
fn parse_floats(s: &str) -> Option<Vec<f32>> {
    s.split_whitespace().map(|w| w.parse::<f32>().ok().filter(|x| x.is_finite())).collect()
}

/// Drops the options of a `map_*` statement (`-bm 0.5 -o 0 0 0 file name.png`) and returns the
/// file name, which may contain spaces.
fn strip_map_options(s: &str) -> &str {
    let mut s = s.trim();
    while s.starts_with('-') {
        let (opt, rest) = split_word(s);
        let (words, numeric) = match opt.to_ascii_lowercase().as_str() {
            "-blendu" | "-blendv" | "-cc" | "-clamp" | "-imfchan" | "-type" => (1, false),
            "-bm" | "-boost" | "-texres" => (1, true),
            "-mm" => (2, true),
            "-o" | "-s" | "-t" => (3, true),
            _ => break, // not an option we know: treat the rest as the file name
        };
        s = rest.trim_start();
        for n in 0..words {
            let (w, r) = split_word(s);
            if w.is_empty() || (numeric && n > 0 && w.parse::<f32>().is_err()) {
                break;
            }
            s = r.trim_start();
        }
    }
    s.trim()
}

/// Finds `rel` (an MTL/OBJ path, possibly with Windows separators or in the wrong case) under
/// one of `dirs`; as a last resort, looks for the bare file name there.
fn resolve_path(files: &dyn Files, rel: &str, dirs: &[PathBuf]) -> Option<PathBuf> {
    let rel = rel.trim().trim_matches('"').replace('\\', "/");
    if rel.is_empty() {
        return None;
    }
    let p = Path::new(&rel);
    if p.is_absolute() && files.is_file(p) {
        return Some(p.to_path_buf());
    }
    for dir in dirs {
        let q = dir.join(p);
        if files.is_file(&q) {
            return Some(q);
        }
    }
    for dir in dirs {
        if let Some(q) = find_case_insensitive(files, dir, p) {
            return Some(q);
        }
    }
    let file_name = p.file_name()?;
    dirs.iter().map(|d| d.join(file_name)).find(|q| files.is_file(q))
}

fn find_case_insensitive(files: &dyn Files, dir: &Path, rel: &Path) -> Option<PathBuf> {
    let mut cur = if dir.as_os_str().is_empty() { PathBuf::from(".") } else { dir.to_path_buf() };
    for comp in rel.components() {
        match comp {
            Component::Normal(name) => {
                let direct = cur.join(name);
                if files.exists(&direct) {
                    cur = direct;
                    continue;
                }
                let want = name.to_string_lossy().to_lowercase();
                cur = files
                    .list(&cur)
                    .ok()?
                    .into_iter()
                    .find(|e| e.file_name().is_some_and(|n| n.to_string_lossy().to_lowercase() == want))?;
            }
            Component::ParentDir => cur.push(".."),
            Component::CurDir => {}
            _ => return None,
        }
    }
    files.is_file(&cur).then_some(cur)
}

/// Decoded source images and finished textures, shared by all materials of one load.
struct TextureCache<'f> {
    files: &'f dyn Files,
    images: HashMap<PathBuf, Option<DynamicImage>>,
    /// (map_Kd file, map_d file) -> texture index.
    combined: HashMap<(Option<PathBuf>, Option<PathBuf>), u32>,
    textures: Vec<Texture>,
    warnings: Vec<String>,
}

impl<'f> TextureCache<'f> {
    fn new(files: &'f dyn Files) -> Self {
        TextureCache { files, images: HashMap::new(), combined: HashMap::new(), textures: Vec::new(), warnings: Vec::new() }
    }

    /// Resolves and decodes a `map_*` file; None (with one warning per file) when it cannot be used.
    fn image(&mut self, material: &str, rel: &str, dirs: &[PathBuf]) -> Option<(PathBuf, DynamicImage)> {
        let Some(path) = resolve_path(self.files, rel, dirs) else {
            self.warnings.push(format!(
                "material '{material}': texture '{rel}' not found (looked in {}); the material is untextured",
                dirs.iter().map(|d| d.display().to_string()).collect::<Vec<_>>().join(", ")
            ));
            return None;
        };
        if !self.images.contains_key(&path) {
            let decoded = decode_image(self.files, &path);
            if let Err(e) = &decoded {
                self.warnings.push(format!(
                    "material '{material}': texture '{}' cannot be decoded ({e}); the material is untextured",
                    path.display()
                ));
            }
            self.images.insert(path.clone(), decoded.ok());
        }
        let img = self.images.get(&path)?.clone()?;
        Some((path, img))
    }
}

/// Decodes an image by its content, else by its file name's extension.
fn decode_image(files: &dyn Files, path: &Path) -> Result<DynamicImage, String> {
    let bytes = files.read(path).map_err(|e| e.to_string())?;
    let mut reader = image::ImageReader::new(std::io::Cursor::new(&bytes[..]));
    if let Ok(format) = image::ImageFormat::from_path(path) {
        reader.set_format(format);
    }
    reader.with_guessed_format().map_err(|e| e.to_string())?.decode().map_err(|e| e.to_string())
}

/// The map_d image as one alpha byte per texel: its alpha channel if it has one, else its luminance.
fn alpha_of(img: &DynamicImage) -> GrayImage {
    if img.color().has_alpha() {
        let rgba = img.to_rgba8();
        GrayImage::from_fn(rgba.width(), rgba.height(), |x, y| image::Luma([rgba.get_pixel(x, y)[3]]))
    } else {
        img.to_luma8()
    }
}

fn build_material(mm: &MtlMaterial, obj_dir: &Path, cache: &mut TextureCache<'_>) -> Material {
    let mut dirs = vec![mm.dir.clone()];
    if mm.dir != obj_dir {
        dirs.push(obj_dir.to_path_buf());
    }
    let kd_img = mm.map_kd.as_deref().and_then(|rel| cache.image(&mm.name, rel, &dirs));
    let d_img = mm.map_d.as_deref().and_then(|rel| cache.image(&mm.name, rel, &dirs));

    let key = (kd_img.as_ref().map(|(p, _)| p.clone()), d_img.as_ref().map(|(p, _)| p.clone()));
    let texture = if key == (None, None) {
        None
    } else if let Some(&t) = cache.combined.get(&key) {
        Some(t)
    } else {
        let tex = combine(kd_img.as_ref(), d_img.as_ref());
        cache.textures.push(tex);
        let t = (cache.textures.len() - 1) as u32;
        cache.combined.insert(key, t);
        Some(t)
    };

    let d = mm.d.unwrap_or(1.0);
    let texture_has_alpha = texture.is_some_and(|t| cache.textures[t as usize].rgba.chunks_exact(4).any(|px| px[3] < 255));
    let alpha_tested = d_img.is_some() || texture_has_alpha || d < 1.0;
    let kd = mm.kd.unwrap_or(if texture.is_some() { [1.0; 3] } else { DEFAULT_MATERIAL_COLOR });
    Material {
        name: mm.name.clone(),
        base_color: [kd[0], kd[1], kd[2], d],
        texture,
        alpha_cutoff: alpha_tested.then_some(OBJ_ALPHA_CUTOFF),
        double_sided: true,
    }
}

/// The diffuse texture with the map_d alpha written into it (white when there is no map_Kd).
fn combine(kd: Option<&(PathBuf, DynamicImage)>, d: Option<&(PathBuf, DynamicImage)>) -> Texture {
    let mut tex = match (kd, d) {
        (Some((p, img)), _) => texture_from_image(p.display().to_string(), img.clone()),
        (None, Some((p, img))) => {
            let a = alpha_of(img);
            let white = image::RgbaImage::from_pixel(a.width(), a.height(), image::Rgba([255, 255, 255, 255]));
            texture_from_image(format!("white+alpha({})", p.display()), DynamicImage::ImageRgba8(white))
        }
        (None, None) => unreachable!("combine() needs at least one image"),
    };
    if let Some((p, img)) = d {
        let mut alpha = alpha_of(img);
        if alpha.dimensions() != (tex.width, tex.height) {
            alpha = image::imageops::resize(&alpha, tex.width, tex.height, image::imageops::FilterType::Triangle);
        }
        for (px, a) in tex.rgba.chunks_exact_mut(4).zip(alpha.as_raw()) {
            px[3] = *a;
        }
        if kd.is_some() && kd.map(|(kp, _)| kp) != Some(p) {
            tex.name = format!("{}+alpha({})", tex.name, p.display());
        }
    }
    debug_assert!(tex.width.max(tex.height) <= MAX_TEXTURE_SIZE);
    tex
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn map_options_are_stripped() {
        assert_eq!(strip_map_options(" tex/a b.png "), "tex/a b.png");
        assert_eq!(strip_map_options("-bm 0.5 -o 0 0 0 -clamp on leaf.png"), "leaf.png");
        assert_eq!(strip_map_options("-s 2 2 bark.jpg"), "bark.jpg");
        assert_eq!(strip_map_options("-imfchan l alpha.tga"), "alpha.tga");
    }

    #[test]
    fn mtl_parsing_is_lenient() {
        let mut w = Vec::new();
        let text = "Kd 1 1 1\nnewmtl a\nKd 0.5\nd 0.25\nmap_Kd tex\\a.png\nnewmtl b\nKd 1 1\nd nope\nmap_D -bm 1 m.png\n";
        let m = parse_mtl(text, Path::new("x.mtl"), PathBuf::new(), &mut w);
        assert_eq!(m.len(), 2);
        assert_eq!(m[0].kd, Some([0.5; 3]));
        assert_eq!(m[0].d, Some(0.25));
        assert_eq!(m[0].map_kd.as_deref(), Some("tex\\a.png"));
        assert_eq!(m[1].kd, None);
        assert_eq!(m[1].map_d.as_deref(), Some("m.png"));
        assert_eq!(w.len(), 3, "{w:?}"); // Kd before newmtl, 'Kd 1 1', 'd nope'
    }
}
