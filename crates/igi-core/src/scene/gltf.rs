//! glTF 2.0 meshes (`.gltf` JSON and `.glb` binary) for a scene's `[[mesh]]`, read with
//! the `gltf` crate into the loader's shapes: world-space [`Triangle`]s, materials by name
//! (diffuse + perfect mirror, see [`pbr_to_material`]) and KHR_lights_punctual point
//! lights as [`PointLight`]s in W/sr. The loader (`loader.rs`) calls [`load_gltf_bytes`]
//! for a mesh path ending in `.gltf` or `.glb` (any case, [`is_gltf_path`]) and merges the
//! result as it does an OBJ's: materials are resolved by name, so `[materials.NAME]`
//! overrides a glTF material key by key, and the glTF's lights join `[[point_light]]`s.
//!
//! The mapping (also in `docs/SCENE_FORMAT.md`, "glTF 2.0 meshes"):
//! - Geometry: every mesh primitive of the default scene (or the first scene) under its
//!   node's world matrix (the product of the local matrices down the hierarchy). Normals
//!   go through the inverse transpose; a mirroring matrix (negative determinant) swaps two
//!   vertices so that the winding stays counter-clockwise seen from the front, as the glTF
//!   spec asks. Modes TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN give triangles; POINTS and
//!   LINES* are skipped (one warning with the count). `NORMAL` gives shading normals.
//! - Materials: name = the glTF name, `gltf:<file stem>:<index>` when it has none,
//!   [`DEFAULT_MATERIAL`] for primitives without a material (or the mesh's
//!   `default_material`, which the loader applies). Base colour = `baseColorFactor.rgb`
//!   times the average linear colour of `baseColorTexture`.
//! - Lights: point lights, intensity (cd = lm/sr) / [`LUMENS_PER_WATT`] -> W/sr; spot and
//!   directional lights skipped with a warning.
//!
//! Errors are [`SceneError`]s with one-line messages naming the file (and the mesh,
//! primitive, accessor, node or buffer at fault). Nothing here panics on user data: the
//! gltf crate's readers index and assert on the ranges and types an accessor declares,
//! so every accessor is checked before it is read (`Reader::check_accessor`), the GLB
//! header and the POSITION indices (which gltf's validation indexes with `[]`) are checked
//! before the crate sees them, and the whole read runs under `catch_unwind` as a last
//! resort.

use std::collections::HashMap;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

use ::gltf::accessor::{DataType, Dimensions};
use ::gltf::khr_lights_punctual::Kind as LightKind;
use ::gltf::mesh::Mode;
use ::gltf::Semantic;
use glam::{Mat3, Mat4, Vec3};

use super::loader::{Location, SceneError};
use super::{PointLight, Triangle};

/// Luminous efficacy used to turn glTF photometric intensities (candela = lm/sr) into
/// radiant ones (W/sr): the 683 lm/W of the SI definition of the candela.
pub const LUMENS_PER_WATT: f32 = 683.0;

/// A metallic material is a perfect mirror only when its roughness is below this;
/// rougher metal is treated as diffuse (the renderer has no glossy lobe).
pub const MIRROR_MAX_ROUGHNESS: f32 = 0.2;

/// The material of primitives that name none (glTF's default material: base colour 1,
/// metallic 1, roughness 1, hence diffuse 1 and no mirror).
pub const DEFAULT_MATERIAL: &str = "gltf:default";

/// Vertices an accessor without a buffer view (sparse values over zeros) may declare: such
/// a count is not bounded by any buffer's size, and reading it allocates that many items.
const MAX_VIEWLESS_COUNT: usize = 1 << 26;

/// How many validation problems a message lists before "(and N more)".
const MAX_LISTED: usize = 3;

/// One material of a glTF file, as the file defines it (before `[materials.NAME]`).
#[derive(Clone, Debug, PartialEq)]
pub struct GltfMaterial {
    /// The glTF material's name, `gltf:<file stem>:<index>`, or [`DEFAULT_MATERIAL`].
    pub name: String,
    /// The glTF material index; `None` for the default material (primitives without one).
    pub index: Option<usize>,
    pub diffuse: Vec3,
    pub mirror: Vec3,
    /// Triangles that use it.
    pub triangles: usize,
}

/// What one glTF file contributes to a scene.
#[derive(Clone, Debug, Default)]
pub struct GltfMesh {
    /// World-space triangles, in scene order (depth-first over the nodes, primitives in
    /// order). [`Triangle::material`] indexes [`GltfMesh::materials`].
    pub triangles: Vec<Triangle>,
    /// The materials that primitives use, in order of first use.
    pub materials: Vec<GltfMaterial>,
    /// KHR_lights_punctual point lights of the scene, intensity in W/sr.
    pub lights: Vec<PointLight>,
    /// Files read besides the glTF file itself: external buffers and images.
    pub files: Vec<PathBuf>,
}

/// Whether `path` names a glTF file: it ends in `.gltf` or `.glb`, in any case.
pub fn is_gltf_path(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb"))
}

