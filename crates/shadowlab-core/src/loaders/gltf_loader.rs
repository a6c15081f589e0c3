//! glTF 2.0 (`.gltf` with external or data-URI buffers, `.glb`).
//!
//! The `gltf` crate parses and validates the JSON; buffers, accessors and images are read here
//! with every offset checked, because the crate's own readers assume valid data (they panic or
//! debug-assert on out-of-bounds accessors, zero counts and wrong element types, and
//! `gltf::import` fails the whole load when one image is missing).
//!
//! - The default scene (else the first, else all root nodes) is walked with the node
//!   transforms, then the user matrix `m`. Mirroring transforms keep the front faces.
//! - Triangle lists, strips and fans are loaded; points and lines are skipped with a warning.
//! - Material: base colour factor, base colour texture (its `texCoord` set, else zeros),
//!   `alphaMode` MASK -> `alpha_cutoff` (default 0.5), BLEND -> MASK at 0.5 (one warning),
//!   `doubleSided`. An image that cannot be loaded is a warning: the material is untextured.
//! - UVs keep glTF's top-left origin. Skins, morph targets, cameras and lights are ignored.

use std::collections::hash_map::Entry;
use std::collections::HashMap;
use std::io::Cursor;
use std::path::{Path, PathBuf};

use glam::{Mat4, Vec2, Vec3};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;
use gltf::Semantic;

use super::{texture_from_image, Files, LoadError};
use crate::camera::Camera;
use crate::scene::{LoadReport, Material, Scene, Texture, TriangleSink};

/// glTF's default `alphaCutoff` (spec), also used for BLEND materials.
pub const GLTF_DEFAULT_ALPHA_CUTOFF: f32 = 0.5;
/// Accessors without real data (sparse without a base view) may not claim more components than this.
const MAX_SYNTHETIC_COMPONENTS: usize = 1 << 24;
/// Node instances visited at most (guards against shared-children blow-ups in invalid files).
const MAX_NODE_VISITS: usize = 1 << 20;

