//! glTF 2.0 meshes (`.gltf` JSON and `.glb` binary) for a scene's `[[mesh]]`, read with
//! the `gltf` crate into the loader's shapes: world-space [`Triangle`]s with their
//! [`TriAttributes`] (texture coordinates, vertex colours), materials by name (diffuse +
//! perfect mirror, see [`pbr_to_material`], with a base colour [`Texture`] and an alpha
//! mode) and KHR_lights_punctual point lights as [`PointLight`]s in W/sr. The loader (`loader.rs`) calls [`load_gltf_bytes`]
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
//!   `default_material`, which the loader applies). Base colour = `baseColorFactor.rgb`;
//!   `baseColorTexture` (sRGB RGBA8, its sampler, KHR_texture_transform) and COLOR_0
//!   multiply it where the renderer shades. alphaMode MASK is a cut-out at `alphaCutoff`,
//!   BLEND one at 0.5 (with a warning), OPAQUE ignores alpha.
//! - Attributes: KHR_mesh_quantization's integer positions, normals and texture
//!   coordinates are read as the values they stand for; the TEXCOORD_n set a material's
//!   texture reads, and COLOR_0, become per-triangle attributes.
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
//!
//! Work follows the file's size: the node tree is walked and the triangles it would make
//! are counted (against the scene's [`MAX_TRIANGLES`](super::loader::MAX_TRIANGLES))
//! before any accessor is read; accessors, primitives and images are read once however
//! many nodes, primitives or materials use them; accessors without a buffer view are
//! bounded by [`MAX_VIEWLESS_ELEMENTS`].

mod accessors;
mod document;
mod instancing;
mod materials;
mod messages;
mod nodes;

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

use glam::Vec3;

use super::loader::{SceneError, TriangleBudget};
use super::{Alpha, PointLight, TriAttributes, Triangle};
use crate::texture::{Texture, TextureRef};

use accessors::ReadStats;
use document::read;
pub use materials::DEFAULT_ALPHA_CUTOFF;
use messages::parse;

/// Luminous efficacy used to turn glTF photometric intensities (candela = lm/sr) into
/// radiant ones (W/sr): the 683 lm/W of the SI definition of the candela.
pub const LUMENS_PER_WATT: f32 = 683.0;

/// A metallic material is a perfect mirror only when its roughness is below this;
/// rougher metal is treated as diffuse (the renderer has no glossy lobe).
pub const MIRROR_MAX_ROUGHNESS: f32 = 0.2;

/// The material of primitives that name none (glTF's default material: base colour 1,
/// metallic 1, roughness 1, hence diffuse 1 and no mirror).
pub const DEFAULT_MATERIAL: &str = "gltf:default";

/// How far from 1 the length of a node's rotation quaternion may be: further is an error,
/// closer is normalised. The value is the Khronos glTF-Validator's (`ROTATION_NON_UNIT`,
/// an error there too), slightly more than the error of quaternions quantised to signed
/// 8 bits; float rotations written with 6 or more digits are within 1e-5 of unit length,
/// and even 3 decimals stay within 1e-3, so only a rotation that is not one is refused.
pub const MAX_ROTATION_LENGTH_ERROR: f32 = 0.00769;

