//! MTL material libraries and the resolution of a material name: an MTL (or glTF)
//! definition with `[materials.NAME]` of the scene file laid over it key by key, checked
//! to be a valid albedo, with its texture (MTL maps are read in `maps` when a face first
//! uses them) and alpha. MTL text is checked line by line before tobj reads it.

pub(super) mod maps;

use std::collections::{BTreeMap, HashMap, HashSet};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

use glam::Vec3;
use toml::Spanned;

use super::error::{as_lenient_text, excerpt, fmt3, quote, Location, SceneError, CHANNELS};
use super::loader::settled_alpha;
use super::obj::{strip_comments, Slot};
use super::toml_file::{MaterialDesc, TomlFile, V3};
use super::{Alpha, AlphaMode, Material};
use crate::texture::TextureRef;
use maps::{parse_map, Maps, Textures};

/// The cutoff of MTL materials that `d` or `map_d` makes partly transparent: drawn as
/// cut-outs (the renderer does not blend).
pub(super) const MTL_ALPHA_CUTOFF: f32 = 0.5;

/// Slack allowed on `diffuse + mirror <= 1` (per channel), for values written with few
/// digits such as 0.35 + 0.65.
const ALBEDO_SLACK: f32 = 1e-6;

/// Materials read from MTL files, by name (first definition wins across files).
#[derive(Default)]
pub(super) struct MtlTable {
    pub(super) defs: HashMap<String, MtlDef>,
    /// MTL files already read (a file named by several meshes is read once).
    pub(super) read: HashSet<PathBuf>,
    /// The scene's textures: glTF files' as they are read, MTL maps on first use.
    pub(super) textures: Textures,
}

/// A definition's base colour texture.
pub(super) enum DefTexture {
    None,
    /// In the table's textures (a glTF texture, or MTL maps once read).
    Ready(TextureRef),
    /// MTL `map_Kd` and `map_d`, read when a face first uses the material.
    Maps(Maps),
}

pub(super) struct MtlDef {
    pub(super) kd: Option<[f32; 3]>,
    pub(super) ks: Option<[f32; 3]>,
    pub(super) illum: Option<u8>,
    /// The `newmtl` line.
    pub(super) at: Location,
    /// Made from a glTF material (glTF hook): `kd`/`ks` are its diffuse/mirror, `illum` 3.
    pub(super) gltf: bool,
    pub(super) texture: DefTexture,
    pub(super) vertex_colors: bool,
    /// glTF: the material's; MTL: a cut-out at [`MTL_ALPHA_CUTOFF`] of opacity `d` (`1 -
    /// Tr`) where that is below 1 or there is a `map_d`, otherwise opaque.
    pub(super) alpha: Alpha,
}

impl MtlDef {
    pub(super) fn diffuse(&self) -> [f32; 3] {
        self.kd.unwrap_or([0.0; 3])
    }

    /// Whether its faces need texture coordinates (decided before its maps are read).
    pub(super) fn textured(&self) -> bool {
        !matches!(self.texture, DefTexture::None)
    }

    /// `Ks` is a perfect mirror only for the ray-traced illumination models 3, 5 and 7.
    pub(super) fn mirror(&self) -> [f32; 3] {
        match self.illum {
            Some(3 | 5 | 7) => self.ks.unwrap_or([0.0; 3]),
            _ => [0.0; 3],
        }
    }
}

/// One value of a material and where it comes from, for messages.
pub(super) struct Sourced {
    pub(super) value: [f32; 3],
    pub(super) at: Location,
    pub(super) what: String,
    pub(super) from_toml: bool,
}