pub fn load(files: &dyn Files, path: &Path, m: Mat4) -> Result<Scene, LoadError> {
    let fail = |msg: String| LoadError::invalid(path, msg);
    let data = files.read(path).map_err(|e| fail(format!("cannot read glTF file: {e}")))?;
    if data.is_empty() {
        return Err(fail("empty glTF file".into()));
    }
    let slice = if data.starts_with(b"glTF") { check_glb_header(&data).map_err(fail)? } else { &data[..] };
    let gltf = gltf::Gltf::from_slice_without_validation(slice).map_err(|e| fail(format!("invalid glTF: {e}")))?;
    let blob = gltf.blob;
    let mut json = gltf.document.into_json();
    precheck(&json).map_err(fail)?;
    let repaired = repair_images(&mut json);
    let doc = gltf::Document::from_json(json).map_err(|e| fail(format!("{e}")))?;
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let buffers = load_buffers(files, &doc, &base, blob).map_err(fail)?;

    let mut warnings = repaired;
    let mut loader = Loader { files, base: &base, buffers: &buffers, images: HashMap::new(), textures: Vec::new() };

    // Materials: index i is glTF material i; the spec's default material is appended on demand.
    let mut materials = Vec::new();
    let mut blend = Vec::new();
    for mat in doc.materials() {
        let name = mat.name().map(str::to_string).unwrap_or_else(|| format!("material{}", materials.len()));
        let pbr = mat.pbr_metallic_roughness();
        let texture = pbr.base_color_texture().and_then(|info| loader.image(info.texture().source(), &name, &mut warnings));
        let alpha_cutoff = match mat.alpha_mode() {
            gltf::material::AlphaMode::Opaque => None,
            gltf::material::AlphaMode::Mask => Some(mat.alpha_cutoff().unwrap_or(GLTF_DEFAULT_ALPHA_CUTOFF)),
            gltf::material::AlphaMode::Blend => {
                blend.push(name.clone());
                Some(GLTF_DEFAULT_ALPHA_CUTOFF)
            }
        };
        materials.push(Material { name, base_color: pbr.base_color_factor(), texture, alpha_cutoff, double_sided: mat.double_sided() });
    }
    if !blend.is_empty() {
        warnings.push(format!(
            "{} material(s) use alphaMode BLEND, treated as MASK with cutoff {GLTF_DEFAULT_ALPHA_CUTOFF}: {}",
            blend.len(),
            blend.join(", ")
        ));
    }
    if doc.extensions_used().any(|e| e == "KHR_texture_transform") {
        warnings.push("KHR_texture_transform is ignored (texture coordinates are used as stored)".into());
    }
    if doc.skins().next().is_some() {
        warnings.push("skins are ignored (meshes load in their bind pose)".into());
    }

    // Node instances of the scene.
    let roots: Vec<gltf::Node> = match doc.default_scene().or_else(|| doc.scenes().next()) {
        Some(scene) => scene.nodes().collect(),
        None => {
            let mut is_child = vec![false; doc.nodes().len()];
            for n in doc.nodes() {
                for c in n.children() {
                    is_child[c.index()] = true;
                }
            }
            if doc.meshes().len() > 0 {
                warnings.push("no scene in the file; loading all root nodes".into());
            }
            doc.nodes().filter(|n| !is_child[n.index()]).collect()
        }
    };
    let node_count = doc.nodes().len();
    let mut instances: Vec<(gltf::Mesh, Mat4)> = Vec::new();
    let mut stack: Vec<(gltf::Node, Mat4, usize)> = roots.into_iter().rev().map(|n| (n, Mat4::IDENTITY, 0)).collect();
    let mut visits = 0usize;
    while let Some((node, parent, depth)) = stack.pop() {
        if depth > node_count {
            return Err(fail(format!("nodes[{}]: the node hierarchy has a cycle through it", node.index())));
        }
        visits += 1;
        if visits > MAX_NODE_VISITS {
            return Err(fail("node hierarchy is too large (shared children?)".into()));
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if let Some(mesh) = node.mesh() {
            instances.push((mesh, world));
        }
        let children: Vec<_> = node.children().collect();
        stack.extend(children.into_iter().rev().map(|c| (c, world, depth + 1)));
    }

    let mut sink = TriangleSink::default();
    let mut default_material: Option<u32> = None;
    let mut skipped: HashMap<&'static str, usize> = HashMap::new();
    let mut cache: HashMap<(usize, usize), Primitive> = HashMap::new();
    for (mesh, world) in instances {
        let xf = m * world;
        let flip = xf.determinant() < 0.0;
        for prim in mesh.primitives() {
            let mode_name = match prim.mode() {
                Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan => None,
                Mode::Points => Some("points"),
                Mode::Lines => Some("lines"),
                Mode::LineLoop => Some("line loops"),
                Mode::LineStrip => Some("line strips"),
            };
            if let Some(mode_name) = mode_name {
                *skipped.entry(mode_name).or_default() += 1;
                continue;
            }
            let key = (mesh.index(), prim.index());
            let data = match cache.entry(key) {
                Entry::Occupied(e) => e.into_mut(),
                Entry::Vacant(e) => e.insert(
                    read_primitive(&prim, &buffers)
                        .map_err(|e| fail(format!("meshes[{}].primitives[{}]: {e}", mesh.index(), prim.index())))?,
                ),
            };
            let material = match prim.material().index() {
                Some(i) => i as u32,
                None => *default_material.get_or_insert_with(|| {
                    materials.push(Material {
                        name: "default".into(),
                        base_color: [1.0; 4],
                        texture: None,
                        alpha_cutoff: None,
                        double_sided: false,
                    });
                    (materials.len() - 1) as u32
                }),
            };
            let pos: Vec<Vec3> = data.positions.iter().map(|&p| xf.transform_point3(p)).collect();
            for tri in &data.triangles {
                let mut p = tri.map(|i| pos[i as usize]);
                let mut uv = tri.map(|i| data.uvs.get(i as usize).copied().unwrap_or(Vec2::ZERO));
                if flip {
                    p.swap(1, 2);
                    uv.swap(1, 2);
                }
                sink.push(p, uv, material);
            }
        }
    }
    let mut skipped: Vec<_> = skipped.into_iter().collect();
    skipped.sort();
    for (what, n) in skipped {
        warnings.push(format!("skipped {n} primitive instance(s) of {what} (only triangles are loaded)"));
    }

    let TriangleSink { vertices, report } = sink;
    Ok(Scene {
        name: path.file_stem().and_then(|s| s.to_str()).unwrap_or("scene").to_string(),
        vertices,
        materials,
        textures: loader.textures,
        camera: Camera::new(Vec3::ONE, Vec3::ZERO, 60.0, 0.1, 100.0),
        lights: Vec::new(),
        camera_path: Vec::new(),
        transform: Mat4::IDENTITY,
        animations: Vec::new(),
        report: LoadReport { warnings, ..report },
    })
}

/// The part of a GLB the header says exists; an error when the file is shorter (truncated).
fn check_glb_header(data: &[u8]) -> Result<&[u8], String> {
    if data.len() < 20 {
        return Err(format!("truncated GLB: {} bytes, less than the 12-byte header and a chunk header", data.len()));
    }
    let declared = u32::from_le_bytes([data[8], data[9], data[10], data[11]]) as usize;
    if declared < 20 {
        return Err(format!("invalid GLB: header declares {declared} bytes"));
    }
    if declared > data.len() {
        return Err(format!("truncated GLB: header declares {declared} bytes but the file has {}", data.len()));
    }
    Ok(&data[..declared])
}

/// Checks the gltf crate's validation would index without bounds checks (it indexes
/// `accessors[POSITION]` directly).
/// Images the spec forbids but the `gltf` crate would panic on (`Image::source` unwraps): one
/// with neither `uri` nor `bufferView` gets an empty URI (it then fails to load: a warning, the
/// material untextured), one with a `bufferView` and no `mimeType` an unknown type (its format
/// is guessed from its bytes). Found by the glTF fuzz target. Returns the warnings.
fn repair_images(json: &mut gltf::json::Root) -> Vec<String> {
    let mut warnings = Vec::new();
    for (i, image) in json.images.iter_mut().enumerate() {
        if image.buffer_view.is_some() && image.mime_type.is_none() {
            image.mime_type = Some(gltf::json::image::MimeType("application/octet-stream".into()));
            warnings.push(format!("images[{i}]: a bufferView without mimeType; its format is guessed from its bytes"));
        } else if image.buffer_view.is_none() && image.uri.is_none() {
            image.uri = Some(String::new());
            warnings.push(format!("images[{i}]: neither uri nor bufferView"));
        }
    }
    warnings
}

fn precheck(json: &gltf::json::Root) -> Result<(), String> {
    for (mi, mesh) in json.meshes.iter().enumerate() {
        for (pi, prim) in mesh.primitives.iter().enumerate() {
            for index in prim.attributes.values() {
                if index.value() >= json.accessors.len() {
                    return Err(format!(
                        "meshes[{mi}].primitives[{pi}].attributes: accessors[{}] out of range ({} accessors)",
                        index.value(),
                        json.accessors.len()
                    ));
                }
            }
        }
    }
    Ok(())
}

fn load_buffers(files: &dyn Files, doc: &gltf::Document, base: &Path, mut blob: Option<Vec<u8>>) -> Result<Vec<Vec<u8>>, String> {
    let mut buffers = Vec::new();
    for b in doc.buffers() {
        let data = match b.source() {
            gltf::buffer::Source::Bin => {
                blob.take().ok_or_else(|| format!("buffers[{}]: refers to the GLB binary chunk, which is missing", b.index()))?
            }
            gltf::buffer::Source::Uri(uri) => read_uri(files, uri, base).map_err(|e| format!("buffers[{}]: {e}", b.index()))?.bytes,
        };
        if data.len() < b.length() {
            return Err(format!("buffers[{}]: declares {} bytes but has {}", b.index(), b.length(), data.len()));
        }
        buffers.push(data);
    }
    Ok(buffers)
}

/// What a URI points to.
struct UriData {
    bytes: Vec<u8>,
    /// The data URI's MIME type, if any.
    mime: Option<String>,
    /// The file read, for a relative or `file:` URI.
    file: Option<PathBuf>,
}

/// Bytes of a data URI or of a file relative to `base`.
fn read_uri(files: &dyn Files, uri: &str, base: &Path) -> Result<UriData, String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (meta, payload) = rest.split_once(',').ok_or("malformed data URI (no ',')")?;
        let mime = meta.split(';').next().filter(|s| !s.is_empty()).map(str::to_string);
        let bytes = if meta.ends_with(";base64") { base64_decode(payload)? } else { percent_decode(payload) };
        return Ok(UriData { bytes, mime, file: None });
    }
    let rel = if let Some(rest) = uri.strip_prefix("file://").or_else(|| uri.strip_prefix("file:")) {
        rest
    } else if let Some(colon) = uri.find(':') {
        if !uri[..colon].contains('/') {
            return Err(format!("unsupported URI scheme in '{}'", uri.chars().take(64).collect::<String>()));
        }
        uri
    } else {
        uri
    };
    let decoded = String::from_utf8(percent_decode(rel)).map_err(|_| format!("URI '{uri}' is not valid UTF-8"))?;
    let path = base.join(decoded);
    let bytes = files.read(&path).map_err(|e| format!("cannot read '{}': {e}", path.display()))?;
    Ok(UriData { bytes, mime: None, file: Some(path) })
}

