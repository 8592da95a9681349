//! The glTF document: parsing the JSON or GLB (with the checks that keep the gltf crate
//! from panicking), the whole read of one file, and the warnings reported once per file.

use std::borrow::Cow;
use std::collections::HashMap;
use std::path::Path;

use ::gltf::json::deserialize::from_slice;
use ::gltf::json::Root;
use ::gltf::Semantic;

use super::accessors::{ReadStats, Reader, Shared};
use super::messages::{document_error, invalid, parse};
use super::GltfMesh;
use crate::scene::error::quote;
use crate::scene::loader::{settled_alpha, SceneError, TriangleBudget};
use crate::scene::TriAttributes;

/// Decodes `%XX` escapes of a relative URI. `None` when the result is not UTF-8 (the gltf
/// crate would panic on such a URI, so it never sees one).
pub(super) fn percent_decode(uri: &str) -> Option<String> {
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
pub(super) fn document(bytes: &[u8], file: &str) -> Result<::gltf::Gltf, SceneError> {
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
    let error = |e: ::gltf::Error| {
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
    };
    let (json, blob) = if is_glb {
        let glb = ::gltf::binary::Glb::from_slice(bytes).map_err(error)?;
        (glb.json, glb.bin.map(Cow::into_owned))
    } else {
        (Cow::Borrowed(bytes), None)
    };
    // `extras` may be any JSON value (the gltf crate's `extras` feature keeps it raw).
    let mut root = from_slice::<Root>(&json).map_err(|e| error(::gltf::Error::Deserialize(e)))?;
    // Before the validation, whose complaints about what such an extension replaces
    // (accessors without data, images without a source) would not name it.
    required_extensions(&root, file)?;
    // The crate's validation refuses every required extension it does not read itself,
    // and these are read here (accessors of KHR_mesh_quantization's integer types, node
    // instances): it need not see them.
    root.extensions_required
        .retain(|e| !READ_HERE.contains(&e.as_str()));
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

/// Extensions that igi reads itself, beyond those the gltf crate reads
/// (`ENABLED_EXTENSIONS`, which its validation accepts as required).
const READ_HERE: [&str; 2] = ["KHR_mesh_quantization", "EXT_mesh_gpu_instancing"];

/// Error naming every extension the file requires (`extensionsRequired`) that igi does
/// not read, with what it is for the common ones.
fn required_extensions(root: &Root, file: &str) -> Result<(), SceneError> {
    let missing: Vec<String> = root
        .extensions_required
        .iter()
        .filter(|e| {
            !::gltf::json::extensions::ENABLED_EXTENSIONS.contains(&e.as_str())
                && !READ_HERE.contains(&e.as_str())
        })
        .map(|e| match unread_extension(e) {
            Some(what) => format!("{} ({what})", quote(e)),
            None => quote(e),
        })
        .collect();
    if missing.is_empty() {
        return Ok(());
    }
    let (s, them) = if missing.len() == 1 {
        ("", "it")
    } else {
        ("s", "them")
    };
    Err(parse(
        file,
        format!(
            "the file requires (extensionsRequired) the glTF extension{s} {}, which igi does not read; export the model without {them}",
            missing.join(", ")
        ),
    ))
}

/// What a required extension igi does not read is, for its error.
fn unread_extension(name: &str) -> Option<&'static str> {
    Some(match name {
        "KHR_draco_mesh_compression" => "Draco-compressed meshes",
        "EXT_meshopt_compression" => "meshoptimizer-compressed buffers",
        "KHR_texture_basisu" => "KTX2 / Basis Universal textures",
        "EXT_texture_webp" => "WebP textures",
        "MSFT_texture_dds" => "DDS textures",
        _ => return None,
    })
}

/// Reads one glTF file (see [`super::load_gltf_bytes`]) whose triangles must fit in
/// `budget`; with what reading it took.
pub(super) fn read(
    bytes: &[u8],
    path: &Path,
    file: &str,
    budget: TriangleBudget,
) -> Result<(GltfMesh, ReadStats), SceneError> {
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
        uv_sets: Vec::new(),
        textures: HashMap::new(),
        bad_images: image_problems(&document),
        warn: Warnings::default(),
        budget,
        shared: Shared::default(),
        stats: ReadStats::default(),
    };
    r.load_buffers(&document, blob)?;
    let Some(scene) = document
        .default_scene()
        .or_else(|| document.scenes().next())
    else {
        return Err(invalid(file, "the glTF file has no scene to render"));
    };
    r.scene(&document, &scene)?;
    if !r.out.attributes.is_empty() {
        r.out
            .attributes
            .resize(r.out.triangles.len(), TriAttributes::NONE);
    }
    for m in &mut r.out.materials {
        m.alpha = settled_alpha(m.alpha, m.texture.is_some(), m.vertex_colors);
    }
    r.warn.log(file);
    r.out.ignored = ignored_features(&document);
    if !r.out.ignored.is_empty() {
        log::warn!("{file}: ignored: {}", r.out.ignored.join(", "));
    }
    Ok((r.out, r.stats))
}

