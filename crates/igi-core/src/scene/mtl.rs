//! MTL material libraries and the resolution of a material name: an MTL (or glTF)
//! definition with `[materials.NAME]` of the scene file laid over it key by key, checked
//! to be a valid albedo. MTL text is checked line by line before tobj reads it.

use std::collections::{BTreeMap, HashMap, HashSet};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

use glam::Vec3;
use toml::Spanned;

use super::error::{as_lenient_text, excerpt, fmt3, quote, Location, SceneError, CHANNELS};
use super::obj::{strip_comments, Slot};
use super::toml_file::{MaterialDesc, TomlFile, V3};
use super::Material;

/// Slack allowed on `diffuse + mirror <= 1` (per channel), for values written with few
/// digits such as 0.35 + 0.65.
const ALBEDO_SLACK: f32 = 1e-6;

/// Materials read from MTL files, by name (first definition wins across files).
#[derive(Default)]
pub(super) struct MtlTable {
    pub(super) defs: HashMap<String, MtlDef>,
    /// MTL files already read (a file named by several meshes is read once).
    pub(super) read: HashSet<PathBuf>,
}

pub(super) struct MtlDef {
    pub(super) kd: Option<[f32; 3]>,
    pub(super) ks: Option<[f32; 3]>,
    pub(super) illum: Option<u8>,
    /// The `newmtl` line.
    pub(super) at: Location,
    /// Made from a glTF material (glTF hook): `kd`/`ks` are its diffuse/mirror, `illum` 3.
    pub(super) gltf: bool,
}

impl MtlDef {
    pub(super) fn diffuse(&self) -> [f32; 3] {
        self.kd.unwrap_or([0.0; 3])
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
/// `Ok(None)` when neither defines it.
pub(super) fn resolve_material(
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
    Ok(Some(Material::new(
        full_name,
        Vec3::from(diffuse.value),
        Vec3::from(mirror.value),
    )))
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
    Ok(())
}

/// Checks the MTL lines that `tobj::load_mtl_buf` parses strictly, so that its errors come
/// with a line number and its panic (a colour of fewer than three numbers) cannot happen.
/// Returns the line of each `newmtl` (the last one for a repeated name).
pub(super) fn check_mtl(text: &str, file: &str) -> Result<HashMap<String, usize>, SceneError> {
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
