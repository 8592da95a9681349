//! Scene loader: the TOML scene description of `shared/SCENE_FORMAT.md` and its Wavefront
//! OBJ/MTL meshes, read and validated into a [`Scene`].
//!
//! Every failure is a [`SceneError`] whose message is one line that names the file (and the
//! line, and for TOML the column, where known), e.g.
//! `scenes/box/box.obj:123: face index 999 out of range (the file has 456 vertices)`.
//! Nothing in here panics on user data.
//!
//! Choices where the contract leaves room (they follow the reference converter
//! `shared/tools/scene_to_mitsuba.py`, so that a scene means the same thing to both):
//! - `[film]` is optional, and so is each of its keys: 800 x 600 by default ([`DEFAULT_FILM`]).
//! - `camera.up` is optional: +y by default. `eye`, `target` and `fov_y_deg` are required.
//! - At least one `[[mesh]]`, one light (`[[point_light]]` or a glTF mesh's point light)
//!   and one (non-degenerate) triangle.
//! - [`Scene::materials`] holds the materials that triangles use, each name once across all
//!   meshes, in order of first use. A `[materials.NAME]` table that no face uses is still
//!   validated, then dropped with a warning (often a misspelt name).
//! - A material name defined by several MTL files takes its first definition (meshes in
//!   scene order, `mtllib` lines in file order); within one MTL file the last one wins.
//! - A `mtllib` file that does not exist is an error only if a material that faces use is
//!   then defined nowhere (the message names the missing file); otherwise it is a warning,
//!   so that a scene may define all of a mesh's materials in its TOML.
//! - Faces with one or two vertices are ignored (with a warning), `l` polylines too.
//! - A face index beyond the file's count is an error naming the line; negative indices
//!   count back from the vertices declared before the line. Forward references (a face
//!   before its vertices) work within one object or group (a limit of tobj).
//! - A face uses its `vn` normals only if every corner has one (otherwise the geometric
//!   normal); `vn` of zero length fall back to the geometric normal.
//! - Degenerate triangles (zero area, judged in f64 so that a large valid triangle whose
//!   f32 cross product overflows is kept) are dropped with a warning; non-finite vertex
//!   coordinates used by a face are an error.
//! - A light may emit nothing (intensity 0); a light whose power 4 pi (r + g + b), or the
//!   sum of all lights' power, is beyond f32 is an error (the renderer sums it in f32 to
//!   choose lights; an infinite sum made every pixel NaN).
//! - Vectors are exactly three numbers, each within the f32 range (quoted as written
//!   otherwise). In OBJ and MTL files a `#` that starts a word starts a comment, on every
//!   kind of line (`strip_comments`).
//! - A TOML file must be UTF-8. In OBJ and MTL files a NUL byte is an error (binary data),
//!   other bytes that are not UTF-8 (a Latin-1 comment) are replaced, with a warning.
//!
//! OBJ files are read with `tobj` (`load_obj_buf`, fanning polygons, separate
//! position/normal indices, points and lines ignored), preceded by our own fast pass over
//! the text (`scan_obj`). That pass exists because tobj 4.0.5 reports no line numbers, and
//! because of four behaviours of tobj that would otherwise be wrong for us: a `usemtl` name
//! that its MTL files do not define becomes "no material" (the name is lost, yet the name
//! may be defined in the TOML); a face corner without a `vn` index gets some other vertex's
//! normal when the file has normals; a texture or normal index of 0 or out of range
//! overflows an index computation (a panic in debug builds); and `l` lines of three or more
//! vertices come out as triangles. The pass validates every face index (with its line),
//! records per triangle whether it has complete normals or comes from an `l` line, and lists
//! the `usemtl` names; a synthetic first line `mtllib <names>` makes tobj resolve every one
//! of those names to our own table. MTL files are checked line by line before
//! `tobj::load_mtl_buf` reads them, because tobj panics on a `Kd` with fewer than three
//! numbers.

use std::borrow::Cow;
use std::collections::{BTreeMap, HashMap, HashSet};
use std::io::{self, Read};
use std::ops::Range;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

use glam::{DVec3, Vec3};
use serde::Deserialize;
use toml::Spanned;

use super::{Camera, Film, Material, PointLight, Scene, Triangle};

/// Image size when the scene file has no `[film]` (or leaves a key out).
pub const DEFAULT_FILM: Film = Film {
    width: 800,
    height: 600,
};

/// `camera.up` when the scene file leaves it out.
pub const DEFAULT_UP: Vec3 = Vec3::Y;

/// Coordinates beyond which ray tests may overflow (2^62, ~4.6e18; an edge of 9e18 was
/// already missed on lavapipe).
const FAR_COORDINATE: f32 = 4.611686e18;

/// Slack allowed on `diffuse + mirror <= 1` (per channel), for values written with few
/// digits such as 0.35 + 0.65.
const ALBEDO_SLACK: f32 = 1e-6;

// ---------------------------------------------------------------------------------------
// Errors
// ---------------------------------------------------------------------------------------

/// Where in which file an error is: `file`, `file:line` or `file:line:column` (1-based).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Location {
    pub file: String,
    pub line: Option<usize>,
    pub column: Option<usize>,
}

impl Location {
    fn file(file: &str) -> Self {
        Location {
            file: one_line(file),
            line: None,
            column: None,
        }
    }

    fn line(file: &str, line: usize) -> Self {
        Location {
            line: Some(line),
            ..Location::file(file)
        }
    }

    /// The line and column (in characters) of byte `offset` of `text`.
    fn offset(file: &str, text: &str, offset: usize) -> Self {
        let mut offset = offset.min(text.len());
        while !text.is_char_boundary(offset) {
            offset -= 1;
        }
        let before = &text[..offset];
        let line = before.matches('\n').count() + 1;
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        Location {
            line: Some(line),
            column: Some(before[line_start..].chars().count() + 1),
            ..Location::file(file)
        }
    }
}

impl std::fmt::Display for Location {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.file)?;
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
            if let Some(column) = self.column {
                write!(f, ":{column}")?;
            }
        }
        Ok(())
    }
}

/// Why a scene could not be loaded. Its `Display` is one line naming the file.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// A file could not be read: missing, unreadable, a directory.
    #[error("cannot read {what} '{}'{}: {}", one_line(&.path.display().to_string()), context_suffix(.context), io_message(.error))]
    Read {
        /// "scene file", "mesh" or "material library".
        what: &'static str,
        path: PathBuf,
        /// Who referenced the file, e.g. "referenced by scene.toml".
        context: Option<String>,
        /// The cause, whose message the error's own includes (so it is not also its
        /// `source()`, which would print it twice in a chain of causes).
        error: io::Error,
    },
    /// The file is not well-formed: TOML syntax or types, OBJ or MTL syntax, not text.
    #[error("{at}: {message}")]
    Parse { at: Location, message: String },
    /// The file is well-formed but describes no valid scene (a value out of range, a
    /// material defined nowhere, no lights, ...).
    #[error("{at}: {message}")]
    Invalid { at: Location, message: String },
}

impl SceneError {
    fn parse(at: Location, message: impl AsRef<str>) -> Self {
        SceneError::Parse {
            at,
            message: one_line(message.as_ref()),
        }
    }

    fn invalid(at: Location, message: impl AsRef<str>) -> Self {
        SceneError::Invalid {
            at,
            message: one_line(message.as_ref()),
        }
    }

    /// Where the error is, when it is in a file's content.
    pub fn location(&self) -> Option<&Location> {
        match self {
            SceneError::Read { .. } => None,
            SceneError::Parse { at, .. } | SceneError::Invalid { at, .. } => Some(at),
        }
    }
}

fn context_suffix(context: &Option<String>) -> String {
    match context {
        Some(c) => format!(" ({})", one_line(c)),
        None => String::new(),
    }
}

/// The OS message without its " (os error 2)" tail: "No such file or directory".
fn io_message(e: &io::Error) -> String {
    one_line(without_os_error_code(&e.to_string()))
}

/// `text` without the " (os error 2)" tail that Rust adds to an OS error's message (the
/// message says it in words); the `igi` command drops it from every error it prints.
pub fn without_os_error_code(text: &str) -> &str {
    match text.rfind(" (os error ") {
        Some(i) if text.ends_with(')') => &text[..i],
        _ => text,
    }
}