/// The diffuse albedo and mirror reflectance of a metallic-roughness material of base
/// colour `base` (linear RGB): smooth metal (roughness < [`MIRROR_MAX_ROUGHNESS`]) reflects
/// `base * metallic` as a mirror; the rest, `base * (1 - m)`, is diffuse, where m is
/// `metallic` for smooth metal and 0 otherwise. So `diffuse + mirror = base <= 1`.
pub fn pbr_to_material(base: Vec3, metallic: f32, roughness: f32) -> (Vec3, Vec3) {
    let m = if roughness < MIRROR_MAX_ROUGHNESS {
        metallic
    } else {
        0.0
    };
    (base * (1.0 - m), base * m)
}

/// Reads the glTF file at `path` (see [`load_gltf_bytes`]).
pub fn load_gltf(path: &Path) -> Result<GltfMesh, SceneError> {
    let bytes = super::loader::read_regular_file(path).map_err(|source| SceneError::Read {
        what: "mesh",
        path: path.to_path_buf(),
        context: None,
        error: source,
    })?;
    load_gltf_bytes(&bytes, path)
}

/// Reads a glTF file (JSON or GLB, told apart by the GLB magic, whatever the extension)
/// whose content is `bytes`; `path` names it in messages and locates its external buffers
/// and images (relative to its directory).
pub fn load_gltf_bytes(bytes: &[u8], path: &Path) -> Result<GltfMesh, SceneError> {
    let file = path.display().to_string();
    // A last resort: every known panic of the gltf crate is prevented by checks below.
    match catch_unwind(AssertUnwindSafe(|| read(bytes, path, &file))) {
        Ok(result) => result,
        Err(_) => Err(parse(
            &file,
            "internal error: the glTF reader (gltf crate) failed on this file",
        )),
    }
}

// ---------------------------------------------------------------------------------------
// Messages
// ---------------------------------------------------------------------------------------

/// Messages quote file contents: keep them on one line.
fn one_line(s: &str) -> String {
    s.chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect()
}

/// A string of the file (a name, a URI), shortened for a message.
fn excerpt(s: &str) -> String {
    const MAX: usize = 60;
    match s.char_indices().nth(MAX) {
        Some((i, _)) => format!("{}...", one_line(&s[..i])),
        None => one_line(s),
    }
}

fn at(file: &str) -> Location {
    Location {
        file: one_line(file),
        line: None,
        column: None,
    }
}

/// The file is not well-formed glTF (syntax, structure, references, byte ranges).
fn parse(file: &str, message: impl AsRef<str>) -> SceneError {
    SceneError::Parse {
        at: at(file),
        message: one_line(message.as_ref()),
    }
}

/// The file is well-formed but its values are not usable (non-finite, out of range).
fn invalid(file: &str, message: impl AsRef<str>) -> SceneError {
    SceneError::Invalid {
        at: at(file),
        message: one_line(message.as_ref()),
    }
}

fn fmt3(v: [f32; 3]) -> String {
    format!("[{}, {}, {}]", v[0], v[1], v[2])
}

/// "mesh 2" or "mesh 2 ('Chair')".
fn mesh_label(mesh: &::gltf::Mesh) -> String {
    match mesh.name() {
        Some(n) => format!("mesh {} ('{}')", mesh.index(), excerpt(n)),
        None => format!("mesh {}", mesh.index()),
    }
}

/// A serde_json error of the glTF JSON: its message without the " at line L column C"
/// tail, and the line and column (0 when unknown).
fn json_error(e: &::gltf::json::Error) -> (String, usize, usize) {
    let full = e.to_string();
    let tail = format!(" at line {} column {}", e.line(), e.column());
    let message = full.strip_suffix(&tail).unwrap_or(&full).to_string();
    (message, e.line(), e.column())
}

/// The first problems of a failed validation, with their JSON paths.
fn validation_message(
    problems: &[(::gltf::json::Path, ::gltf::json::validation::Error)],
) -> String {
    let listed: Vec<String> = problems
        .iter()
        .take(MAX_LISTED)
        .map(|(path, e)| format!("{path}: {}", e.to_string().to_lowercase()))
        .collect();
    let more = match problems.len().saturating_sub(MAX_LISTED) {
        0 => String::new(),
        n => format!(" (and {n} more)"),
    };
    format!("invalid glTF: {}{more}", listed.join("; "))
}

/// What is wrong with a GLB's structure (the crate's own messages omit the numbers).
fn glb_message(e: &::gltf::binary::Error) -> String {
    use ::gltf::binary::{ChunkType, Error as E};
    let chunk = |ty: &ChunkType| match ty {
        ChunkType::Json => "JSON",
        ChunkType::Bin => "BIN",
    };
    match e {
        E::Version(v) => format!("version {v} (only version 2 is read)"),
        E::Length {
            length,
            length_read,
        } => format!(
            "the header says {} bytes but the file has {}",
            u64::from(*length) + 12,
            length_read + 12
        ),
        E::ChunkLength {
            ty,
            length,
            length_read,
        } => format!(
            "the {} chunk says {length} bytes but only {length_read} follow",
            chunk(ty)
        ),
        E::ChunkType(ty) => format!(
            "unexpected {} chunk (a JSON chunk comes first, then at most one BIN chunk)",
            chunk(ty)
        ),
        E::UnknownChunkType(t) => format!(
            "unknown chunk type '{}'",
            one_line(&String::from_utf8_lossy(t))
        ),
        E::Io(e) => format!("truncated ({e})"),
        e => e.to_string(),
    }
}