/// The material `name`: the MTL's values replaced key by key by `[materials.NAME]`.
/// `Ok(None)` when neither defines it. Its MTL maps are read (once) when `for_faces`: a
/// face uses it; otherwise it is only checked.
///
/// The texture and vertex colours of the definition are kept unless `[materials.NAME]`
/// sets `diffuse` or `mirror` (a constant colour replaces them); `texture = false` there
/// replaces the texture by its mean colour (the factors times it) and makes the material
/// opaque.
pub(super) fn resolve_material(
    tf: &TomlFile,
    name: &str,
    toml_mats: &BTreeMap<String, Spanned<MaterialDesc>>,
    mtl: &mut MtlTable,
    for_faces: bool,
) -> Result<Option<Material>, SceneError> {
    let over = toml_mats.get(name);
    let toml_d = over.and_then(|o| o.get_ref().diffuse.as_ref());
    let toml_m = over.and_then(|o| o.get_ref().mirror.as_ref());
    // A colour set in the scene file replaces the texture and the vertex colours.
    let constant = toml_d.is_some() || toml_m.is_some();
    let texture = if for_faces && !constant {
        texture_of(mtl, name)
    } else {
        None
    };
    let base = mtl.defs.get(name);
    if over.is_none() && base.is_none() {
        return Ok(None);
    }
    // Messages quote the name shortened; the material keeps it whole.
    let full_name = name;
    let name = &quote(full_name);
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
    let mut m = Material::new(
        full_name,
        Vec3::from(diffuse.value),
        Vec3::from(mirror.value),
    );
    if let Some(b) = base {
        m.alpha = b.alpha;
        if !constant {
            m.vertex_colors = b.vertex_colors;
        }
    }
    m.texture = texture;
    if over
        .and_then(|o| o.get_ref().texture.as_ref())
        .is_some_and(|t| !*t.get_ref())
    {
        match m.texture.take() {
            Some(t) => {
                let mean = mtl.textures.list[t.texture as usize].mean().truncate();
                m.diffuse *= mean;
                m.mirror *= mean;
            }
            None if for_faces && !constant => log::warn!(
                "{}: [materials.{name}] texture = false, but material '{name}' has no texture",
                tf.name
            ),
            None => {}
        }
        m.alpha = Alpha::OPAQUE;
    }
    m.alpha = settled_alpha(m.alpha, m.texture.is_some(), m.vertex_colors);
    Ok(Some(m))
}

/// The texture of definition `name`, its MTL maps read on first use and kept as read
/// (so that their warnings are given once). A `map_d` that cannot be used makes no
/// cut-out: then `d` alone decides the alpha.
fn texture_of(mtl: &mut MtlTable, name: &str) -> Option<TextureRef> {
    let def = mtl.defs.get_mut(name)?;
    match &def.texture {
        DefTexture::None => None,
        DefTexture::Ready(t) => Some(*t),
        DefTexture::Maps(maps) => {
            let made = mtl.textures.maps(maps, name);
            let with_d = made.is_some_and(|(_, with_d)| with_d);
            if maps.d.is_some() && !with_d && def.alpha.factor >= 1.0 {
                def.alpha = Alpha::OPAQUE;
            }
            let t = made.map(|(t, _)| t);
            def.texture = t.map_or(DefTexture::None, DefTexture::Ready);
            t
        }
    }
}
pub(super) fn undefined_material(
    tf: &TomlFile,
    name: &str,
    how: &str,
    at: Location,
    slot: &Slot,
) -> SceneError {
    let name = quote(name);
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
pub(super) fn read_mtl(bytes: &[u8], path: &Path, table: &mut MtlTable) -> Result<(), SceneError> {
    let file = path.display().to_string();
    let text = as_lenient_text(bytes, &file)?;
    let text = strip_comments(text.as_ref());
    let text = text.as_ref();
    let lines = check_mtl(text, &file)?;
    let dir = path.parent().unwrap_or(Path::new(""));
    let mut partly_transparent = 0usize;
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
        let at_line =
            |f: fn(&MtlLines) -> usize| Location::line(&file, lines.get(&m.name).map_or(1, f));
        let maps = Maps {
            kd: m
                .diffuse_texture
                .as_ref()
                .map(|a| parse_map(a, dir, at_line(|l| l.map_kd))),
            d: m.dissolve_texture
                .as_ref()
                .map(|a| parse_map(a, dir, at_line(|l| l.map_d))),
        };
        // `d` is the opacity, `Tr` (transparency) its complement; `d` where both are given.
        let tr = m
            .unknown_param
            .get("Tr")
            .and_then(|t| t.parse::<f32>().ok());
        let opacity = m.dissolve.or(tr.map(|t| 1.0 - t)).unwrap_or(1.0);
        let alpha = if opacity < 1.0 || maps.d.is_some() {
            partly_transparent += 1;
            Alpha {
                mode: AlphaMode::Mask {
                    cutoff: MTL_ALPHA_CUTOFF,
                },
                factor: opacity,
            }
        } else {
            Alpha::OPAQUE
        };
        let def = MtlDef {
            // With a map_Kd and no Kd, the texture alone.
            kd: m.diffuse.or(maps.kd.as_ref().map(|_| [1.0; 3])),
            ks: m.specular,
            illum: m.illumination_model,
            at: at_line(|l| l.newmtl),
            gltf: false,
            texture: if maps.kd.is_some() || maps.d.is_some() {
                DefTexture::Maps(maps)
            } else {
                DefTexture::None
            },
            vertex_colors: false,
            alpha,
        };
        match table.defs.get(&m.name) {
            Some(old) => {
                if old.diffuse() != def.diffuse() || old.mirror() != def.mirror() {
                    log::warn!(
                        "{}: material '{}' is also defined in {} with other values; the first definition is used",
                        def.at,
                        quote(&m.name),
                        old.at
                    );
                }
            }
            None => {
                table.defs.insert(m.name.clone(), def);
            }
        }
    }
    if partly_transparent > 0 {
        log::warn!(
            "{file}: {partly_transparent} materials with d (or Tr) below 1 or a map_d: partial transparency is drawn as a cut-out at opacity {MTL_ALPHA_CUTOFF} (igi does not blend: a point is there where its opacity is at least {MTL_ALPHA_CUTOFF}, and cut out elsewhere)"
        );
    }
    Ok(())
}