/// Messages quote file contents and paths: keep them on one line.
fn one_line(s: &str) -> String {
    s.chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect()
}

/// A line of a file, shortened for a message.
fn excerpt(line: &str) -> String {
    const MAX: usize = 60;
    let line = line.trim();
    match line.char_indices().nth(MAX) {
        Some((i, _)) => format!("{}...", one_line(&line[..i])),
        None => one_line(line),
    }
}

fn fmt3(v: [f32; 3]) -> String {
    format!("[{}, {}, {}]", v[0], v[1], v[2])
}

const CHANNELS: [&str; 3] = ["red", "green", "blue"];

/// The line (1-based) of byte `offset`.
fn line_at(bytes: &[u8], offset: usize) -> usize {
    bytes[..offset.min(bytes.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// The TOML file as text (TOML must be UTF-8), or an error naming the line of the first
/// byte that is not UTF-8.
fn as_text<'a>(bytes: &'a [u8], file: &str) -> Result<&'a str, SceneError> {
    match std::str::from_utf8(bytes) {
        Ok(text) => Ok(text.strip_prefix('\u{feff}').unwrap_or(text)),
        Err(e) => {
            let at = e.valid_up_to();
            Err(SceneError::parse(
                Location::line(file, line_at(bytes, at)),
                format!(
                    "not a text file: byte 0x{:02x} at offset {at} is not UTF-8",
                    bytes.get(at).copied().unwrap_or(0)
                ),
            ))
        }
    }
}

/// An OBJ or MTL file as text. A NUL byte means binary data: an error. Other bytes that
/// are not UTF-8 (a Latin-1 comment or material name, say) are replaced by U+FFFD with a
/// warning, as the reference converter reads these files (`errors="replace"`).
fn as_lenient_text<'a>(bytes: &'a [u8], file: &str) -> Result<Cow<'a, str>, SceneError> {
    // `contains` searches bytes with memchr, many at a time; the offset is only wanted
    // for the error (over the conference room's 12 MB: 1.5 ms against 8 for a byte loop).
    if bytes.contains(&0) {
        let at = bytes.iter().position(|&b| b == 0).unwrap_or(0);
        return Err(SceneError::parse(
            Location::line(file, line_at(bytes, at)),
            format!("not a text file: a NUL byte at offset {at} (binary data?)"),
        ));
    }
    let text = match std::str::from_utf8(bytes) {
        Ok(text) => Cow::Borrowed(text),
        Err(e) => {
            log::warn!(
                "{file}:{}: bytes that are not UTF-8 replaced by U+FFFD",
                line_at(bytes, e.valid_up_to())
            );
            String::from_utf8_lossy(bytes)
        }
    };
    Ok(match text {
        Cow::Borrowed(t) => Cow::Borrowed(t.strip_prefix('\u{feff}').unwrap_or(t)),
        Cow::Owned(t) => match t.strip_prefix('\u{feff}') {
            Some(rest) => Cow::Owned(rest.to_string()),
            None => Cow::Owned(t),
        },
    })
}

// ---------------------------------------------------------------------------------------
// The TOML document
// ---------------------------------------------------------------------------------------

type V3 = Spanned<Num3>;

/// `[x, y, z]` in the TOML: exactly three numbers, each within the range of f32. Serde's
/// `[f32; 3]` reads three elements and ignores the rest (so `[0, 1, 3.9, 1]` passed), and
/// turns a number beyond the f32 range into inf (so `1e300` was reported as `inf`).
#[derive(Clone, Copy, Debug)]
struct Num3([f32; 3]);

impl<'de> Deserialize<'de> for Num3 {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Three;
        impl<'de> serde::de::Visitor<'de> for Three {
            type Value = Num3;

            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("3 numbers")
            }

            fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<Num3, A::Error> {
                use serde::de::Error;
                let mut v = [0.0f32; 3];
                for (k, x) in v.iter_mut().enumerate() {
                    let Some(y) = seq.next_element::<f64>()? else {
                        return Err(A::Error::invalid_length(k, &self));
                    };
                    // NaN and inf pass: the checks of each key say what they must be.
                    if y.is_finite() && y.abs() > f32::MAX as f64 {
                        return Err(A::Error::custom(format!(
                            "{y:e} is out of range for 32-bit floats (at most {:e} in magnitude)",
                            f32::MAX
                        )));
                    }
                    *x = y as f32;
                }
                let mut n = 3;
                while seq.next_element::<serde::de::IgnoredAny>()?.is_some() {
                    n += 1;
                }
                if n > 3 {
                    return Err(A::Error::invalid_length(n, &self));
                }
                Ok(Num3(v))
            }
        }
        d.deserialize_seq(Three)
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneDesc {
    camera: Spanned<CameraDesc>,
    film: Option<FilmDesc>,
    #[serde(default)]
    mesh: Vec<MeshDesc>,
    #[serde(default)]
    point_light: Vec<LightDesc>,
    #[serde(default)]
    materials: BTreeMap<String, Spanned<MaterialDesc>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraDesc {
    eye: V3,
    target: V3,
    up: Option<V3>,
    /// f64, so that a value beyond the f32 range is reported as written, not as inf.
    fov_y_deg: Spanned<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FilmDesc {
    width: Option<Spanned<u32>>,
    height: Option<Spanned<u32>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MeshDesc {
    path: Spanned<String>,
    default_material: Option<Spanned<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LightDesc {
    position: V3,
    intensity: V3,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MaterialDesc {
    diffuse: Option<V3>,
    mirror: Option<V3>,
}

/// The TOML text and its name, to turn spans into locations.
struct TomlFile<'a> {
    text: &'a str,
    name: &'a str,
}

impl TomlFile<'_> {
    fn at(&self, span: Range<usize>) -> Location {
        Location::offset(self.name, self.text, span.start)
    }

    fn invalid(&self, span: Range<usize>, message: impl AsRef<str>) -> SceneError {
        SceneError::invalid(self.at(span), message)
    }

    /// A value as the file writes it (its span), for messages.
    fn written(&self, span: Range<usize>) -> String {
        excerpt(self.text.get(span).unwrap_or(""))
    }

    fn finite(&self, v: &V3, key: &str) -> Result<Vec3, SceneError> {
        let a = v.get_ref().0;
        if a.iter().all(|x| x.is_finite()) {
            Ok(Vec3::from(a))
        } else {
            Err(self.invalid(
                v.span(),
                format!("{key} = {} must be finite numbers", fmt3(a)),
            ))
        }
    }
}

// ---------------------------------------------------------------------------------------
// Entry points
// ---------------------------------------------------------------------------------------

/// Reads a whole file, refusing anything but a regular file: a device (`/dev/zero`) would
/// be read forever and a FIFO would block, so bad input could hang the loader.
pub fn read_regular_file(path: &Path) -> io::Result<Vec<u8>> {
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            "not a regular file (a directory, device or pipe)",
        ));
    }
    std::fs::read(path)
}

/// Loads the scene file at `path` and the meshes it names (paths relative to the file).
///
/// [`Scene::source`] is `path` as given; [`Scene::files`] lists the TOML file, then each
/// mesh and material library read.
pub fn load_scene(path: &Path) -> Result<Scene, SceneError> {
    let bytes = read_regular_file(path).map_err(|source| SceneError::Read {
        what: "scene file",
        path: path.to_path_buf(),
        context: None,
        error: source,
    })?;
    let name = path.display().to_string();
    let text = as_text(&bytes, &name)?;
    let base_dir = path.parent().unwrap_or(Path::new(""));
    let mut scene = load_scene_str(text, base_dir, &name)?;
    scene.files.insert(0, path.to_path_buf());
    Ok(scene)
}