fn base64_decode(s: &str) -> Result<Vec<u8>, String> {
    let mut out = Vec::with_capacity(s.len() / 4 * 3 + 3);
    let (mut acc, mut bits) = (0u32, 0u32);
    for (i, c) in s.bytes().enumerate() {
        let v = match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            b'=' => break,
            b' ' | b'\t' | b'\r' | b'\n' => continue,
            _ => return Err(format!("invalid base64 character at offset {i} of a data URI")),
        };
        acc = (acc << 6) | u32::from(v);
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    Ok(out)
}

fn percent_decode(s: &str) -> Vec<u8> {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' {
            let hex = |c: u8| (c as char).to_digit(16);
            if let (Some(&h), Some(&l)) = (b.get(i + 1), b.get(i + 2)) {
                if let (Some(h), Some(l)) = (hex(h), hex(l)) {
                    out.push((h * 16 + l) as u8);
                    i += 3;
                    continue;
                }
            }
        }
        out.push(b[i]);
        i += 1;
    }
    out
}

/// One primitive's data in the mesh's own coordinates.
struct Primitive {
    positions: Vec<Vec3>,
    /// Empty when the primitive has no coordinates for the material's texture set.
    uvs: Vec<Vec2>,
    triangles: Vec<[u32; 3]>,
}