/// Where a material's lines are in its MTL file (of its last definition there).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct MtlLines {
    pub(super) newmtl: usize,
    pub(super) map_kd: usize,
    pub(super) map_d: usize,
}

/// Checks the MTL lines that `tobj::load_mtl_buf` parses strictly, so that its errors come
/// with a line number and its panic (a colour of fewer than three numbers) cannot happen;
/// and the opacities igi reads (`d`, `Tr`), which must lie in [0, 1]. Returns the lines of
/// each material (of the last definition of a repeated name).
pub(super) fn check_mtl(text: &str, file: &str) -> Result<HashMap<String, MtlLines>, SceneError> {
    let mut newmtl: HashMap<String, MtlLines> = HashMap::new();
    let mut current: Option<String> = None;
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
                    let lines = MtlLines {
                        newmtl: ln,
                        ..MtlLines::default()
                    };
                    newmtl.insert(name.to_string(), lines);
                    current = Some(name.to_string());
                }
                name.is_empty()
                    .then(|| "newmtl without a material name".to_string())
            }
            "Ka" | "Kd" | "Ks" | "Ke" => (!(0..3).all(|_| number(words.next())))
                .then(|| format!("{key} needs three numbers (r g b)")),
            "Ns" | "Ni" => (!number(words.next())).then(|| format!("{key} needs a number")),
            "d" | "Tr" => match words.next().map(|w| w.parse::<f32>()) {
                Some(Ok(x)) if (0.0..=1.0).contains(&x) => None,
                Some(Ok(_)) => Some(format!(
                    "{key} must be in [0, 1] ({}: 1 is opaque, 0 invisible)",
                    if key == "d" {
                        "opacity"
                    } else {
                        "transparency, 1 - d: 0 is opaque"
                    }
                )),
                _ => Some(format!("{key} needs a number")),
            },
            "illum" => words
                .next()
                .is_none_or(|w| w.parse::<u8>().is_err())
                .then(|| "illum needs an integer from 0 to 10".to_string()),
            "map_Ka" | "map_Kd" | "map_Ks" | "map_Bump" | "map_bump" | "map_Ns" | "map_ns"
            | "map_NS" | "bump" | "map_d" => {
                let at = current.as_ref().and_then(|c| newmtl.get_mut(c));
                match (key, at) {
                    ("map_Kd", Some(l)) => l.map_kd = ln,
                    ("map_d", Some(l)) => l.map_d = ln,
                    _ => {}
                }
                line.get(key.len()..)
                    .unwrap_or("")
                    .trim()
                    .is_empty()
                    .then(|| format!("{key} without a file name"))
            }
            _ => None,
        };
        if let Some(problem) = problem {
            return Err(bad(&problem));
        }
    }
    Ok(newmtl)
}

#[cfg(test)]
mod tests {
    use super::*;

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