/// The camera of a `[camera]` table (or of its bare keys) in TOML text, validated as in a
/// scene file: what `igi view --camera` accepts and [`camera_toml`] writes.
pub fn parse_camera_toml(toml_text: &str, name: &str) -> Result<Camera, SceneError> {
    #[derive(Deserialize)]
    #[serde(deny_unknown_fields)]
    struct Wrapped {
        camera: Spanned<CameraDesc>,
    }
    let tf = TomlFile {
        text: toml_text,
        name,
    };
    let parse_error = |e: toml::de::Error| {
        let at = e.span().map_or(Location::file(name), |span| tf.at(span));
        SceneError::parse(at, toml_message(&e))
    };
    let has_table = toml_text.lines().any(|l| l.trim() == "[camera]");
    let desc = if has_table {
        toml::from_str::<Wrapped>(toml_text)
            .map_err(parse_error)?
            .camera
    } else {
        let bare: CameraDesc = toml::from_str(toml_text).map_err(parse_error)?;
        Spanned::new(0..toml_text.len(), bare)
    };
    camera(&tf, &desc)
}

/// `camera` as the `[camera]` table of a scene file (round-trips through
/// [`parse_camera_toml`] and [`load_scene`]).
pub fn camera_toml(camera: &Camera) -> String {
    // `{:?}` of an f32 prints the shortest decimal that reads back to the same value.
    let v = |v: Vec3| format!("[{:?}, {:?}, {:?}]", v.x, v.y, v.z);
    format!(
        "[camera]\neye = {}\ntarget = {}\nup = {}\nfov_y_deg = {:?}\n",
        v(camera.eye),
        v(camera.target),
        v(camera.up),
        camera.fov_y_deg
    )
}

/// Loads a scene from TOML text held in memory. Mesh paths are relative to `base_dir`;
/// `name` stands for the TOML file in messages and becomes [`Scene::source`].
/// [`Scene::files`] lists the meshes and material libraries read.
pub fn load_scene_str(toml_text: &str, base_dir: &Path, name: &str) -> Result<Scene, SceneError> {
    let tf = TomlFile {
        text: toml_text,
        name,
    };
    let desc: SceneDesc = toml::from_str(toml_text).map_err(|e| {
        let at = match e.span() {
            // A span over the whole document (a missing top-level key) says nothing.
            Some(span) if span.start > 0 || span.end < toml_text.trim_end().len() => tf.at(span),
            _ => Location::file(name),
        };
        SceneError::parse(at, toml_message(&e))
    })?;

    let camera = camera(&tf, &desc.camera)?;
    let film = film(&tf, desc.film.as_ref())?;
    let mut lights = desc
        .point_light
        .iter()
        .map(|l| light(&tf, l))
        .collect::<Result<Vec<_>, _>>()?;
    for (mat_name, m) in &desc.materials {
        check_toml_material(&tf, mat_name, m.get_ref())?;
    }
    if desc.mesh.is_empty() {
        return Err(SceneError::invalid(
            Location::file(name),
            "the scene has no [[mesh]]: at least one mesh is required",
        ));
    }
    let mut triangles = Vec::new();
    let mut slots: Vec<Slot> = Vec::new();
    let mut mtl = MtlTable::default();
    let mut files = Vec::new();
    for (mesh_index, mesh) in desc.mesh.iter().enumerate() {
        let rel = mesh.path.get_ref();
        if rel.trim().is_empty() {
            return Err(tf.invalid(mesh.path.span(), "mesh path is empty"));
        }
        let obj_path = base_dir.join(rel);
        let bytes = read_regular_file(&obj_path).map_err(|source| SceneError::Read {
            what: "mesh",
            path: obj_path.clone(),
            context: Some(format!("referenced by {name}")),
            error: source,
        })?;
        files.push(obj_path.clone());
        let first_slot = slots.len();
        // glTF hook: `.gltf`/`.glb` meshes are read by scene/gltf.rs (see add_gltf).
        if super::gltf::is_gltf_path(&obj_path) {
            let g = super::gltf::load_gltf_bytes(&bytes, &obj_path)?;
            lights.extend_from_slice(&g.lights);
            files.extend_from_slice(&g.files);
            let has_default = mesh.default_material.is_some();
            add_gltf(
                g,
                &obj_path,
                mesh_index,
                has_default,
                &mut slots,
                &mut triangles,
                &mut mtl,
            );
            continue;
        }
        load_obj(
            &bytes,
            &obj_path,
            mesh_index,
            &mut slots,
            &mut triangles,
            &mut mtl,
            &mut files,
        )?;
        log::debug!(
            "{}: {} material groups",
            obj_path.display(),
            slots.len() - first_slot
        );
    }

    // After the meshes: glTF point lights count too (glTF hook).
    if lights.is_empty() {
        return Err(SceneError::invalid(
            Location::file(name),
            "the scene has no [[point_light]] (and its glTF meshes no point light): at least one light is required",
        ));
    }
    check_total_power(&lights, name)?;

    // Resolve every used slot to a material, once per name.
    let mut materials: Vec<Material> = Vec::new();
    let mut by_name: HashMap<String, u32> = HashMap::new();
    let mut slot_material = vec![u32::MAX; slots.len()];
    for (i, slot) in slots.iter().enumerate() {
        if slot.triangles == 0 {
            continue;
        }
        let mesh = &desc.mesh[slot.mesh];
        let (mat_name, used_at, how) = match &slot.name {
            Some(n) => (
                n.as_str(),
                Location::line(&slot.file, slot.line),
                "usemtl".to_string(),
            ),
            None => match &mesh.default_material {
                Some(d) => (
                    d.get_ref().as_str(),
                    tf.at(d.span()),
                    format!("default_material of mesh '{}'", mesh.path.get_ref()),
                ),
                None => {
                    return Err(SceneError::invalid(
                        Location::line(&slot.file, slot.line),
                        format!(
                            "this face has no material (no usemtl before it) and its [[mesh]] in {name} has no default_material"
                        ),
                    ))
                }
            },
        };
        let index = match by_name.get(mat_name) {
            Some(&index) => index,
            None => {
                let Some(m) = resolve_material(&tf, mat_name, &desc.materials, &mtl)? else {
                    return Err(undefined_material(&tf, mat_name, &how, used_at, slot));
                };
                let index = materials.len() as u32;
                materials.push(m);
                by_name.insert(mat_name.to_string(), index);
                index
            }
        };
        slot_material[i] = index;
    }
    for t in &mut triangles {
        // Every triangle's slot has triangles, hence a material.
        t.material = slot_material
            .get(t.material as usize)
            .copied()
            .unwrap_or(u32::MAX);
    }
    for mat_name in desc.materials.keys() {
        if !by_name.contains_key(mat_name) {
            resolve_material(&tf, mat_name, &desc.materials, &mtl)?;
            log::warn!("{name}: [materials.{mat_name}] is used by no face; ignored");
        }
    }
    if triangles.is_empty() {
        return Err(SceneError::invalid(
            Location::file(name),
            "the scene has no triangles (its meshes have no faces, or only degenerate ones)",
        ));
    }
    // Ray tests multiply coordinates (relative to the ray's origin) in f32: past ~1e19
    // the products overflow and rays miss the triangle. Valid input, so kept, but said.
    let far = triangles
        .iter()
        .filter(|t| t.v.iter().any(|p| p.abs().max_element() > FAR_COORDINATE))
        .count();
    if far > 0 {
        log::warn!(
            "{name}: {far} triangles have coordinates beyond {FAR_COORDINATE:e}: rays (32-bit floats) may miss them"
        );
    }

    Ok(Scene {
        camera,
        film,
        triangles,
        materials,
        lights,
        source: name.to_string(),
        files,
    })
}

/// The toml crate's message, prefixed with the key path where it knows one
/// ("camera.fov_y_deg: invalid type: string \"wide\", expected f32"). The path is not
/// public API, but its `Display` adds a line "in `a.b`" when it has no input text to show.
fn toml_message(e: &toml::de::Error) -> String {
    let mut bare = e.clone();
    bare.set_input(None);
    let shown = bare.to_string();
    let keys = shown
        .lines()
        .find_map(|l| l.strip_prefix("in `").and_then(|k| k.strip_suffix('`')));
    match keys {
        Some(k) if !k.is_empty() => format!("{k}: {}", e.message()),
        _ => e.message().to_string(),
    }
}