/// Elements that the accessors without a buffer view (zeros, or sparse values over zeros)
/// of one file may declare in all (1,048,576: 12 MiB as positions). Such a count is paid
/// for by no bytes of the file, so a 1.5 KB file could ask for gigabytes; real files use
/// them for small sparse edits (mostly of morph targets, which are not read).
pub const MAX_VIEWLESS_ELEMENTS: usize = 1 << 20;

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
    /// The base colour texture; [`TextureRef::texture`] indexes [`GltfMesh::textures`].
    pub texture: Option<TextureRef>,
    /// Whether a primitive that uses it has COLOR_0.
    pub vertex_colors: bool,
    /// OPAQUE, or MASK (and BLEND) as a cut-out; a mask without texture and vertex colours
    /// is settled here: opaque where its factor passes the cutoff.
    pub alpha: Alpha,
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
    /// The base colour textures of the materials (sRGB), one per image source.
    pub textures: Vec<Texture>,
    /// Empty, or one per triangle of [`GltfMesh::triangles`] where some material uses
    /// texture coordinates or vertex colours (NONE for the others).
    pub attributes: Vec<TriAttributes>,
    /// KHR_lights_punctual point lights of the scene, intensity in W/sr.
    pub lights: Vec<PointLight>,
    /// Files read besides the glTF file itself: external buffers and images.
    pub files: Vec<PathBuf>,
    /// What the file holds that igi does not render, one entry a feature (said in one
    /// warning, "ignored: ..."), e.g. "COLOR_0 vertex colours (1 primitive)".
    pub ignored: Vec<String>,
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
/// and images (relative to its directory). Its node tree may make at most
/// [`MAX_TRIANGLES`](crate::scene::loader::MAX_TRIANGLES) triangles.
pub fn load_gltf_bytes(bytes: &[u8], path: &Path) -> Result<GltfMesh, SceneError> {
    load_gltf_within(bytes, path, TriangleBudget::default())
}

/// [`load_gltf_bytes`] for a scene whose earlier meshes used part of `budget`.
pub(super) fn load_gltf_within(
    bytes: &[u8],
    path: &Path,
    budget: TriangleBudget,
) -> Result<GltfMesh, SceneError> {
    load_counted(bytes, path, budget).map(|(mesh, _)| mesh)
}

/// [`load_gltf_within`], with what reading took.
fn load_counted(
    bytes: &[u8],
    path: &Path,
    budget: TriangleBudget,
) -> Result<(GltfMesh, ReadStats), SceneError> {
    let file = path.display().to_string();
    // A last resort: every known panic of the gltf crate is prevented by checks below.
    match catch_unwind(AssertUnwindSafe(|| read(bytes, path, &file, budget))) {
        Ok(result) => result,
        Err(_) => Err(parse(
            &file,
            "internal error: the glTF reader (gltf crate) failed on this file",
        )),
    }
}

/// The glTF builder of the integration tests, for the tests below.
#[cfg(test)]
#[path = "../../tests/common/gltf_builder.rs"]
mod test_builder;

#[cfg(test)]
mod tests {
    use super::document::percent_decode;
    use super::nodes::triangulate;
    use super::*;
    use crate::texture::srgb_to_linear;
    use ::gltf::mesh::Mode;

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

    use super::test_builder as builder;
    use builder::{quad, Gltf, QUAD_INDICES};