fn read_primitive(prim: &gltf::Primitive, buffers: &[Vec<u8>]) -> Result<Primitive, String> {
    let pos_acc = prim.get(&Semantic::Positions).ok_or("no POSITION attribute")?;
    if pos_acc.dimensions() != Dimensions::Vec3 {
        return Err(format!("attributes.POSITION: accessors[{}] is {:?}, expected VEC3", pos_acc.index(), pos_acc.dimensions()));
    }
    let positions: Vec<Vec3> = read_floats(&pos_acc, buffers)?.chunks_exact(3).map(|p| Vec3::new(p[0], p[1], p[2])).collect();
    let n = positions.len();

    let set = prim.material().pbr_metallic_roughness().base_color_texture().map_or(0, |t| t.tex_coord());
    let uvs = match prim.get(&Semantic::TexCoords(set)) {
        Some(acc) => {
            if acc.dimensions() != Dimensions::Vec2 {
                return Err(format!("attributes.TEXCOORD_{set}: accessors[{}] is {:?}, expected VEC2", acc.index(), acc.dimensions()));
            }
            let uv: Vec<Vec2> = read_floats(&acc, buffers)?.chunks_exact(2).map(|t| Vec2::new(t[0], t[1])).collect();
            if uv.len() != n {
                return Err(format!("attributes.TEXCOORD_{set}: {} elements but POSITION has {n}", uv.len()));
            }
            uv
        }
        None => Vec::new(),
    };

    let indices: Vec<u32> = match prim.indices() {
        Some(acc) => {
            if acc.dimensions() != Dimensions::Scalar {
                return Err(format!("indices: accessors[{}] is {:?}, expected SCALAR", acc.index(), acc.dimensions()));
            }
            let idx = read_indices(&acc, buffers)?;
            if let Some((k, &bad)) = idx.iter().enumerate().find(|(_, &i)| i as usize >= n) {
                return Err(format!("indices: accessors[{}] element {k} is index {bad}, out of range: {n} vertices", acc.index()));
            }
            idx
        }
        None => (0..n as u32).collect(),
    };
    let triangles = match prim.mode() {
        Mode::Triangles => indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect(),
        Mode::TriangleStrip => (0..indices.len().saturating_sub(2))
            .map(|i| {
                let t = [indices[i], indices[i + 1], indices[i + 2]];
                if i % 2 == 0 {
                    t
                } else {
                    [t[1], t[0], t[2]]
                }
            })
            .collect(),
        Mode::TriangleFan => (1..indices.len().saturating_sub(1)).map(|i| [indices[0], indices[i], indices[i + 1]]).collect(),
        _ => Vec::new(),
    };
    Ok(Primitive { positions, uvs, triangles })
}