/// A gltf crate error while reading the document, as a scene error.
fn document_error(e: ::gltf::Error, file: &str, is_glb: bool) -> SceneError {
    match e {
        ::gltf::Error::Deserialize(e) => {
            let (message, line, column) = json_error(&e);
            let what = if e.is_data() {
                "invalid glTF JSON"
            } else {
                "not a glTF file: cannot read its JSON"
            };
            if is_glb {
                parse(
                    file,
                    format!("{what} (GLB JSON chunk, line {line} column {column}): {message}"),
                )
            } else if line > 0 {
                SceneError::Parse {
                    at: Location {
                        file: one_line(file),
                        line: Some(line),
                        column: Some(column.max(1)),
                    },
                    message: one_line(&format!("{what}: {message}")),
                }
            } else {
                parse(file, format!("{what}: {message}"))
            }
        }
        ::gltf::Error::Binary(e) => parse(
            file,
            format!("not a valid GLB (binary glTF) file: {}", glb_message(&e)),
        ),
        ::gltf::Error::Validation(problems) => parse(file, validation_message(&problems)),
        e => parse(file, format!("cannot read the glTF file: {e}")),
    }
}

// ---------------------------------------------------------------------------------------
// Reading
// ---------------------------------------------------------------------------------------

/// Decodes `%XX` escapes of a relative URI. `None` when the result is not UTF-8 (the gltf
/// crate would panic on such a URI, so it never sees one).
fn percent_decode(uri: &str) -> Option<String> {
    let b = uri.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        if b[i] == b'%' && i + 2 < b.len() {
            if let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2])) {
                out.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8(out).ok()
}

/// The document, with the checks that keep the gltf crate from panicking on it.
fn document(bytes: &[u8], file: &str) -> Result<::gltf::Gltf, SceneError> {
    let is_glb = bytes.starts_with(b"glTF");
    if is_glb {
        // The crate subtracts 12 from the header's length field unchecked.
        if bytes.len() < 12 {
            return Err(parse(
                file,
                format!(
                    "not a valid GLB (binary glTF) file: {} bytes, shorter than the 12-byte header",
                    bytes.len()
                ),
            ));
        }
        let length = u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]);
        if length < 12 {
            return Err(parse(
                file,
                format!("not a valid GLB (binary glTF) file: the header's length {length} is less than 12"),
            ));
        }
    }
    let raw = ::gltf::Gltf::from_slice_without_validation(bytes).map_err(|e| {
        let e = document_error(e, file, is_glb);
        // A `.glb` that is neither GLB nor JSON: say that the magic is missing.
        let ext_glb = file.to_ascii_lowercase().ends_with(".glb");
        match e {
            SceneError::Parse { at, message } if ext_glb && !is_glb => SceneError::Parse {
                at,
                message: format!(
                    "no GLB header (the file does not start with 'glTF') and {message}"
                ),
            },
            e => e,
        }
    })?;
    let ::gltf::Gltf { document, blob } = raw;
    let root = document.into_json();
    // gltf 1.4's validation reads `accessors[POSITION]` with `[]`: check that index first.
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            let key = ::gltf::json::validation::Checked::Valid(Semantic::Positions);
            if let Some(index) = prim.attributes.get(&key) {
                if index.value() >= root.accessors.len() {
                    return Err(parse(
                        file,
                        format!(
                            "invalid glTF: meshes[{m}].primitives[{p}].attributes.POSITION = {}: index out of bounds (the file has {} accessors)",
                            index.value(),
                            root.accessors.len()
                        ),
                    ));
                }
            }
        }
    }
    let document =
        ::gltf::Document::from_json(root).map_err(|e| document_error(e, file, is_glb))?;
    Ok(::gltf::Gltf { document, blob })
}

fn read(bytes: &[u8], path: &Path, file: &str) -> Result<GltfMesh, SceneError> {
    let ::gltf::Gltf { document, blob } = document(bytes, file)?;
    let mut r = Reader {
        file: file.to_string(),
        dir: path.parent().unwrap_or(Path::new("")).to_path_buf(),
        stem: path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default(),
        buffers: Vec::new(),
        out: GltfMesh::default(),
        materials: HashMap::new(),
        textures: HashMap::new(),
        bad_images: image_problems(&document),
        warn: Warnings::default(),
    };
    r.load_buffers(&document, blob)?;
    let Some(scene) = document
        .default_scene()
        .or_else(|| document.scenes().next())
    else {
        return Err(invalid(file, "the glTF file has no scene to render"));
    };
    r.scene(&document, &scene)?;
    r.warn.log(file);
    Ok(r.out)
}

/// Images that `Image::source()` of gltf 1.4 would `unwrap()` a `None` of: it assumes a
/// `uri` when there is no `bufferView`, and a `mimeType` when there is one (a fuzzing find).
fn image_problems(doc: &::gltf::Document) -> HashMap<usize, &'static str> {
    let images = doc.as_json().images.iter().enumerate();
    images
        .filter_map(
            |(i, img)| match (&img.buffer_view, &img.uri, &img.mime_type) {
                (None, None, _) => Some((i, "the image has neither uri nor bufferView")),
                (Some(_), _, None) => Some((i, "the image has a bufferView but no mimeType")),
                _ => None,
            },
        )
        .collect()
}

