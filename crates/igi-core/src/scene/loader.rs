//! Scene loader: the TOML scene description of `shared/SCENE_FORMAT.md` and its Wavefront
//! OBJ/MTL meshes, read and validated into a [`Scene`].
//!
//! Every failure is a [`SceneError`] whose message is one line that names the file (and the
//! line, and for TOML the column, where known), e.g.
//! `scenes/box/box.obj:123: face index 999 out of range (the file has 456 vertices)`.
//! Nothing in here panics on user data. Text quoted from a file is shortened (the `quote`
//! helpers of `error`), so a huge name makes a short message. Work and memory follow the
//! files' sizes: a scene has at most [`MAX_TRIANGLES`] triangles, each mesh counted before
//! it is read.
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
//!   other bytes that are not UTF-8 (a Latin-1 comment) are replaced, with a warning, and
//!   a lone CR ends a line as LF and CRLF do.
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
//!
//! This module holds the entry points and the merge of the meshes into one scene (the
//! material slots resolved once every mesh is read); the rest is by format, in private
//! modules of [`super`]: `toml_file` (the scene file's schema and the checks of its
//! values), `obj` (`scan_obj`, `strip_comments` and the reading with tobj), `mtl` (the
//! MTL libraries and the resolution of a material name) and `error` ([`SceneError`],
//! [`Location`] and the helpers that keep messages on one line); glTF files are read by
//! [`super::gltf`].

use std::collections::HashMap;
use std::io;
use std::path::Path;

use glam::Vec3;
use serde::Deserialize;
use toml::Spanned;

use super::error::{as_text, quote};
use super::mtl::{resolve_material, undefined_material, DefTexture, MtlDef, MtlTable};
use super::obj::{load_obj, Slot};
use super::toml_file::{
    camera, check_toml_material, check_total_power, film, light, toml_message, CameraDesc,
    SceneDesc, TomlFile,
};
use super::{Alpha, AlphaMode, Camera, Material, Scene, TriAttributes, Triangle};

pub use super::error::{without_os_error_code, Location, SceneError};
pub use super::toml_file::{max_light_intensity, DEFAULT_FILM, DEFAULT_UP};

/// The most triangles a scene may have, over all its meshes: 16,777,216 (2^24), fifty times
/// the conference room's 331K. A loaded triangle takes 76 bytes, and the BVH build and the
/// GPU's copy take several times that again, so the limit keeps a scene within a few GB of
/// memory; without it a small file whose node tree places one mesh many times (or a scene
/// file naming one mesh many times) asked for billions of triangles and aborted on a
/// failed allocation. Meshes are counted before they are read.
pub const MAX_TRIANGLES: usize = 1 << 24;

/// The triangles a scene may still take while its meshes are read: `limit` in all, of
/// which the meshes read so far have `used`.
#[derive(Clone, Copy, Debug)]
pub(super) struct TriangleBudget {
    pub(super) limit: usize,
    pub(super) used: usize,
}

impl Default for TriangleBudget {
    fn default() -> Self {
        TriangleBudget {
            limit: MAX_TRIANGLES,
            used: 0,
        }
    }
}

impl TriangleBudget {
    /// Checks that `more` triangles, counted before they are made, fit; otherwise an error
    /// naming `file`, what `made` says ("its faces make 123 triangles") and the limit.
    pub(super) fn check(
        &self,
        more: usize,
        file: &str,
        made: impl FnOnce() -> String,
    ) -> Result<(), SceneError> {
        if more <= self.limit.saturating_sub(self.used) {
            return Ok(());
        }
        let earlier = match self.used {
            0 => String::new(),
            n => format!(", and the scene's earlier meshes {n}"),
        };
        Err(SceneError::invalid(
            Location::file(file),
            format!(
                "{}{earlier}: more than the {} triangles a scene may have",
                made(),
                self.limit
            ),
        ))
    }
}

/// The scene's triangles as the meshes add them, with their attributes: none until a mesh
/// brings some, then one per triangle up to the last that has some (NONE for those
/// before it); the loader pads or drops them at the end.
#[derive(Default)]
pub(super) struct Geometry {
    pub(super) triangles: Vec<Triangle>,
    pub(super) attributes: Vec<TriAttributes>,
}

impl Geometry {
    pub(super) fn push(&mut self, t: Triangle, attributes: Option<TriAttributes>) {
        if let Some(a) = attributes {
            self.attributes
                .resize(self.triangles.len(), TriAttributes::NONE);
            self.attributes.push(a);
        }
        self.triangles.push(t);
    }
}