/// Reads an accessor's components (`count * dimensions`), bounds-checked, sparse values applied.
fn read_components<T: Copy + Default>(acc: &gltf::Accessor, buffers: &[Vec<u8>], decode: impl Fn(&[u8]) -> T) -> Result<Vec<T>, String> {
    let id = acc.index();
    let count = acc.count();
    let dims = acc.dimensions().multiplicity();
    let comp = acc.data_type().size();
    let elem = dims * comp;
    let total = count.checked_mul(dims).ok_or_else(|| format!("accessors[{id}]: count {count} too large"))?;

    let mut out = Vec::new();
    match acc.view() {
        Some(view) => {
            let data = view_bytes(&view, buffers)?;
            let stride = view.stride().unwrap_or(elem);
            if stride < elem {
                return Err(format!("accessors[{id}]: byteStride {stride} is smaller than its element ({elem} bytes)"));
            }
            if count > 0 {
                let need = (count - 1)
                    .checked_mul(stride)
                    .and_then(|x| x.checked_add(elem))
                    .and_then(|x| x.checked_add(acc.offset()))
                    .ok_or_else(|| format!("accessors[{id}]: size overflows"))?;
                if need > data.len() {
                    return Err(format!(
                        "accessors[{id}]: out of bounds: needs {need} bytes of bufferViews[{}] which has {}",
                        view.index(),
                        data.len()
                    ));
                }
            }
            out.reserve_exact(total);
            for i in 0..count {
                let at = acc.offset() + i * stride;
                for c in 0..dims {
                    out.push(decode(&data[at + c * comp..at + (c + 1) * comp]));
                }
            }
        }
        None => {
            if total > MAX_SYNTHETIC_COMPONENTS {
                return Err(format!("accessors[{id}]: {count} elements without a bufferView"));
            }
            out.resize(total, T::default());
        }
    }

    if let Some(sparse) = acc.sparse() {
        let n = sparse.count();
        let idx_view = sparse.indices().view();
        let idx_type = sparse.indices().index_type();
        let isize_ = idx_type.size();
        let idx_data = view_bytes(&idx_view, buffers)?;
        let idx_off = sparse.indices().offset();
        let val_data = view_bytes(&sparse.values().view(), buffers)?;
        let val_off = sparse.values().offset();
        let fits = |off: usize, size: usize, len: usize| n.checked_mul(size).and_then(|x| x.checked_add(off)).is_some_and(|e| e <= len);
        if !fits(idx_off, isize_, idx_data.len()) || !fits(val_off, elem, val_data.len()) {
            return Err(format!("accessors[{id}].sparse: indices or values out of bounds"));
        }
        for k in 0..n {
            let b = &idx_data[idx_off + k * isize_..idx_off + (k + 1) * isize_];
            let target = match idx_type {
                gltf::accessor::sparse::IndexType::U8 => b[0] as usize,
                gltf::accessor::sparse::IndexType::U16 => u16::from_le_bytes([b[0], b[1]]) as usize,
                gltf::accessor::sparse::IndexType::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize,
            };
            if target >= count {
                return Err(format!("accessors[{id}].sparse: index {target} out of range ({count} elements)"));
            }
            for c in 0..dims {
                let at = val_off + k * elem + c * comp;
                out[target * dims + c] = decode(&val_data[at..at + comp]);
            }
        }
    }
    Ok(out)
}

fn view_bytes<'b>(view: &gltf::buffer::View, buffers: &'b [Vec<u8>]) -> Result<&'b [u8], String> {
    let buf = buffers
        .get(view.buffer().index())
        .ok_or_else(|| format!("bufferViews[{}]: no buffers[{}]", view.index(), view.buffer().index()))?;
    let end = view.offset().checked_add(view.length());
    match end {
        Some(end) if end <= buf.len() => Ok(&buf[view.offset()..end]),
        _ => Err(format!(
            "bufferViews[{}]: out of bounds: bytes {}+{} of buffers[{}] which has {}",
            view.index(),
            view.offset(),
            view.length(),
            view.buffer().index(),
            buf.len()
        )),
    }
}