/// Things skipped or repaired, reported once per file.
#[derive(Default)]
struct Warnings {
    /// Primitives of mode POINTS, LINES, LINE_LOOP, LINE_STRIP.
    not_triangles: usize,
    /// Index counts of TRIANGLES primitives that are not a multiple of 3.
    leftover_indices: usize,
    degenerate: usize,
    bad_normals: usize,
    /// Spot and directional lights.
    lights_skipped: usize,
    emissive: usize,
    skinned_or_morphed: usize,
}

impl Warnings {
    fn log(&self, file: &str) {
        let w = |n: usize, what: &str| {
            if n > 0 {
                log::warn!("{file}: {n} {what}");
            }
        };
        w(
            self.not_triangles,
            "primitives of mode POINTS or LINES* skipped (only triangles are rendered)",
        );
        w(
            self.leftover_indices,
            "TRIANGLES primitives whose index count is not a multiple of 3 (the last indices ignored)",
        );
        w(
            self.degenerate,
            "degenerate triangles (zero area, or a vertex made non-finite by its node transform) dropped",
        );
        w(
            self.bad_normals,
            "NORMAL values of zero length or not finite replaced by the geometric normal",
        );
        w(
            self.lights_skipped,
            "spot or directional lights skipped (the only light type is the point light)",
        );
        w(
            self.emissive,
            "materials with an emissive colour: emission ignored (surfaces do not emit)",
        );
        w(
            self.skinned_or_morphed,
            "skinned or morphed meshes: skins and morph targets ignored (the mesh as stored)",
        );
    }
}

struct Reader {
    file: String,
    /// The glTF file's directory: relative URIs start there.
    dir: PathBuf,
    /// File name without extension, for names of unnamed materials.
    stem: String,
    buffers: Vec<::gltf::buffer::Data>,
    out: GltfMesh,
    /// glTF material index (`None`: default material) -> index in `out.materials`.
    materials: HashMap<Option<usize>, usize>,
    /// Image index -> average linear colour (`None`: could not be decoded).
    textures: HashMap<usize, Option<Vec3>>,
    /// Images whose `Image::source()` would panic in the gltf crate (found by fuzzing:
    /// neither `uri` nor `bufferView`, or a `bufferView` without `mimeType`), with why.
    bad_images: HashMap<usize, &'static str>,
    warn: Warnings,
}

impl Reader {
    /// Where a `file:` or relative URI points (as the gltf crate resolves it).
    fn resolve_uri(&self, uri: &str) -> Result<PathBuf, String> {
        if let Some(rest) = uri
            .strip_prefix("file://")
            .or_else(|| uri.strip_prefix("file:"))
        {
            Ok(PathBuf::from(rest))
        } else if uri.contains(':') {
            Err(format!(
                "URI '{}' has an unsupported scheme (data:, file: and relative paths are read)",
                excerpt(uri)
            ))
        } else {
            percent_decode(uri)
                .map(|p| self.dir.join(p))
                .ok_or_else(|| format!("URI '{}' is not valid percent-encoded UTF-8", excerpt(uri)))
        }
    }

    /// Reads every buffer: the GLB's BIN chunk, `data:` URIs (by the gltf crate) and files
    /// (here, so that an error names the file).
    fn load_buffers(
        &mut self,
        doc: &::gltf::Document,
        mut blob: Option<Vec<u8>>,
    ) -> Result<(), SceneError> {
        use ::gltf::buffer::Source;
        for buffer in doc.buffers() {
            let i = buffer.index();
            let data = match buffer.source() {
                Source::Bin => blob.take().ok_or_else(|| {
                    parse(
                        &self.file,
                        format!("buffer {i} has no uri, so it is the GLB's BIN chunk, but the file has none"),
                    )
                })?,
                Source::Uri(uri) if uri.starts_with("data:") => {
                    ::gltf::buffer::Data::from_source(buffer.source(), None)
                        .map_err(|e| {
                            parse(
                                &self.file,
                                format!("buffer {i}: cannot decode its data: URI: {e}"),
                            )
                        })?
                        .0
                }
                Source::Uri(uri) => {
                    let p = self
                        .resolve_uri(uri)
                        .map_err(|m| parse(&self.file, format!("buffer {i}: {m}")))?;
                    let data = super::loader::read_regular_file(&p).map_err(|source| SceneError::Read {
                        what: "glTF buffer",
                        path: p.clone(),
                        context: Some(format!("buffer {i} of {}", self.file)),
                        error: source,
                    })?;
                    self.out.files.push(p);
                    data
                }
            };
            if data.len() < buffer.length() {
                return Err(parse(
                    &self.file,
                    format!(
                        "buffer {i}: byteLength is {} but its data has only {} bytes",
                        buffer.length(),
                        data.len()
                    ),
                ));
            }
            self.buffers.push(::gltf::buffer::Data(data));
        }
        Ok(())
    }