/// The OBJ or MTL text without its comments: a `#` at the start of a line or after
/// white space begins a comment to the end of the line (`f 1 2 3 # face`). Lines keep
/// their numbers (the newlines stay). tobj skips only lines whose first word is `#`, so
/// a trailing comment failed on `f` lines ("cannot read face index '#'"), became part of
/// the name on `usemtl`/`newmtl` lines and a file name on `mtllib` lines, and passed on
/// `v` lines only by chance. A `#` inside a word (`Material#2`) is kept: names use it.
fn strip_comments(text: &str) -> Cow<'_, str> {
    let bytes = text.as_bytes();
    let mut out = String::new();
    // text[..kept] is in `out` or was a comment.
    let mut kept = 0;
    let mut any = false;
    for (i, _) in text.match_indices('#') {
        if i < kept || (i > 0 && !bytes[i - 1].is_ascii_whitespace()) {
            continue;
        }
        out.push_str(&text[kept..i]);
        kept = text[i..].find('\n').map_or(text.len(), |n| i + n);
        any = true;
    }
    if !any {
        return Cow::Borrowed(text);
    }
    out.push_str(&text[kept..]);
    Cow::Owned(out)
}

// ---------------------------------------------------------------------------------------
// TOML validation
// ---------------------------------------------------------------------------------------

fn camera(tf: &TomlFile, c: &Spanned<CameraDesc>) -> Result<Camera, SceneError> {
    let d = c.get_ref();
    let eye = tf.finite(&d.eye, "camera.eye")?;
    let target = tf.finite(&d.target, "camera.target")?;
    let up = match &d.up {
        Some(up) => tf.finite(up, "camera.up")?,
        None => DEFAULT_UP,
    };
    let up_span = d.up.as_ref().map_or(c.span(), |u| u.span());
    let fov64 = *d.fov_y_deg.get_ref();
    let fov = fov64 as f32;
    // Also in f32: a value just above 0 that rounds to 0.
    if !(fov64 > 0.0 && fov64 < 180.0 && fov > 0.0 && fov < 180.0) {
        return Err(tf.invalid(
            d.fov_y_deg.span(),
            format!(
                "camera.fov_y_deg = {} must be between 0 and 180 degrees (exclusive)",
                tf.written(d.fov_y_deg.span())
            ),
        ));
    }
    // In f64: the basis must be well defined for any finite f32 input.
    let dir = (target.as_dvec3() - eye.as_dvec3()).normalize_or_zero();
    if dir == DVec3::ZERO {
        return Err(tf.invalid(
            d.target.span(),
            format!(
                "camera.target = camera.eye = {}: the view direction is undefined",
                fmt3(target.into())
            ),
        ));
    }
    let up_n = up.as_dvec3().normalize_or_zero();
    if up_n == DVec3::ZERO || dir.cross(up_n).length() < 1e-6 {
        return Err(tf.invalid(
            up_span,
            format!(
                "camera.up = {} is zero or parallel to the view direction (target - eye): the image's orientation is undefined",
                fmt3(up.into())
            ),
        ));
    }
    Ok(Camera {
        eye,
        target,
        up,
        fov_y_deg: fov,
    })
}

fn film(tf: &TomlFile, f: Option<&FilmDesc>) -> Result<Film, SceneError> {
    let get = |v: Option<&Spanned<u32>>, key: &str, default: u32| match v {
        None => Ok(default),
        Some(s) if *s.get_ref() == 0 => {
            Err(tf.invalid(s.span(), format!("film.{key} must be at least 1")))
        }
        Some(s) => Ok(*s.get_ref()),
    };
    Ok(Film {
        width: get(
            f.and_then(|f| f.width.as_ref()),
            "width",
            DEFAULT_FILM.width,
        )?,
        height: get(
            f.and_then(|f| f.height.as_ref()),
            "height",
            DEFAULT_FILM.height,
        )?,
    })
}

fn light(tf: &TomlFile, l: &LightDesc) -> Result<PointLight, SceneError> {
    let position = tf.finite(&l.position, "point_light.position")?;
    let i = l.intensity.get_ref().0;
    if !i.iter().all(|x| x.is_finite() && *x >= 0.0) {
        return Err(tf.invalid(
            l.intensity.span(),
            format!(
                "point_light.intensity = {}: each channel must be a finite number >= 0 (W/sr)",
                fmt3(i)
            ),
        ));
    }
    let power = light_power_f64(Vec3::from(i));
    if power > f32::MAX as f64 {
        return Err(tf.invalid(
            l.intensity.span(),
            format!(
                "point_light.intensity = {}: its power 4 pi (r + g + b) = {power:.3e} W is beyond the range of 32-bit floats ({:.3e}), in which the renderer sums the lights' power",
                tf.written(l.intensity.span()),
                f32::MAX
            ),
        ));
    }
    Ok(PointLight {
        position,
        intensity: Vec3::from(i),
    })
}

/// A light's power summed over channels, 4 pi (r + g + b), in f64: the figure by which
/// lights are chosen (vpl.wgsl sums it in f32, over all lights, so it must stay in range).
fn light_power_f64(intensity: Vec3) -> f64 {
    4.0 * std::f64::consts::PI * intensity.as_dvec3().element_sum()
}

/// The largest value that channel `channel` (0, 1, 2: r, g, b) of light `index` may take,
/// the other channels and lights as they are, for the lights' total power to stay within
/// f32 as loading requires (`check_total_power`); for editors such as the viewer's
/// light panel, where a drag could otherwise push the sum past it at run time.
pub fn max_light_intensity(lights: &[PointLight], index: usize, channel: usize) -> f32 {
    let others: f64 = lights
        .iter()
        .enumerate()
        .map(|(i, l)| {
            let mut intensity = l.intensity;
            if i == index {
                intensity[channel] = 0.0;
            }
            light_power_f64(intensity)
        })
        .sum();
    // The power left, as this channel's intensity (power = 4 pi intensity), with a
    // margin far above the rounding of the f32 sums and of this cast.
    let room = (f32::MAX as f64 - others) / light_power_f64(Vec3::X);
    (room.max(0.0) * (1.0 - 1e-6)) as f32
}

/// Refuses lights whose summed power overflows f32: light choice on the GPU and CPU
/// divides by that sum, and an infinite one made every VPL's flux NaN (a NaN image). A
/// light that emits nothing is fine (it is never chosen); each TOML light was checked on
/// its own in [`light`], this catches the sum and glTF lights.
fn check_total_power(lights: &[PointLight], name: &str) -> Result<(), SceneError> {
    let total: f64 = lights.iter().map(|l| light_power_f64(l.intensity)).sum();
    if total > f32::MAX as f64 {
        return Err(SceneError::invalid(
            Location::file(name),
            format!(
                "the {} lights' total power 4 pi sum(r + g + b) = {total:.3e} W is beyond the range of 32-bit floats ({:.3e}), in which the renderer sums it: scale the intensities down",
                lights.len(),
                f32::MAX
            ),
        ));
    }
    Ok(())
}