/// Float attributes; integer components are converted (normalized when the accessor says so).
fn read_floats(acc: &gltf::Accessor, buffers: &[Vec<u8>]) -> Result<Vec<f32>, String> {
    let norm = acc.normalized();
    match acc.data_type() {
        DataType::F32 => read_components(acc, buffers, |b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        DataType::U8 => read_components(acc, buffers, |b| if norm { b[0] as f32 / 255.0 } else { b[0] as f32 }),
        DataType::I8 => read_components(acc, buffers, |b| {
            let v = b[0] as i8 as f32;
            if norm {
                (v / 127.0).max(-1.0)
            } else {
                v
            }
        }),
        DataType::U16 => read_components(acc, buffers, |b| {
            let v = u16::from_le_bytes([b[0], b[1]]) as f32;
            if norm {
                v / 65535.0
            } else {
                v
            }
        }),
        DataType::I16 => read_components(acc, buffers, |b| {
            let v = i16::from_le_bytes([b[0], b[1]]) as f32;
            if norm {
                (v / 32767.0).max(-1.0)
            } else {
                v
            }
        }),
        DataType::U32 => read_components(acc, buffers, |b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32),
    }
}

fn read_indices(acc: &gltf::Accessor, buffers: &[Vec<u8>]) -> Result<Vec<u32>, String> {
    match acc.data_type() {
        DataType::U8 => read_components(acc, buffers, |b| b[0] as u32),
        DataType::U16 => read_components(acc, buffers, |b| u16::from_le_bytes([b[0], b[1]]) as u32),
        DataType::U32 => read_components(acc, buffers, |b| u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        other => Err(format!("indices: accessors[{}] has component type {other:?}, expected an unsigned integer", acc.index())),
    }
}

struct Loader<'a> {
    files: &'a dyn Files,
    base: &'a Path,
    buffers: &'a [Vec<u8>],
    /// glTF image index -> scene texture index (None: could not be loaded, already warned).
    images: HashMap<usize, Option<u32>>,
    textures: Vec<Texture>,
}

impl Loader<'_> {
    fn image(&mut self, image: gltf::Image, material: &str, warnings: &mut Vec<String>) -> Option<u32> {
        let index = image.index();
        if let Some(&t) = self.images.get(&index) {
            return t;
        }
        let t = match self.decode(&image) {
            Ok(tex) => {
                self.textures.push(tex);
                Some((self.textures.len() - 1) as u32)
            }
            Err(e) => {
                warnings.push(format!("image {index} (used by material '{material}') cannot be loaded: {e}; the material is untextured"));
                None
            }
        };
        self.images.insert(index, t);
        t
    }

    fn decode(&self, image: &gltf::Image) -> Result<Texture, String> {
        let (bytes, mime, file, name) = match image.source() {
            gltf::image::Source::View { view, mime_type } => {
                let bytes = view_bytes(&view, self.buffers)?.to_vec();
                let name =
                    image.name().map(str::to_string).unwrap_or_else(|| format!("image{} (bufferView {})", image.index(), view.index()));
                (bytes, Some(mime_type.to_string()), None, name)
            }
            gltf::image::Source::Uri { uri, mime_type } => {
                let UriData { bytes, mime: data_mime, file } = read_uri(self.files, uri, self.base)?;
                let name = match &file {
                    Some(p) => p.display().to_string(),
                    None => image.name().map(str::to_string).unwrap_or_else(|| format!("image{} (data URI)", image.index())),
                };
                (bytes, data_mime.or(mime_type.map(str::to_string)), file, name)
            }
        };
        let mut reader = image::ImageReader::new(Cursor::new(&bytes[..])).with_guessed_format().map_err(|e| e.to_string())?;
        if reader.format().is_none() {
            let format = mime
                .as_deref()
                .and_then(image::ImageFormat::from_mime_type)
                .or_else(|| file.as_deref().and_then(|p| image::ImageFormat::from_path(p).ok()));
            match format {
                Some(f) => reader.set_format(f),
                None => return Err("unknown image format".into()),
            }
        }
        let img = reader.decode().map_err(|e| e.to_string())?;
        Ok(texture_from_image(name, img))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_and_percent() {
        assert_eq!(base64_decode("aGVsbG8=").unwrap(), b"hello");
        assert_eq!(base64_decode("aGVsbG8h").unwrap(), b"hello!");
        assert!(base64_decode("a$b").is_err());
        assert_eq!(percent_decode("a%20b%2"), b"a b%2");
        assert_eq!(percent_decode("%"), b"%");
    }

    #[test]
    fn glb_header_checks() {
        assert!(check_glb_header(b"glTF").is_err());
        let mut h = b"glTF\x02\0\0\0".to_vec();
        h.extend(100u32.to_le_bytes());
        h.extend([0u8; 20]);
        assert!(check_glb_header(&h).unwrap_err().contains("truncated"));
    }
}