    /// Checks that `view` lies in its buffer's data.
    fn check_view(&self, view: &::gltf::buffer::View, label: &str) -> Result<(), SceneError> {
        let b = view.buffer().index();
        let buf_len = self.buffers.get(b).map_or(0, |d| d.0.len());
        let view_end = view.offset().checked_add(view.length());
        if view_end.is_none_or(|e| e > buf_len) {
            return Err(parse(
                &self.file,
                format!(
                    "{label}: buffer view {} (bytes {} + {}) lies outside buffer {b} ({buf_len} bytes)",
                    view.index(),
                    view.offset(),
                    view.length()
                ),
            ));
        }
        Ok(())
    }

    /// Checks that `count` elements of `size` bytes from `offset` in `view` (with its
    /// stride) lie in the view, and the view in its buffer's data: the gltf crate's
    /// readers slice and assert on these.
    fn check_range(
        &self,
        view: &::gltf::buffer::View,
        offset: usize,
        count: usize,
        size: usize,
        label: &str,
    ) -> Result<(), SceneError> {
        self.check_view(view, label)?;
        let stride = view.stride().unwrap_or(size);
        if stride < size {
            return Err(parse(
                &self.file,
                format!(
                    "{label}: buffer view {} has byteStride {stride}, smaller than one element ({size} bytes)",
                    view.index()
                ),
            ));
        }
        let end = count
            .checked_sub(1)
            .and_then(|c| c.checked_mul(stride))
            .and_then(|x| x.checked_add(size))
            .and_then(|x| x.checked_add(offset));
        if end.is_none_or(|e| e > view.length()) {
            return Err(parse(
                &self.file,
                format!(
                    "{label}: {count} elements of {size} bytes (stride {stride}) from byte {offset} do not fit in buffer view {} ({} bytes)",
                    view.index(),
                    view.length()
                ),
            ));
        }
        Ok(())
    }

    /// Checks what the gltf crate's reader of `acc` assumes: its type (the reader asserts
    /// the element size), a count of at least 1 (it computes `count - 1`), its byte
    /// ranges, and those of its sparse part.
    fn check_accessor(
        &self,
        acc: &::gltf::Accessor,
        what: &str,
        types: &[DataType],
        dims: Dimensions,
    ) -> Result<(), SceneError> {
        let label = format!("{what} (accessor {})", acc.index());
        if !types.contains(&acc.data_type()) || acc.dimensions() != dims {
            let expected: Vec<String> = types.iter().map(|t| format!("{t:?}")).collect();
            return Err(parse(
                &self.file,
                format!(
                    "{label} is {:?} of {:?}; expected {dims:?} of {}",
                    acc.dimensions(),
                    acc.data_type(),
                    expected.join(" or ")
                ),
            ));
        }
        let count = acc.count();
        if count == 0 {
            return Err(parse(&self.file, format!("{label} has count 0")));
        }
        let size = acc.size();
        match acc.view() {
            Some(view) => self.check_range(&view, acc.offset(), count, size, &label)?,
            None if count > MAX_VIEWLESS_COUNT => {
                return Err(parse(
                    &self.file,
                    format!("{label} has no bufferView and a count of {count} (at most {MAX_VIEWLESS_COUNT})"),
                ))
            }
            None => {}
        }
        if let Some(sparse) = acc.sparse() {
            let n = sparse.count();
            if n == 0 || n > count {
                return Err(parse(
                    &self.file,
                    format!(
                        "{label}: sparse count {n} must be from 1 to the accessor's count {count}"
                    ),
                ));
            }
            let indices = sparse.indices();
            self.check_range(
                &indices.view(),
                indices.offset(),
                n,
                indices.index_type().size(),
                &format!("{label} sparse indices"),
            )?;
            let values = sparse.values();
            self.check_range(
                &values.view(),
                values.offset(),
                n,
                size,
                &format!("{label} sparse values"),
            )?;
        }
        Ok(())
    }

    /// Walks the scene's node trees depth-first, each node's world matrix the product of
    /// the local ones from its root down.
    fn scene(&mut self, doc: &::gltf::Document, scene: &::gltf::Scene) -> Result<(), SceneError> {
        // An explicit stack (no recursion, so a deep file cannot overflow ours) and a
        // visited mark (the crate does not reject cycles, which would never end).
        let mut seen = vec![false; doc.nodes().len()];
        let mut stack: Vec<(::gltf::Node, Mat4)> = scene
            .nodes()
            .map(|n| (n, Mat4::IDENTITY))
            .collect::<Vec<_>>();
        stack.reverse();
        while let Some((node, parent)) = stack.pop() {
            let i = node.index();
            if std::mem::replace(&mut seen[i], true) {
                return Err(parse(
                    &self.file,
                    format!(
                        "node {i} is reached twice from scene {} (a cycle, or a node with two parents): the node hierarchy must be a tree",
                        scene.index()
                    ),
                ));
            }
            let local = Mat4::from_cols_array_2d(&node.transform().matrix());
            let world = parent * local;
            if !world.is_finite() {
                return Err(invalid(
                    &self.file,
                    format!("node {i}: its transform (or a parent's) is not finite"),
                ));
            }
            if let Some(mesh) = node.mesh() {
                if node.skin().is_some() || mesh.primitives().any(|p| p.morph_targets().len() > 0) {
                    self.warn.skinned_or_morphed += 1;
                }
                for prim in mesh.primitives() {
                    self.primitive(&mesh, &prim, &world)?;
                }
            }
            if let Some(light) = node.light() {
                self.light(&light, i, &world)?;
            }
            let children: Vec<_> = node.children().collect();
            stack.extend(children.into_iter().rev().map(|c| (c, world)));
        }
        Ok(())
    }