fn check_toml_material(tf: &TomlFile, name: &str, m: &MaterialDesc) -> Result<(), SceneError> {
    for (v, key) in [(&m.diffuse, "diffuse"), (&m.mirror, "mirror")] {
        if let Some(v) = v {
            let a = v.get_ref().0;
            if !a.iter().all(|x| (0.0..=1.0).contains(x)) {
                return Err(tf.invalid(
                    v.span(),
                    format!(
                        "materials.{name}.{key} = {}: each channel must be in [0, 1]",
                        fmt3(a)
                    ),
                ));
            }
        }
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------
// Materials
// ---------------------------------------------------------------------------------------

/// Materials read from MTL files, by name (first definition wins across files).
#[derive(Default)]
struct MtlTable {
    defs: HashMap<String, MtlDef>,
    /// MTL files already read (a file named by several meshes is read once).
    read: HashSet<PathBuf>,
}

struct MtlDef {
    kd: Option<[f32; 3]>,
    ks: Option<[f32; 3]>,
    illum: Option<u8>,
    /// The `newmtl` line.
    at: Location,
    /// Made from a glTF material (glTF hook): `kd`/`ks` are its diffuse/mirror, `illum` 3.
    gltf: bool,
}

impl MtlDef {
    fn diffuse(&self) -> [f32; 3] {
        self.kd.unwrap_or([0.0; 3])
    }

    /// `Ks` is a perfect mirror only for the ray-traced illumination models 3, 5 and 7.
    fn mirror(&self) -> [f32; 3] {
        match self.illum {
            Some(3 | 5 | 7) => self.ks.unwrap_or([0.0; 3]),
            _ => [0.0; 3],
        }
    }
}

/// One value of a material and where it comes from, for messages.
struct Sourced {
    value: [f32; 3],
    at: Location,
    what: String,
    from_toml: bool,
}

/// The material `name`: the MTL's values replaced key by key by `[materials.NAME]`.
/// `Ok(None)` when neither defines it.
fn resolve_material(
    tf: &TomlFile,
    name: &str,
    toml_mats: &BTreeMap<String, Spanned<MaterialDesc>>,
    mtl: &MtlTable,
) -> Result<Option<Material>, SceneError> {
    let over = toml_mats.get(name);
    let base = mtl.defs.get(name);
    if over.is_none() && base.is_none() {
        return Ok(None);
    }
    let pick = |key: &str, toml_v: Option<&V3>, mtl_v: Option<([f32; 3], String)>| {
        if let Some(v) = toml_v {
            Sourced {
                value: v.get_ref().0,
                at: tf.at(v.span()),
                what: format!("materials.{name}.{key}"),
                from_toml: true,
            }
        } else if let (Some((value, what)), Some(b)) = (mtl_v, base) {
            Sourced {
                value,
                at: b.at.clone(),
                what,
                from_toml: false,
            }
        } else {
            Sourced {
                value: [0.0; 3],
                at: over.map_or(Location::file(tf.name), |o| tf.at(o.span())),
                what: format!("materials.{name}.{key} (default)"),
                from_toml: true,
            }
        }
    };
    let toml_d = over.and_then(|o| o.get_ref().diffuse.as_ref());
    let toml_m = over.and_then(|o| o.get_ref().mirror.as_ref());
    let diffuse = pick(
        "diffuse",
        toml_d,
        base.map(|b| {
            let what = if b.gltf {
                format!("diffuse of glTF material '{name}'")
            } else {
                format!("Kd of material '{name}'")
            };
            (b.diffuse(), what)
        }),
    );
    let mirror = pick(
        "mirror",
        toml_m,
        base.map(|b| {
            let what = match b.illum {
                _ if b.gltf => format!("mirror of glTF material '{name}'"),
                Some(i @ (3 | 5 | 7)) => format!("Ks (illum {i}) of material '{name}'"),
                _ => format!("mirror of material '{name}' (0: illum is not 3, 5 or 7)"),
            };
            (b.mirror(), what)
        }),
    );
    let hint = |from_toml: bool| {
        if from_toml {
            String::new()
        } else {
            format!(" (override it with [materials.{name}] in {})", tf.name)
        }
    };
    for s in [&diffuse, &mirror] {
        if !s.value.iter().all(|x| (0.0..=1.0).contains(x)) {
            return Err(SceneError::invalid(
                s.at.clone(),
                format!(
                    "{} = {}: each channel must be in [0, 1]{}",
                    s.what,
                    fmt3(s.value),
                    hint(s.from_toml)
                ),
            ));
        }
    }
    for (c, channel) in CHANNELS.iter().enumerate() {
        let sum = diffuse.value[c] + mirror.value[c];
        if sum > 1.0 + ALBEDO_SLACK {
            // Point at the TOML when a value comes from it: that is where to fix it.
            let at = if mirror.from_toml || !diffuse.from_toml {
                &mirror
            } else {
                &diffuse
            };
            return Err(SceneError::invalid(
                at.at.clone(),
                format!(
                    "material '{name}': diffuse + mirror = {sum} exceeds 1 in the {} channel ({} = {} from {}, {} = {} from {}){}",
                    channel,
                    diffuse.what,
                    fmt3(diffuse.value),
                    diffuse.at,
                    mirror.what,
                    fmt3(mirror.value),
                    mirror.at,
                    hint(diffuse.from_toml || mirror.from_toml)
                ),
            ));
        }
    }
    Ok(Some(Material {
        name: name.to_string(),
        diffuse: Vec3::from(diffuse.value),
        mirror: Vec3::from(mirror.value),
    }))
}

fn undefined_material(
    tf: &TomlFile,
    name: &str,
    how: &str,
    at: Location,
    slot: &Slot,
) -> SceneError {
    let libs = if slot.missing_mtl.is_empty() {
        if slot.has_mtllib {
            String::new()
        } else {
            format!(" ({} has no mtllib)", slot.file)
        }
    } else {
        format!(
            "; note: cannot read material library {}",
            slot.missing_mtl.join("; ")
        )
    };
    SceneError::invalid(
        at,
        format!(
            "material '{name}' ({how}) is defined nowhere: no MTL file defines it and {} has no [materials.{name}]{libs}",
            tf.name
        ),
    )
}

/// Reads one MTL file into `table` (names it defines first keep their values).
fn read_mtl(bytes: &[u8], path: &Path, table: &mut MtlTable) -> Result<(), SceneError> {
    let file = path.display().to_string();
    let text = as_lenient_text(bytes, &file)?;
    let text = strip_comments(text.as_ref());
    let text = text.as_ref();
    let newmtl_lines = check_mtl(text, &file)?;
    let loaded = catch_unwind(AssertUnwindSafe(|| {
        tobj::load_mtl_buf(&mut text.as_bytes())
    }));
    let (mats, map) = match loaded {
        Ok(Ok(r)) => r,
        Ok(Err(e)) => {
            return Err(SceneError::parse(
                Location::file(&file),
                format!("cannot read material library: {e}"),
            ))
        }
        Err(_) => {
            return Err(SceneError::parse(
                Location::file(&file),
                "the MTL reader (tobj) failed on this file",
            ))
        }
    };
    for (i, m) in mats.iter().enumerate() {
        // Within a file the last definition of a name wins (tobj's map says which).
        if map.get(&m.name) != Some(&i) {
            continue;
        }
        let def = MtlDef {
            kd: m.diffuse,
            ks: m.specular,
            illum: m.illumination_model,
            at: Location::line(&file, newmtl_lines.get(&m.name).copied().unwrap_or(1)),
            gltf: false,
        };
        match table.defs.get(&m.name) {
            Some(old) => {
                if old.diffuse() != def.diffuse() || old.mirror() != def.mirror() {
                    log::warn!(
                        "{}: material '{}' is also defined in {} with other values; the first definition is used",
                        def.at,
                        m.name,
                        old.at
                    );
                }
            }
            None => {
                table.defs.insert(m.name.clone(), def);
            }
        }
    }
    Ok(())
}

/// Checks the MTL lines that `tobj::load_mtl_buf` parses strictly, so that its errors come
/// with a line number and its panic (a colour of fewer than three numbers) cannot happen.
/// Returns the line of each `newmtl` (the last one for a repeated name).
fn check_mtl(text: &str, file: &str) -> Result<HashMap<String, usize>, SceneError> {
    let mut newmtl = HashMap::new();
    for (i, raw) in text.lines().enumerate() {
        let ln = i + 1;
        let line = raw.trim();
        let mut words = line.split_whitespace();
        let Some(key) = words.next() else { continue };
        let bad = |what: &str| {
            SceneError::parse(
                Location::line(file, ln),
                format!("{what}: '{}'", excerpt(line)),
            )
        };
        let number = |w: Option<&str>| w.is_some_and(|w| w.parse::<f32>().is_ok());
        let problem = match key {
            "newmtl" => {
                let name = line.get(6..).unwrap_or("").trim();
                if !name.is_empty() {
                    newmtl.insert(name.to_string(), ln);
                }
                name.is_empty()
                    .then(|| "newmtl without a material name".to_string())
            }
            "Ka" | "Kd" | "Ks" | "Ke" => (!(0..3).all(|_| number(words.next())))
                .then(|| format!("{key} needs three numbers (r g b)")),
            "Ns" | "Ni" | "d" => (!number(words.next())).then(|| format!("{key} needs a number")),
            "illum" => words
                .next()
                .is_none_or(|w| w.parse::<u8>().is_err())
                .then(|| "illum needs an integer from 0 to 10".to_string()),
            "map_Ka" | "map_Kd" | "map_Ks" | "map_Bump" | "map_bump" | "map_Ns" | "map_ns"
            | "map_NS" | "bump" | "map_d" => line
                .get(key.len()..)
                .unwrap_or("")
                .trim()
                .is_empty()
                .then(|| format!("{key} without a file name")),
            _ => None,
        };
        if let Some(problem) = problem {
            return Err(bad(&problem));
        }
    }
    Ok(newmtl)
}

// ---------------------------------------------------------------------------------------
// glTF hook (the reading is in scene/gltf.rs)
// ---------------------------------------------------------------------------------------

/// Adds what scene/gltf.rs read from one glTF file the way an OBJ's faces are added: each
/// material becomes a slot (as a `usemtl` name does) and a definition in `mtl` (as an MTL
/// material, the first definition of a name winning), so that names are shared across
/// meshes and `[materials.NAME]` overrides them key by key. Primitives without a material
/// take the mesh's `default_material` when it has one (as faces without `usemtl` do).
fn add_gltf(
    g: super::gltf::GltfMesh,
    path: &Path,
    mesh: usize,
    has_default_material: bool,
    slots: &mut Vec<Slot>,
    triangles: &mut Vec<Triangle>,
    mtl: &mut MtlTable,
) {
    let file = path.display().to_string();
    let slot_base = slots.len();
    for m in &g.materials {
        let name = (m.index.is_some() || !has_default_material).then(|| m.name.clone());
        if name.is_some() {
            let def = MtlDef {
                kd: Some(m.diffuse.into()),
                ks: Some(m.mirror.into()),
                illum: Some(3),
                at: Location::file(&file),
                gltf: true,
            };
            match mtl.defs.get(&m.name) {
                Some(old) if old.diffuse() != def.diffuse() || old.mirror() != def.mirror() => {
                    log::warn!(
                        "{file}: material '{}' is also defined in {} with other values; the first definition is used",
                        m.name,
                        old.at
                    );
                }
                Some(_) => {}
                None => {
                    mtl.defs.insert(m.name.clone(), def);
                }
            }
        }
        slots.push(Slot {
            name,
            mesh,
            file: file.clone(),
            line: 1,
            triangles: m.triangles,
            // Not "has no mtllib" in messages: glTF files define their materials.
            has_mtllib: true,
            missing_mtl: Vec::new(),
        });
    }
    triangles.extend(g.triangles.into_iter().map(|mut t| {
        t.material += slot_base as u32;
        t
    }));
}

// ---------------------------------------------------------------------------------------
// OBJ
// ---------------------------------------------------------------------------------------

/// The triangles of one mesh that share a `usemtl` name (or have none): their material is
/// resolved once all meshes and MTL files are read. [`Triangle::material`] holds the slot
/// index until then.
struct Slot {
    /// The `usemtl` name; `None` for faces before any `usemtl` (default_material).
    name: Option<String>,
    mesh: usize,
    file: String,
    /// First `usemtl` line of the name, or first face without `usemtl`.
    line: usize,
    triangles: usize,
    has_mtllib: bool,
    /// "'path' (mtllib at file:line): error" of material libraries that do not exist.
    missing_mtl: Vec<String>,
}

/// A triangle came from an `l` line (a polyline, not a surface): dropped.
const TRI_POLYLINE: u8 = 1;
/// Every corner of the face the triangle came from has a `vn` index.
const TRI_HAS_VN: u8 = 2;

/// What [`scan_obj`] learns from an OBJ's text.
#[derive(Debug, Default)]
struct ObjScan<'a> {
    /// `usemtl` names as tobj looks them up (the rest of the line after the first space,
    /// trimmed), distinct, in order of first use.
    keys: Vec<&'a str>,
    /// The same names as the format reads them (the words after `usemtl`).
    names: Vec<Cow<'a, str>>,
    first_line: Vec<usize>,
    /// First face before any `usemtl`.
    untagged_line: Option<usize>,
    /// (line, file) of each `mtllib` file.
    mtllibs: Vec<(usize, &'a str)>,
    /// Per triangle of the fanned faces, in file order: `TRI_*` bits.
    flags: Vec<u8>,
    /// Faces with one or two vertices (ignored).
    small_faces: usize,
    /// Number of `v`, `vt`, `vn` lines.
    counts: [usize; 3],
}

const KIND: [&str; 3] = ["vertices", "texture coordinates", "normals"];
const INDEX: [&str; 3] = [
    "face index",
    "face texture coordinate index",
    "face normal index",
];

/// Positive indices beyond the count declared so far (forward references): kept when they
/// exceed every earlier one, so the first that is beyond the file's total can be found at
/// the end.
#[derive(Default)]
struct Forward {
    max: [usize; 3],
    refs: [Vec<(usize, usize)>; 3],
}

/// One pass over the OBJ text: validates faces and collects what tobj does not tell us
/// (see the module documentation). No float parsing: tobj does that.
fn scan_obj<'a>(text: &'a str, file: &str) -> Result<ObjScan<'a>, SceneError> {
    let mut s = ObjScan::default();
    let mut key_index: HashMap<&str, usize> = HashMap::new();
    let mut tagged = false;
    let mut forward = Forward::default();
    let mut first_error: Option<(usize, String)> = None;
    for (i, line) in text.lines().enumerate() {
        let ln = i + 1;
        let mut words = line.split_whitespace();
        let Some(key) = words.next() else { continue };
        match key {
            "v" => s.counts[0] += 1,
            "vt" => s.counts[1] += 1,
            "vn" => s.counts[2] += 1,
            // After an error, only count (a forward reference may be an earlier error).
            _ if first_error.is_some() => {}
            "f" | "l" => match scan_face(words, &s.counts, &mut forward, ln) {
                Err(e) => first_error = Some((ln, e)),
                Ok((corners, all_vn)) => {
                    if corners < 3 {
                        if corners == 0 {
                            first_error = Some((ln, format!("'{key}' line without vertices")));
                        } else if key == "f" {
                            s.small_faces += 1;
                        }
                        continue;
                    }
                    let mut flag = if all_vn { TRI_HAS_VN } else { 0 };
                    if key == "l" {
                        flag |= TRI_POLYLINE;
                    } else if !tagged && s.untagged_line.is_none() {
                        s.untagged_line = Some(ln);
                    }
                    s.flags.extend(std::iter::repeat_n(flag, corners - 2));
                }
            },
            "usemtl" => {
                let words: Vec<&str> = words.collect();
                let name: Cow<str> = match words.as_slice() {
                    [one] => Cow::Borrowed(one),
                    more => Cow::Owned(more.join(" ")),
                };
                let tobj_key = line.split_once(' ').map_or("", |(_, rest)| rest.trim());
                if name.is_empty() {
                    first_error = Some((ln, "usemtl without a material name".into()));
                } else if tobj_key.is_empty() {
                    first_error = Some((
                        ln,
                        "separate usemtl and the material name with a space".into(),
                    ));
                } else {
                    tagged = true;
                    key_index.entry(tobj_key).or_insert_with(|| {
                        s.keys.push(tobj_key);
                        s.names.push(name);
                        s.first_line.push(ln);
                        s.keys.len() - 1
                    });
                }
            }
            "mtllib" => {
                let before = s.mtllibs.len();
                s.mtllibs.extend(words.map(|w| (ln, w)));
                if s.mtllibs.len() == before {
                    log::warn!("{file}:{ln}: mtllib without a file name, ignored");
                }
            }
            _ => {}
        }
    }
    // The first face whose positive index is beyond the file's total.
    let mut out_of_range: Option<(usize, String)> = None;
    for k in 0..3 {
        if let Some(&(ln, idx)) = forward.refs[k].iter().find(|(_, idx)| *idx > s.counts[k]) {
            if out_of_range.as_ref().is_none_or(|(l, _)| ln < *l) {
                out_of_range = Some((
                    ln,
                    format!(
                        "{} {idx} out of range (the file has {} {})",
                        INDEX[k], s.counts[k], KIND[k]
                    ),
                ));
            }
        }
    }
    let error = match (first_error, out_of_range) {
        (Some(a), Some(b)) => Some(if b.0 < a.0 { b } else { a }),
        (a, b) => a.or(b),
    };
    match error {
        Some((ln, message)) => Err(SceneError::parse(Location::line(file, ln), message)),
        None => Ok(s),
    }
}