/// A cut-out whose opacity cannot vary (no texture, no vertex colours) is all there or
/// all cut out: opaque where its factor reaches the cutoff, so that rays need not test it;
/// below the cutoff it stays a mask (every ray passes).
pub(super) fn settled_alpha(alpha: Alpha, textured: bool, vertex_colors: bool) -> Alpha {
    match alpha.mode {
        AlphaMode::Mask { cutoff } if !textured && !vertex_colors && alpha.factor >= cutoff => {
            Alpha::OPAQUE
        }
        _ => alpha,
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
    load_scene_str_within(toml_text, base_dir, name, MAX_TRIANGLES)
}

/// [`load_scene_str`] with a scene of at most `max_triangles` triangles.
pub(super) fn load_scene_str_within(
    toml_text: &str,
    base_dir: &Path,
    name: &str,
    max_triangles: usize,
) -> Result<Scene, SceneError> {
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
    let mut geometry = Geometry::default();
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
        let budget = TriangleBudget {
            limit: max_triangles,
            used: geometry.triangles.len(),
        };
        // glTF hook: `.gltf`/`.glb` meshes are read by scene/gltf.rs (see add_gltf).
        if super::gltf::is_gltf_path(&obj_path) {
            let g = super::gltf::load_gltf_within(&bytes, &obj_path, budget)?;
            lights.extend_from_slice(&g.lights);
            files.extend_from_slice(&g.files);
            let has_default = mesh.default_material.is_some();
            add_gltf(
                g,
                &obj_path,
                mesh_index,
                has_default,
                &mut slots,
                &mut geometry,
                &mut mtl,
            );
            continue;
        }
        let default_material = mesh.default_material.as_ref().map(|d| d.get_ref().as_str());
        load_obj(
            &bytes,
            &obj_path,
            mesh_index,
            default_material,
            budget,
            &mut slots,
            &mut geometry,
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
                    format!("default_material of mesh '{}'", quote(mesh.path.get_ref())),
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
                let Some(m) = resolve_material(&tf, mat_name, &desc.materials, &mut mtl, true)?
                else {
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
    let Geometry {
        mut triangles,
        mut attributes,
    } = geometry;
    for t in &mut triangles {
        // Every triangle's slot has triangles, hence a material.
        t.material = slot_material
            .get(t.material as usize)
            .copied()
            .unwrap_or(u32::MAX);
    }
    for mat_name in desc.materials.keys() {
        if !by_name.contains_key(mat_name) {
            resolve_material(&tf, mat_name, &desc.materials, &mut mtl, false)?;
            log::warn!(
                "{name}: [materials.{}] is used by no face; ignored",
                quote(mat_name)
            );
        }
    }
    if triangles.is_empty() {
        return Err(SceneError::invalid(
            Location::file(name),
            "the scene has no triangles (its meshes have no faces, or only degenerate ones)",
        ));
    }
    // Attributes where a material uses them (one per triangle), else none.
    if materials.iter().any(|m| m.uses_attributes()) {
        attributes.resize(triangles.len(), TriAttributes::NONE);
    } else {
        attributes = Vec::new();
    }
    let textures = used_textures(&mut materials, std::mem::take(&mut mtl.textures.list));
    files.append(&mut mtl.textures.files);
    let scene = Scene {
        camera,
        film,
        triangles,
        materials,
        textures,
        attributes,
        lights,
        source: name.to_string(),
        files,
    };
    check_scale(&scene)?;
    Ok(scene)
}

/// The textures that `materials` use, in order of first use, their indices made those of
/// the list returned: a texture whose materials no face uses, or that `[materials.NAME]`
/// replaced, is not kept.
fn used_textures(
    materials: &mut [Material],
    all: Vec<crate::texture::Texture>,
) -> Vec<crate::texture::Texture> {
    let mut index: Vec<Option<u32>> = vec![None; all.len()];
    let mut order: Vec<usize> = Vec::new();
    for m in materials.iter_mut() {
        if let Some(t) = &mut m.texture {
            let old = t.texture as usize;
            let new = *index[old].get_or_insert_with(|| {
                order.push(old);
                order.len() as u32 - 1
            });
            t.texture = new;
        }
    }
    let mut all: Vec<Option<crate::texture::Texture>> = all.into_iter().map(Some).collect();
    order.into_iter().filter_map(|i| all[i].take()).collect()
}

/// Errors where 32-bit floats cannot trace the scene (a small scene far from the origin,
/// [`crate::trace_scale::check_precision`]); warns where its ray offsets, set by its
/// farthest coordinate, are large against what the camera looks at (a far triangle among
/// small ones). Any size in itself is traced (see [`crate::trace_scale`]).
fn check_scale(scene: &Scene) -> Result<(), SceneError> {
    let (lo, hi) = scene.bounds();
    crate::trace_scale::check_precision(lo, hi)
        .map_err(|e| SceneError::invalid(Location::file(&scene.source), e))?;
    let floor = crate::bvh::offset_floor(lo, hi);
    let view = scene.camera.eye.distance(scene.camera.target);
    if floor > view * crate::trace_scale::MAX_OFFSET_FRACTION {
        log::warn!(
            "{}: its farthest coordinates ({:.3e}) make ray origins move {floor:.3e} off surfaces, more than 1/{} of the camera's distance to its target ({view:.3e}): shadows near the camera may detach or vanish",
            scene.source,
            lo.abs().max(hi.abs()).max_element(),
            (1.0 / crate::trace_scale::MAX_OFFSET_FRACTION) as u32
        );
    }
    Ok(())
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
    geometry: &mut Geometry,
    mtl: &mut MtlTable,
) {
    let file = path.display().to_string();
    let slot_base = slots.len();
    // The file's textures join the scene's; its materials' indices follow them.
    let texture_base = mtl.textures.list.len() as u32;
    for t in g.textures {
        mtl.textures.push(t);
    }
    for m in &g.materials {
        let name = (m.index.is_some() || !has_default_material).then(|| m.name.clone());
        if name.is_some() {
            let texture = m.texture.map(|mut t| {
                t.texture += texture_base;
                t
            });
            let def = MtlDef {
                kd: Some(m.diffuse.into()),
                ks: Some(m.mirror.into()),
                illum: Some(3),
                at: Location::file(&file),
                gltf: true,
                texture: texture.map_or(DefTexture::None, DefTexture::Ready),
                vertex_colors: m.vertex_colors,
                alpha: m.alpha,
            };
            match mtl.defs.get(&m.name) {
                Some(old) if old.diffuse() != def.diffuse() || old.mirror() != def.mirror() => {
                    log::warn!(
                        "{file}: material '{}' is also defined in {} with other values; the first definition is used",
                        quote(&m.name),
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
    if !g.attributes.is_empty() {
        let before = geometry.triangles.len();
        geometry.attributes.resize(before, TriAttributes::NONE);
        geometry.attributes.extend_from_slice(&g.attributes);
    }
    geometry
        .triangles
        .extend(g.triangles.into_iter().map(|mut t| {
            t.material += slot_base as u32;
            t
        }));
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The triangle limit counts each mesh, OBJ or glTF, before reading it, with the
    /// triangles of the meshes before it (a small limit stands for [`MAX_TRIANGLES`]).
    #[test]
    fn the_triangle_limit_counts_every_mesh_before_it_is_read() {
        let dir = std::env::temp_dir().join(format!("igi-loader-limit-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let ring: String = (0..7)
            .map(|k| {
                let a = k as f32;
                format!("v {} {} 0\n", a.cos(), a.sin())
            })
            .collect();
        std::fs::write(dir.join("quad.obj"), format!("{ring}f 1 2 3 4\n")).unwrap();
        std::fs::write(dir.join("fan.obj"), format!("{ring}f 1 2 3 4 5 6 7\n")).unwrap();
        // One triangle (positions and indices in a data: URI).
        let gltf = r#"{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],"meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],"buffers":[{"byteLength":42,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIA"}],"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":6}],"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}]}"#;
        std::fs::write(dir.join("tri.gltf"), gltf).unwrap();
        let scene = |meshes: &[&str]| {
            let meshes: String = meshes
                .iter()
                .map(|m| format!("[[mesh]]\npath = \"{m}\"\ndefault_material = \"d\"\n"))
                .collect();
            format!("[camera]\neye = [0.0, 0.0, 5.0]\ntarget = [0.0, 0.0, 0.0]\nfov_y_deg = 40.0\n[[point_light]]\nposition = [0.0, 0.0, 3.0]\nintensity = [1.0, 1.0, 1.0]\n[materials.d]\ndiffuse = [0.5, 0.5, 0.5]\n{meshes}")
        };
        let load =
            |meshes: &[&str], limit| load_scene_str_within(&scene(meshes), &dir, "s.toml", limit);
        let message = |r: Result<Scene, SceneError>| r.err().map(|e| e.to_string()).unwrap();

        let three = ["quad.obj", "quad.obj", "fan.obj"];
        assert_eq!(load(&three, 9).unwrap().triangles.len(), 9);
        let e = message(load(&three, 8));
        assert!(e.contains("fan.obj"), "{e}");
        assert!(
            e.ends_with("its faces make 5 triangles, and the scene's earlier meshes 4: more than the 8 triangles a scene may have"),
            "{e}"
        );
        // A single mesh beyond the limit, with nothing before it.
        let e = message(load(&["fan.obj"], 4));
        assert!(
            e.ends_with(
                "fan.obj: its faces make 5 triangles: more than the 4 triangles a scene may have"
            ),
            "{e}"
        );
        // glTF after OBJ, and OBJ after glTF.
        let e = message(load(&["quad.obj", "quad.obj", "tri.gltf"], 4));
        assert!(
            e.contains(
                "tri.gltf: its node tree would make 1 triangles, and the scene's earlier meshes 4"
            ),
            "{e}"
        );
        let e = message(load(&["tri.gltf", "tri.gltf", "quad.obj"], 3));
        assert!(
            e.contains("quad.obj: its faces make 2 triangles, and the scene's earlier meshes 2"),
            "{e}"
        );
        assert_eq!(
            load(&["tri.gltf", "tri.gltf", "tri.gltf"], 3)
                .unwrap()
                .triangles
                .len(),
            3
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}