    /// A KHR_lights_punctual light at node `node`.
    fn light(
        &mut self,
        light: &::gltf::khr_lights_punctual::Light,
        node: usize,
        world: &Mat4,
    ) -> Result<(), SceneError> {
        if !matches!(light.kind(), LightKind::Point) {
            self.warn.lights_skipped += 1;
            return Ok(());
        }
        let color = light.color();
        let intensity = light.intensity();
        let valid = intensity.is_finite()
            && intensity >= 0.0
            && color.iter().all(|c| c.is_finite() && *c >= 0.0);
        if !valid {
            return Err(invalid(
                &self.file,
                format!(
                    "light {} (node {node}): color {} and intensity {intensity} must be finite numbers >= 0",
                    light.index(),
                    fmt3(color)
                ),
            ));
        }
        // Candela is lm/sr; at 683 lm/W it is 1/683 W/sr. The range cut-off is ignored:
        // the renderer's point lights fall off with the inverse square only.
        self.out.lights.push(PointLight {
            position: world.w_axis.truncate(),
            intensity: Vec3::from(color) * (intensity / LUMENS_PER_WATT),
        });
        Ok(())
    }

    /// The index in `out.materials` of `mat`, read on first use.
    fn material(&mut self, doc_mat: ::gltf::Material) -> Result<usize, SceneError> {
        let key = doc_mat.index();
        if let Some(&i) = self.materials.get(&key) {
            return Ok(i);
        }
        let name = match (key, doc_mat.name()) {
            (None, _) => DEFAULT_MATERIAL.to_string(),
            (Some(_), Some(n)) if !n.trim().is_empty() => n.to_string(),
            (Some(i), _) => format!("gltf:{}:{i}", self.stem),
        };
        let label = match key {
            Some(i) => format!("material {i} ('{}')", excerpt(&name)),
            None => format!("the default material ('{DEFAULT_MATERIAL}')"),
        };
        let pbr = doc_mat.pbr_metallic_roughness();
        let factor = pbr.base_color_factor();
        let base = [factor[0], factor[1], factor[2]];
        let metallic = pbr.metallic_factor();
        let roughness = pbr.roughness_factor();
        let unit = |x: f32| (0.0..=1.0).contains(&x);
        if !base.iter().all(|&x| unit(x)) {
            return Err(invalid(
                &self.file,
                format!("{label}: baseColorFactor {} must be in [0, 1]", fmt3(base)),
            ));
        }
        if !unit(metallic) || !unit(roughness) {
            return Err(invalid(
                &self.file,
                format!(
                    "{label}: metallicFactor {metallic} and roughnessFactor {roughness} must be in [0, 1]"
                ),
            ));
        }
        let mut base = Vec3::from(base);
        if let Some(info) = pbr.base_color_texture() {
            if let Some(avg) = self.texture_average(&info.texture().source(), &label) {
                base *= avg;
            }
        }
        if doc_mat.emissive_factor().iter().any(|&e| e != 0.0) {
            self.warn.emissive += 1;
        }
        let (diffuse, mirror) = pbr_to_material(base, metallic, roughness);
        let i = self.out.materials.len();
        self.out.materials.push(GltfMaterial {
            name,
            index: key,
            diffuse,
            mirror,
            triangles: 0,
        });
        self.materials.insert(key, i);
        Ok(i)
    }

    /// The average linear RGB of an image, decoded by the gltf crate; `None` (with a
    /// warning) when it cannot be read or decoded, and the base colour factor is used alone.
    fn texture_average(&mut self, image: &::gltf::image::Image, label: &str) -> Option<Vec3> {
        if let Some(&avg) = self.textures.get(&image.index()) {
            return avg;
        }
        let avg = match self.decode(image) {
            Ok(data) => {
                let avg = average_linear(&data);
                if avg.is_none() {
                    log::warn!(
                        "{}: {label}: baseColorTexture image {} has no texels; its factor is used alone",
                        self.file,
                        image.index()
                    );
                }
                avg
            }
            Err(why) => {
                log::warn!(
                    "{}: {label}: cannot decode baseColorTexture image {}: {}; its factor is used alone",
                    self.file,
                    image.index(),
                    one_line(&why)
                );
                None
            }
        };
        self.textures.insert(image.index(), avg);
        avg
    }