/// Parses the corners of one `f` line exactly as tobj does (`v`, `v/vt`, `v//vn`,
/// `v/vt/vn`, negative indices relative to the count so far) and checks every index.
/// Returns the number of corners and whether all have a normal index.
fn scan_face<'a>(
    corners: impl Iterator<Item = &'a str>,
    counts: &[usize; 3],
    forward: &mut Forward,
    ln: usize,
) -> Result<(usize, bool), String> {
    let mut n = 0;
    let mut all_vn = true;
    for corner in corners {
        n += 1;
        let mut has = [false; 3];
        for (k, part) in corner.split('/').enumerate() {
            if k >= 3 {
                return Err(format!(
                    "face corner '{}' has more than three indices (v/vt/vn)",
                    excerpt(corner)
                ));
            }
            if part.is_empty() {
                continue;
            }
            let Ok(x) = part.parse::<isize>() else {
                return Err(if part == corner {
                    format!("cannot read face index '{}'", excerpt(part))
                } else {
                    format!(
                        "cannot read face index '{}' in '{}'",
                        excerpt(part),
                        excerpt(corner)
                    )
                });
            };
            has[k] = true;
            if x == 0 {
                return Err(format!(
                    "{} 0 in '{}': OBJ indices start at 1 (negative ones count back from the last of the {})",
                    INDEX[k],
                    excerpt(corner),
                    KIND[k]
                ));
            }
            if x < 0 {
                if x.unsigned_abs() > counts[k] {
                    return Err(format!(
                        "{} {x} out of range (only {} {} are declared before this line)",
                        INDEX[k], counts[k], KIND[k]
                    ));
                }
            } else {
                let x = x as usize;
                if x > counts[k] && x > forward.max[k] {
                    forward.max[k] = x;
                    forward.refs[k].push((ln, x));
                }
            }
        }
        if !has[0] {
            return Err(format!(
                "face corner '{}' has no vertex index",
                excerpt(corner)
            ));
        }
        all_vn &= has[2];
    }
    Ok((n, all_vn))
}