/// What `doc` holds that igi does not render (see [`GltfMesh::ignored`]), each with how
/// many of its parts use it. Emission, unlit materials, BLEND, skins, morph targets and
/// spot or directional lights have warnings of their own, so none is here.
pub(super) fn ignored_features(doc: &::gltf::Document) -> Vec<String> {
    let json = doc.as_json();
    let mut out = Vec::new();
    let mut say = |n: usize, what: &str, of: &str| {
        if n > 0 {
            let s = if n == 1 { "" } else { "s" };
            out.push(format!("{what} ({n} {of}{s})"));
        }
    };
    // Extensions igi reads (lights, the strength of emission it warns of, instances,
    // texture transforms, quantized attributes, unlit materials).
    const READ: [&str; 6] = [
        "KHR_lights_punctual",
        "KHR_materials_emissive_strength",
        "EXT_mesh_gpu_instancing",
        "KHR_texture_transform",
        "KHR_mesh_quantization",
        "KHR_materials_unlit",
    ];
    // The set a material's base colour texture reads (KHR_texture_transform may change it).
    let base_set = |m: &::gltf::Material| {
        m.pbr_metallic_roughness().base_color_texture().map(|t| {
            t.texture_transform()
                .and_then(|x| x.tex_coord())
                .unwrap_or(t.tex_coord())
        })
    };
    let prims = || doc.meshes().flat_map(|m| m.primitives());
    say(
        prims()
            .filter(|p| {
                p.attributes().any(|(s, _)| s.to_string() == "TEXCOORD_1")
                    && base_set(&p.material()) != Some(1)
            })
            .count(),
        "a second texture coordinate set that no base colour texture reads",
        "primitive",
    );
    say(
        prims()
            .filter(|p| p.attributes().any(|(s, _)| s.to_string() == "COLOR_1"))
            .count(),
        "a second vertex colour set (COLOR_1)",
        "primitive",
    );
    let materials = || doc.materials();
    say(
        materials().filter(|m| m.normal_texture().is_some()).count(),
        "normal maps",
        "material",
    );
    say(
        materials()
            .filter(|m| {
                m.pbr_metallic_roughness()
                    .metallic_roughness_texture()
                    .is_some()
            })
            .count(),
        "metallic-roughness textures",
        "material",
    );
    say(
        materials()
            .filter(|m| m.occlusion_texture().is_some())
            .count(),
        "occlusion textures",
        "material",
    );
    say(json.animations.len(), "animations", "animation");
    say(
        json.cameras.len(),
        "cameras (the scene file's [camera] is used)",
        "camera",
    );
    for e in &json.extensions_used {
        if !READ.contains(&e.as_str()) {
            out.push(format!("extension {}", quote(e)));
        }
    }
    out
}

/// Images that `Image::source()` of gltf 1.4 would `unwrap()` a `None` of: it assumes a
/// `uri` when there is no `bufferView`, and a `mimeType` when there is one (a fuzzing find).
pub(super) fn image_problems(doc: &::gltf::Document) -> HashMap<usize, &'static str> {
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
pub(super) struct Warnings {
    /// Primitives of mode POINTS, LINES, LINE_LOOP, LINE_STRIP.
    pub(super) not_triangles: usize,
    /// Index counts of TRIANGLES primitives that are not a multiple of 3.
    pub(super) leftover_indices: usize,
    pub(super) degenerate: usize,
    pub(super) bad_normals: usize,
    /// Spot and directional lights.
    pub(super) lights_skipped: usize,
    pub(super) emissive: usize,
    pub(super) skinned_or_morphed: usize,
    /// Materials of alphaMode BLEND (drawn as cut-outs).
    pub(super) blend: usize,
    /// KHR_materials_unlit materials (shaded as diffuse).
    pub(super) unlit: usize,
    /// Primitives of a textured material without the texture coordinates it reads.
    pub(super) no_texcoords: usize,
    /// Texture coordinate accessors with values that are not finite (made 0).
    pub(super) bad_texcoords: usize,
    /// COLOR_0 accessors with values outside [0, 1] or not finite (clamped, or 1).
    pub(super) bad_colors: usize,
}

impl Warnings {
    pub(super) fn log(&self, file: &str) {
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
        w(
            self.blend,
            "materials of alphaMode BLEND drawn as cut-outs at alpha 0.5 (igi does not blend: a point is there where its alpha is at least 0.5, and cut out elsewhere)",
        );
        w(
            self.unlit,
            "unlit materials (KHR_materials_unlit) shaded as diffuse surfaces of their base colour (surfaces do not emit)",
        );
        w(
            self.no_texcoords,
            "primitives of textured materials lack the texture coordinates (TEXCOORD_n) the texture reads: they are drawn with the texel at (0, 0)",
        );
        w(
            self.bad_texcoords,
            "texture coordinate accessors hold values that are not finite: those are made 0",
        );
        w(
            self.bad_colors,
            "COLOR_0 accessors hold values outside [0, 1] or not finite: clamped into [0, 1] (1 where not finite)",
        );
    }
}