    fn decode(&mut self, image: &::gltf::image::Image) -> Result<::gltf::image::Data, String> {
        use ::gltf::image::Source;
        if let Some(&why) = self.bad_images.get(&image.index()) {
            return Err(why.to_string());
        }
        let mut file = None;
        match image.source() {
            Source::View { view, .. } => {
                // The crate slices the buffer with the view's range unchecked.
                self.check_view(&view, "image").map_err(|e| match e {
                    SceneError::Parse { message, .. } => message,
                    e => e.to_string(),
                })?;
            }
            Source::Uri { uri, .. } if uri.starts_with("data:") => {}
            Source::Uri { uri, .. } => {
                let p = self.resolve_uri(uri)?;
                if !p.is_file() {
                    return Err(format!("'{}' is not a file", p.display()));
                }
                file = Some(p);
            }
        }
        let decoded = catch_unwind(AssertUnwindSafe(|| {
            ::gltf::image::Data::from_source(image.source(), Some(&self.dir), &self.buffers)
        }));
        let data = match decoded {
            Ok(Ok(data)) => data,
            Ok(Err(e)) => return Err(e.to_string()),
            Err(_) => return Err("the image decoder failed".to_string()),
        };
        if let Some(p) = file {
            self.out.files.push(p);
        }
        Ok(data)
    }

    /// One primitive of `mesh` under the world matrix `world`: appends its triangles.
    fn primitive(
        &mut self,
        mesh: &::gltf::Mesh,
        prim: &::gltf::Primitive,
        world: &Mat4,
    ) -> Result<(), SceneError> {
        let what = format!("{} primitive {}", mesh_label(mesh), prim.index());
        let mode = prim.mode();
        if !matches!(
            mode,
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
        ) {
            self.warn.not_triangles += 1;
            return Ok(());
        }
        let Some(pos_acc) = prim.get(&Semantic::Positions) else {
            return Err(parse(&self.file, format!("{what} has no POSITION")));
        };
        self.check_accessor(
            &pos_acc,
            &format!("{what} POSITION"),
            &[DataType::F32],
            Dimensions::Vec3,
        )?;
        let nrm_acc = prim.get(&Semantic::Normals);
        if let Some(acc) = &nrm_acc {
            self.check_accessor(
                acc,
                &format!("{what} NORMAL"),
                &[DataType::F32],
                Dimensions::Vec3,
            )?;
            if acc.count() != pos_acc.count() {
                return Err(parse(
                    &self.file,
                    format!(
                        "{what}: NORMAL has {} elements but POSITION has {}",
                        acc.count(),
                        pos_acc.count()
                    ),
                ));
            }
        }
        if let Some(acc) = prim.indices() {
            self.check_accessor(
                &acc,
                &format!("{what} indices"),
                &[DataType::U8, DataType::U16, DataType::U32],
                Dimensions::Scalar,
            )?;
        }

        let buffers = &self.buffers;
        let reader = prim.reader(|b| buffers.get(b.index()).map(|d| d.0.as_slice()));
        let internal = |of: &str| {
            parse(
                &self.file,
                format!("{what}: internal error: cannot read the {of} accessor"),
            )
        };
        let positions: Vec<Vec3> = reader
            .read_positions()
            .ok_or_else(|| internal("POSITION"))?
            .map(Vec3::from)
            .collect();
        let normals: Option<Vec<Vec3>> = match &nrm_acc {
            Some(_) => Some(
                reader
                    .read_normals()
                    .ok_or_else(|| internal("NORMAL"))?
                    .map(Vec3::from)
                    .collect(),
            ),
            None => None,
        };
        let indices: Vec<u32> = match prim.indices() {
            Some(_) => reader
                .read_indices()
                .ok_or_else(|| internal("indices"))?
                .into_u32()
                .collect(),
            None => (0..positions.len() as u32).collect(),
        };
        let nv = positions.len();
        if let Some((k, &i)) = indices.iter().enumerate().find(|(_, &i)| i as usize >= nv) {
            return Err(parse(
                &self.file,
                format!("{what}: index {i} (element {k} of the indices) out of range: POSITION has {nv} vertices"),
            ));
        }

        let corners = triangulate(mode, &indices);
        if mode == Mode::Triangles && !indices.len().is_multiple_of(3) {
            self.warn.leftover_indices += 1;
        }
        let material = self.material(prim.material())?;

        // Normals go through the cofactor matrix, det * M^-T: defined even when M is
        // singular, and with the sign of det undone it is the inverse transpose's direction.
        let m3 = Mat3::from_mat4(*world);
        let det = m3.determinant();
        let mirrored = det < 0.0;
        let (c0, c1, c2) = (m3.x_axis, m3.y_axis, m3.z_axis);
        let mut normal_matrix = Mat3::from_cols(c1.cross(c2), c2.cross(c0), c0.cross(c1));
        if mirrored {
            normal_matrix = -normal_matrix;
        }

        let mut count = 0usize;
        for mut t in corners {
            if mirrored {
                // The glTF spec: a negative determinant makes front faces clockwise; keep
                // the geometric normal on the side of the (inverse transposed) normals.
                t.swap(1, 2);
            }
            let local = t.map(|i| positions[i as usize]);
            if let Some(k) = (0..3).find(|&k| !local[k].is_finite()) {
                return Err(invalid(
                    &self.file,
                    format!(
                        "{what}: a triangle uses vertex {} whose position {} is not finite",
                        t[k],
                        fmt3(local[k].into())
                    ),
                ));
            }
            let v = local.map(|p| world.transform_point3(p));
            // A world transform may still make a vertex non-finite: then it is dropped too.
            let Some(ng) = super::geometric_normal(&v) else {
                self.warn.degenerate += 1;
                continue;
            };
            let mut n = [ng; 3];
            if let Some(normals) = &normals {
                for (k, nk) in n.iter_mut().enumerate() {
                    match (normal_matrix * normals[t[k] as usize]).try_normalize() {
                        Some(x) => *nk = x,
                        None => self.warn.bad_normals += 1,
                    }
                }
            }
            self.out.triangles.push(Triangle {
                v,
                n,
                material: material as u32,
            });
            count += 1;
        }
        self.out.materials[material].triangles += count;
        Ok(())
    }
}