/// The path tobj is given (as its first `mtllib` line) to learn every `usemtl` name.
const NAMES_MTLLIB: &str = "\u{1}igi-usemtl-names";

/// Reads one OBJ: appends its triangles (material = slot index) and its slots; reads its
/// MTL files into `mtl`.
fn load_obj(
    bytes: &[u8],
    path: &Path,
    mesh: usize,
    slots: &mut Vec<Slot>,
    out: &mut Vec<Triangle>,
    mtl: &mut MtlTable,
    files: &mut Vec<PathBuf>,
) -> Result<(), SceneError> {
    let file = path.display().to_string();
    let text = as_lenient_text(bytes, &file)?;
    let text = strip_comments(text.as_ref());
    let text = text.as_ref();
    let scan = scan_obj(text, &file)?;
    if scan.small_faces > 0 {
        log::warn!(
            "{file}: {} faces with fewer than 3 vertices ignored",
            scan.small_faces
        );
    }

    // Material libraries, relative to the OBJ.
    let dir = path.parent().unwrap_or(Path::new(""));
    let mut missing_mtl = Vec::new();
    for &(ln, lib) in &scan.mtllibs {
        let lib_path = dir.join(lib);
        if mtl.read.contains(&lib_path) {
            continue;
        }
        match read_regular_file(&lib_path) {
            Ok(b) => {
                read_mtl(&b, &lib_path, mtl)?;
                mtl.read.insert(lib_path.clone());
                files.push(lib_path);
            }
            Err(e) if e.kind() == io::ErrorKind::NotFound => {
                log::warn!(
                    "{file}:{ln}: material library '{}' not found",
                    lib_path.display()
                );
                missing_mtl.push(format!(
                    "'{}' (mtllib at {file}:{ln}): {}",
                    lib_path.display(),
                    io_message(&e)
                ));
            }
            Err(source) => {
                return Err(SceneError::Read {
                    what: "material library",
                    path: lib_path,
                    context: Some(format!("mtllib at {file}:{ln}")),
                    error: source,
                })
            }
        }
    }

    let slot_base = slots.len();
    let n_keys = scan.keys.len();
    for k in 0..=n_keys {
        slots.push(Slot {
            name: scan.names.get(k).map(|n| n.to_string()),
            mesh,
            file: file.clone(),
            line: scan
                .first_line
                .get(k)
                .copied()
                .or(scan.untagged_line)
                .unwrap_or(1),
            triangles: 0,
            has_mtllib: !scan.mtllibs.is_empty(),
            missing_mtl: missing_mtl.clone(),
        });
    }

    // tobj, with a first line that makes it resolve every usemtl name to our slot index
    // (its own MTL loading is bypassed: the closure returns nothing for real files).
    let names_table = || -> tobj::MTLLoadResult {
        let mut table: tobj::MTLLoadResult = Ok((Vec::new(), Default::default()));
        if let Ok((mats, map)) = &mut table {
            for (i, key) in scan.keys.iter().enumerate() {
                mats.push(tobj::Material {
                    name: key.to_string(),
                    ..Default::default()
                });
                map.insert(key.to_string(), i);
            }
        }
        table
    };
    let prefix = format!("mtllib {NAMES_MTLLIB}\n");
    let mut reader = prefix.as_bytes().chain(text.as_bytes());
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let loaded = catch_unwind(AssertUnwindSafe(|| {
        tobj::load_obj_buf(&mut reader, &options, |p| {
            if p == Path::new(NAMES_MTLLIB) {
                names_table()
            } else {
                Ok((Vec::new(), Default::default()))
            }
        })
    }));
    let models = match loaded {
        Ok(Ok((models, _))) => models,
        Ok(Err(e)) => return Err(obj_error(text, &file, e)),
        Err(_) => {
            return Err(SceneError::parse(
                Location::file(&file),
                "the OBJ reader (tobj) failed on this file",
            ))
        }
    };

    let internal = |what: &str| {
        SceneError::parse(
            Location::file(&file),
            format!("internal error reading the OBJ: {what}"),
        )
    };
    let mut g = 0; // triangle number in file order, indexes scan.flags
    let mut degenerate = 0usize;
    let mut bad_normals = 0usize;
    out.reserve(scan.flags.len());
    for model in &models {
        let m = &model.mesh;
        let slot = match m.material_id {
            None => n_keys,
            Some(id) if id < n_keys => id,
            Some(_) => return Err(internal("unknown material id")),
        };
        let has_normals = !m.normals.is_empty() && m.normal_indices.len() == m.indices.len();
        let pos = |i: u32| -> Option<Vec3> {
            let i = i as usize * 3;
            m.positions.get(i..i + 3).map(Vec3::from_slice)
        };
        let nrm = |i: u32| -> Option<Vec3> {
            let i = i as usize * 3;
            m.normals.get(i..i + 3).map(Vec3::from_slice)
        };
        for (t, idx) in m.indices.chunks_exact(3).enumerate() {
            let Some(&flag) = scan.flags.get(g) else {
                return Err(internal("more triangles than faces"));
            };
            g += 1;
            if flag & TRI_POLYLINE != 0 {
                continue;
            }
            let (Some(p0), Some(p1), Some(p2)) = (pos(idx[0]), pos(idx[1]), pos(idx[2])) else {
                return Err(internal("vertex index out of range"));
            };
            let v = [p0, p1, p2];
            if !v.iter().all(|p| p.is_finite()) {
                return Err(non_finite_vertex(text, &file));
            }
            let Some(ng) = super::geometric_normal(&v) else {
                degenerate += 1;
                continue;
            };
            let mut n = [ng; 3];
            if has_normals && flag & TRI_HAS_VN != 0 {
                for (k, nk) in n.iter_mut().enumerate() {
                    let vn = m.normal_indices.get(3 * t + k).and_then(|&i| nrm(i));
                    match vn.and_then(|x| x.try_normalize()) {
                        Some(x) => *nk = x,
                        None => bad_normals += 1,
                    }
                }
            }
            out.push(Triangle {
                v,
                n,
                material: (slot_base + slot) as u32,
            });
            slots[slot_base + slot].triangles += 1;
        }
    }
    if g != scan.flags.len() {
        return Err(internal("fewer triangles than faces"));
    }
    if degenerate > 0 {
        log::warn!(
            "{file}: {degenerate} degenerate triangles (zero area, or edges beyond the 32-bit float range) dropped"
        );
    }
    if bad_normals > 0 {
        log::warn!(
            "{file}: {bad_normals} vn normals of zero length or not finite replaced by the geometric normal"
        );
    }
    let polylines = scan
        .flags
        .iter()
        .filter(|&&f| f & TRI_POLYLINE != 0)
        .count();
    if polylines > 0 {
        log::warn!("{file}: 'l' polylines ignored");
    }
    Ok(())
}