    /// Loads `g` (as `t.gltf` in a temp dir holding `files`), with what reading took.
    fn load_counting(g: &Gltf, files: &[(&str, &[u8])]) -> (GltfMesh, ReadStats) {
        static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
        let n = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let dir = std::env::temp_dir().join(format!("igi-gltf-unit-{}-{n}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for (name, bytes) in files {
            std::fs::write(dir.join(name), bytes).unwrap();
        }
        let r = load_counted(&g.gltf(), &dir.join("t.gltf"), TriangleBudget::default());
        let _ = std::fs::remove_dir_all(&dir);
        r.unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn accessors_shared_by_nodes_and_primitives_are_read_once() {
        // The quad with normals, placed by 40 nodes; a second mesh whose two primitives
        // share the quad's POSITION and indices.
        let mut g = quad(None);
        let n = g.normals(&[[0.0, 0.0, 1.0]; 4]);
        g.meshes[0] = g.meshes[0].replace(
            r#""POSITION": 0"#,
            &format!(r#""POSITION": 0, "NORMAL": {n}"#),
        );
        g.mesh(&[
            builder::primitive(0, Some(1), ""),
            builder::primitive(0, Some(1), r#", "mode": 4"#),
        ]);
        let nodes = 40;
        for k in 0..nodes {
            g.node(&format!(r#""mesh": 0, "translation": [{k}.0, 0.0, 0.0]"#));
        }
        g.node(r#""mesh": 1"#);
        g.roots = (0..=nodes).collect();
        let (mesh, stats) = load_counting(&g, &[]);
        assert_eq!(mesh.triangles.len(), 2 * (nodes + 2));
        assert_eq!(
            stats.accessors_read, 3,
            "POSITION, NORMAL and indices, once each"
        );
        // Each node's copy is where its node puts it.
        for k in 0..nodes {
            assert_eq!(
                mesh.triangles[2 * k].v[1],
                Vec3::new(k as f32 + 1.0, 0.0, 0.0)
            );
        }

        // A sparse accessor without a buffer view used by many nodes: read once too.
        let mut g = Gltf::default();
        let idx: Vec<u8> = [1u16, 2, 3].iter().flat_map(|x| x.to_le_bytes()).collect();
        let vals: Vec<u8> = [[1.0f32, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]]
            .iter()
            .flatten()
            .flat_map(|x| x.to_le_bytes())
            .collect();
        let (iv, vv) = (g.view(&idx), g.view(&vals));
        let count = MAX_VIEWLESS_ELEMENTS / 2;
        let p = g.accessor(format!(
            r#"{{"componentType": 5126, "count": {count}, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0], "sparse": {{"count": 3, "indices": {{"bufferView": {iv}, "componentType": 5123}}, "values": {{"bufferView": {vv}}}}}}}"#
        ));
        let i = g.indices(&QUAD_INDICES);
        g.mesh(&[builder::primitive(p, Some(i), "")]);
        for _ in 0..nodes {
            g.node(r#""mesh": 0"#);
        }
        g.roots = (0..nodes).collect();
        let (mesh, stats) = load_counting(&g, &[]);
        assert_eq!(mesh.triangles.len(), 2 * nodes);
        assert_eq!(stats.accessors_read, 2);
    }

    #[test]
    fn each_image_source_is_decoded_once() {
        let png: &[u8] = &PNG;
        // 30 image entries of one buffer view, 30 of one file (named two ways), one of
        // another view; each with its texture and material, on its own primitive.
        let mut g = quad(None);
        let v = g.view(png);
        let w = g.view(png);
        for k in 0..61 {
            g.images.push(match k {
                0..30 => format!(r#"{{"bufferView": {v}, "mimeType": "image/png"}}"#),
                30..45 => r#"{"uri": "t.png"}"#.to_string(),
                45..60 => r#"{"uri": "./t.png"}"#.to_string(),
                _ => format!(r#"{{"bufferView": {w}, "mimeType": "image/png"}}"#),
            });
            g.material(&format!(
                r#"{{"pbrMetallicRoughness": {{"baseColorTexture": {{"index": {k}}}, "metallicFactor": 0.0}}}}"#
            ));
        }
        let prims: Vec<String> = (0..61)
            .map(|k| builder::primitive(0, Some(1), &format!(r#", "material": {k}"#)))
            .collect();
        g.meshes[0] = format!(r#"{{"primitives": [{}]}}"#, prims.join(", "));
        g.node(r#""mesh": 0"#);
        let (mesh, stats) = load_counting(&g, &[("t.png", png)]);
        assert_eq!(mesh.materials.len(), 61);
        assert_eq!(stats.images_decoded, 3, "one view, one file, another view");
        assert_eq!(mesh.textures.len(), 3);
        let texture = |k: usize| mesh.materials[k].texture.map(|t| t.texture);
        assert!((0..30).all(|k| texture(k) == Some(0)));
        assert!((30..60).all(|k| texture(k) == Some(1)));
        assert_eq!(texture(60), Some(2));
        assert_eq!(mesh.textures[1].levels[0].texels, [[200, 100, 50, 255]]);
        assert_eq!(mesh.files.len(), 1, "{:?}", mesh.files);
    }

    // PNG: a 1x1 PNG.
    include!("../../tests/common/tiny_png.rs");

    #[test]
    fn gltf_paths() {
        assert!(is_gltf_path(Path::new("a/b.GLTF")));
        assert!(is_gltf_path(Path::new("b.glb")));
        assert!(!is_gltf_path(Path::new("b.obj")));
        assert!(!is_gltf_path(Path::new("gltf")));
    }
}