/// The triangles of a primitive's vertex list, per the glTF spec: TRIANGLES in threes
/// (a remainder ignored), TRIANGLE_STRIP `{i, i + 1 + i % 2, i + 2 - i % 2}` (every
/// triangle counter-clockwise), TRIANGLE_FAN `{i + 1, i + 2, 0}`.
fn triangulate(mode: Mode, idx: &[u32]) -> Vec<[u32; 3]> {
    let n = idx.len();
    match mode {
        Mode::Triangles => idx.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        Mode::TriangleStrip => (0..n.saturating_sub(2))
            .map(|i| [idx[i], idx[i + 1 + i % 2], idx[i + 2 - i % 2]])
            .collect(),
        Mode::TriangleFan => (0..n.saturating_sub(2))
            .map(|i| [idx[i + 1], idx[i + 2], idx[0]])
            .collect(),
        _ => Vec::new(),
    }
}

/// The sRGB transfer function undone (IEC 61966-2-1).
fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The mean linear RGB of an image's texels: integer texels are sRGB-encoded (the glTF
/// spec for baseColorTexture) and are decoded one by one before averaging (averaging the
/// encoded values would darken); grey images count as equal RGB; alpha is ignored.
fn average_linear(data: &::gltf::image::Data) -> Option<Vec3> {
    use ::gltf::image::Format as F;
    let (channels, bytes) = match data.format {
        F::R8 => (1, 1),
        F::R8G8 => (2, 1),
        F::R8G8B8 => (3, 1),
        F::R8G8B8A8 => (4, 1),
        F::R16 => (1, 2),
        F::R16G16 => (2, 2),
        F::R16G16B16 => (3, 2),
        F::R16G16B16A16 => (4, 2),
        F::R32G32B32FLOAT => (3, 4),
        F::R32G32B32A32FLOAT => (4, 4),
    };
    let lut: Vec<f32> = (0..256).map(|v| srgb_to_linear(v as f32 / 255.0)).collect();
    // The crate's pixels are the decoder's samples in native byte order.
    let value = |s: &[u8]| -> f32 {
        match bytes {
            1 => lut[s[0] as usize],
            2 => srgb_to_linear(f32::from(u16::from_ne_bytes([s[0], s[1]])) / 65535.0),
            _ => f32::from_ne_bytes([s[0], s[1], s[2], s[3]]),
        }
    };
    let texel = channels * bytes;
    let mut sum = [0f64; 3];
    let mut n = 0usize;
    for px in data.pixels.chunks_exact(texel) {
        for (c, s) in sum.iter_mut().enumerate() {
            let ch = if channels >= 3 { c } else { 0 };
            *s += f64::from(value(&px[ch * bytes..(ch + 1) * bytes]));
        }
        n += 1;
    }
    if n == 0 {
        return None;
    }
    let avg = Vec3::new(
        (sum[0] / n as f64) as f32,
        (sum[1] / n as f64) as f32,
        (sum[2] / n as f64) as f32,
    );
    // Float images (not produced by PNG or JPEG) could hold anything: keep an albedo.
    avg.is_finite().then(|| avg.clamp(Vec3::ZERO, Vec3::ONE))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strips_and_fans_keep_the_winding() {
        let idx = [0, 1, 2, 3, 4];
        assert_eq!(
            triangulate(Mode::TriangleStrip, &idx),
            [[0, 1, 2], [1, 3, 2], [2, 3, 4]]
        );
        assert_eq!(
            triangulate(Mode::TriangleFan, &idx),
            [[1, 2, 0], [2, 3, 0], [3, 4, 0]]
        );
        assert_eq!(triangulate(Mode::Triangles, &idx), [[0, 1, 2]]);
        assert!(triangulate(Mode::TriangleStrip, &idx[..2]).is_empty());
    }

    #[test]
    fn percent_decoding() {
        assert_eq!(percent_decode("a%20b.bin").as_deref(), Some("a b.bin"));
        assert_eq!(percent_decode("100%.bin").as_deref(), Some("100%.bin"));
        assert_eq!(percent_decode("x%4"), Some("x%4".to_string()));
        assert_eq!(percent_decode("%FF.bin"), None);
    }

    #[test]
    fn srgb_decoding() {
        assert_eq!(srgb_to_linear(0.0), 0.0);
        assert!((srgb_to_linear(1.0) - 1.0).abs() < 1e-6);
        assert!((srgb_to_linear(0.5) - 0.214_041).abs() < 1e-5);
    }

    #[test]
    fn gltf_paths() {
        assert!(is_gltf_path(Path::new("a/b.GLTF")));
        assert!(is_gltf_path(Path::new("b.glb")));
        assert!(!is_gltf_path(Path::new("b.obj")));
        assert!(!is_gltf_path(Path::new("gltf")));
    }
}