/// Turns a tobj error into one with a line: tobj's remaining failures (after
/// [`scan_obj`]) are numbers it cannot read in `v`, `vt`, `vn` lines.
fn obj_error(text: &str, file: &str, e: tobj::LoadError) -> SceneError {
    use tobj::LoadError as E;
    match e {
        E::PositionParseError
        | E::ScalingByZeroError
        | E::ColorParseError
        | E::NormalParseError
        | E::TexcoordParseError => {
            if let Some((ln, message)) = find_bad_vertex_line(text) {
                return SceneError::parse(Location::line(file, ln), message);
            }
        }
        E::FaceVertexOutOfBounds | E::FaceNormalOutOfBounds | E::FaceTexCoordOutOfBounds => {
            // Indices are in range of the whole file (checked), so this is a forward
            // reference past the end of the face's object or group, which tobj cannot do.
            return SceneError::parse(
                Location::file(file),
                "a face refers to a vertex declared later in the file, after the face's object or group ends (move the vertices before the faces)",
            );
        }
        _ => {}
    }
    SceneError::parse(Location::file(file), format!("cannot read the OBJ: {e}"))
}

/// The first `v`, `vt` or `vn` line that tobj rejects, with tobj's rules.
fn find_bad_vertex_line(text: &str) -> Option<(usize, String)> {
    let num = |w: Option<&str>| w.and_then(|w| w.parse::<f32>().ok());
    for (i, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let (need, what) = match words.next() {
            Some("v") => (3, "vertex position (v x y z [w] or v x y z r g b)"),
            Some("vt") => (2, "texture coordinate (vt u v)"),
            Some("vn") => (3, "normal (vn x y z)"),
            _ => continue,
        };
        let bad = || Some((i + 1, format!("cannot read {what}: '{}'", excerpt(line))));
        if !(0..need).all(|_| num(words.next()).is_some()) {
            return bad();
        }
        if need == 3 && line.split_whitespace().next() == Some("v") {
            let rest: Vec<&str> = words.collect();
            match rest.len() {
                0 | 3 => {}
                1 => match num(rest.first().copied()) {
                    Some(w) if w != 0.0 => {}
                    _ => return bad(),
                },
                _ => return bad(),
            }
        }
    }
    None
}

/// The error for a face that uses a vertex with a non-finite coordinate, located by
/// reading the text again (a cold path).
fn non_finite_vertex(text: &str, file: &str) -> SceneError {
    let mut bad: HashMap<usize, usize> = HashMap::new(); // vertex index -> its line
    let mut nv = 0usize;
    let lines: Vec<&str> = text.lines().collect();
    for (i, line) in lines.iter().enumerate() {
        let mut words = line.split_whitespace();
        if words.next() != Some("v") {
            continue;
        }
        let vals: Vec<f32> = words.filter_map(|w| w.parse::<f32>().ok()).collect();
        let w = if vals.len() == 4 { vals[3] } else { 1.0 };
        if vals.iter().take(3).any(|x| !(x / w).is_finite()) {
            bad.insert(nv, i + 1);
        }
        nv += 1;
    }
    let mut seen = 0usize;
    for (i, line) in lines.iter().enumerate() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => seen += 1,
            Some("f") => {
                for corner in words {
                    let idx = corner
                        .split('/')
                        .next()
                        .and_then(|p| p.parse::<isize>().ok());
                    let v = match idx {
                        Some(x) if x < 0 => seen.checked_sub(x.unsigned_abs()),
                        Some(x) if x > 0 => Some(x as usize - 1),
                        _ => None,
                    };
                    if let Some(vl) = v.and_then(|v| bad.get(&v).map(|l| (v, *l))) {
                        return SceneError::invalid(
                            Location::line(file, i + 1),
                            format!(
                                "face uses vertex {} whose coordinates are not finite (line {}: '{}')",
                                vl.0 + 1,
                                vl.1,
                                excerpt(lines[vl.1 - 1])
                            ),
                        );
                    }
                }
            }
            _ => {}
        }
    }
    SceneError::invalid(
        Location::file(file),
        "a face uses a vertex whose coordinates are not finite",
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn location_of_an_offset_counts_lines_and_characters() {
        let text = "a = 1\nbé = [1, 2]\n";
        let at = Location::offset("s.toml", text, text.find('[').unwrap());
        assert_eq!(at.to_string(), "s.toml:2:6");
        assert_eq!(
            Location::offset("s.toml", text, 0).to_string(),
            "s.toml:1:1"
        );
        // Past the end and inside a character: clamped, no panic.
        assert_eq!(Location::offset("s.toml", text, 999).line, Some(3));
        assert_eq!(
            Location::offset("s.toml", text, 8).to_string(),
            "s.toml:2:2"
        );
        assert_eq!(Location::file("x.obj").to_string(), "x.obj");
        assert_eq!(Location::line("x.obj", 7).to_string(), "x.obj:7");
    }

    #[test]
    fn messages_are_one_line() {
        assert_eq!(one_line("a\nb\r\tc"), "a b  c");
        let e = io::Error::from_raw_os_error(2);
        assert_eq!(io_message(&e), "No such file or directory");
        assert_eq!(excerpt(&"x".repeat(100)).len(), 63);
        let e = SceneError::invalid(Location::file("f\ng"), "two\nlines");
        assert_eq!(e.to_string(), "f g: two lines");
    }

    #[test]
    fn scan_counts_fanned_triangles_and_flags() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvn 0 0 1\nf 1 2 3 4\nusemtl m\nf 1//1 2//1 3//1\nl 1 2 3\nf 1 2\n";
        let s = scan_obj(text, "t.obj").unwrap();
        assert_eq!(s.flags, [0, 0, TRI_HAS_VN, TRI_POLYLINE]);
        assert_eq!(s.untagged_line, Some(6));
        assert_eq!(s.keys, ["m"]);
        assert_eq!(s.small_faces, 1);
        assert_eq!(s.counts, [4, 0, 1]);
    }

    #[test]
    fn scan_reports_the_first_bad_line() {
        // A forward reference beyond the file (line 1) comes before the zero (line 2).
        let e = scan_obj("f 1 2 9\nf 0 1 2\nv 0 0 0\n", "t.obj").unwrap_err();
        let e = e.to_string();
        assert!(e.starts_with("t.obj:1: face index "), "{e}");
        assert!(
            e.ends_with(" out of range (the file has 1 vertices)"),
            "{e}"
        );
        let e = scan_obj("v 0 0 0\nf 1 1 1\nf 1 1 0\nf 1 1 5\n", "t.obj").unwrap_err();
        assert!(e.to_string().starts_with("t.obj:3: face index 0"));
    }

    #[test]
    fn mtl_check_matches_what_tobj_rejects() {
        assert!(check_mtl("newmtl a\nKd 1 1 1 # c\nmap_Kd x.png\nfoo bar\n", "m").is_ok());
        for bad in [
            "Kd 1 1",
            "Ke",
            "Ns x",
            "d",
            "illum 300",
            "map_Kd",
            "newmtl  ",
        ] {
            let e = check_mtl(&format!("newmtl a\n{bad}\n"), "m").unwrap_err();
            assert!(e.to_string().starts_with("m:2: "), "{bad}: {e}");
        }
    }
}
