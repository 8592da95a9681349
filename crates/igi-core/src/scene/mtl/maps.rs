//! MTL texture maps: `map_Kd` (the base colour texture) and `map_d` (its opacity), with
//! the options igi reads (`-clamp`, `-o`, `-s`), decoded with the `image` crate (PNG,
//! JPEG, TGA, BMP) when a face first uses their material. Each image file is decoded once
//! however many materials or MTL files name it (by its canonical path), and each pair of
//! `map_Kd` and `map_d` makes one texture.
//!
//! Conventions: MTL texture coordinates have v upwards; the OBJ reader stores them with
//! v' = 1 - v (glTF's convention, the renderer's), and [`Map::transform`] maps those to
//! the image as the MTL options say. A map that cannot be read or decoded gives one
//! warning naming its file, and the material keeps its colour factor.

use std::collections::HashMap;
use std::io::Cursor;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::rc::Rc;

use glam::Vec2;

use crate::scene::error::{io_message, quote, quote_message, quote_path, Location};
use crate::scene::loader::read_regular_file;
use crate::texture::{Sampler, Texture, TextureRef, UvTransform, Wrap};

/// One `map_Kd` or `map_d` line: its file (relative to the MTL file) and options.
#[derive(Clone, Debug, PartialEq)]
pub(in crate::scene) struct Map {
    pub(in crate::scene) path: PathBuf,
    /// `-clamp on`: coordinates outside [0, 1] take the edge texels.
    pub(in crate::scene) clamp: bool,
    /// `-o` and `-s` as a transform of the OBJ reader's coordinates (v' = 1 - v).
    pub(in crate::scene) transform: UvTransform,
    /// The line, for messages.
    pub(in crate::scene) at: Location,
}

/// A material's maps, read when a face first uses it.
#[derive(Clone, Debug, PartialEq)]
pub(in crate::scene) struct Maps {
    pub(in crate::scene) kd: Option<Map>,
    pub(in crate::scene) d: Option<Map>,
}

/// How many numbers each option of a map line takes (`-o`, `-s` and `-t` one to three:
/// as many as follow), from the MTL specification.
fn option_arguments(option: &str) -> Option<(usize, usize)> {
    Some(match option {
        "-o" | "-s" | "-t" => (1, 3),
        "-mm" => (2, 2),
        "-blendu" | "-blendv" | "-boost" | "-texres" | "-clamp" | "-bm" | "-imfchan" | "-type"
        | "-cc" => (1, 1),
        _ => return None,
    })
}

/// Reads the text after `map_Kd` or `map_d`: options, then the file name (the rest of
/// the line, so that a name with spaces is kept). Options igi does not use are skipped
/// with their arguments; an unknown one is skipped alone, with a warning.
pub(in crate::scene) fn parse_map(args: &str, dir: &Path, at: Location) -> Map {
    let words: Vec<&str> = args.split_whitespace().collect();
    let mut clamp = false;
    let mut offset = [0.0f32, 0.0];
    let mut scale = [1.0f32, 1.0];
    let mut k = 0;
    // The file name is the last word at least, even when it starts with '-'.
    while k + 1 < words.len() && words[k].starts_with('-') {
        let option = words[k];
        k += 1;
        let Some((least, most)) = option_arguments(option) else {
            log::warn!(
                "{at}: unknown texture map option '{}' ignored",
                quote(option)
            );
            continue;
        };
        // Numbers (for -o, -s, -t: as many as follow, up to three), or the one word.
        let mut taken: Vec<&str> = Vec::new();
        while taken.len() < most && k + 1 < words.len() {
            let w = words[k];
            let is_number = w.parse::<f32>().is_ok();
            if taken.len() >= least && !is_number {
                break;
            }
            taken.push(w);
            k += 1;
        }
        let numbers: Vec<f32> = taken.iter().filter_map(|w| w.parse().ok()).collect();
        // u, and v with the specification's default where one number is given (w unused).
        let uv = |default: f32| {
            [
                numbers.first().copied().unwrap_or(default),
                numbers.get(1).copied().unwrap_or(default),
            ]
        };
        let finite = numbers.iter().all(|x| x.is_finite());
        match option {
            "-clamp" => clamp = taken.first() == Some(&"on"),
            "-o" if finite => offset = uv(0.0),
            "-s" if finite => scale = uv(1.0),
            "-o" | "-s" => log::warn!(
                "{at}: texture map option {option} with numbers that are not finite ignored"
            ),
            _ => {}
        }
    }
    let name = words[k.min(words.len().saturating_sub(1))..].join(" ");
    Map {
        path: dir.join(name),
        clamp,
        transform: mtl_transform(Vec2::from(offset), Vec2::from(scale)),
        at,
    }
}

/// The MTL options' lookup, U = s u + o and V = s v + o in MTL coordinates (v upwards), as
/// a transform of coordinates stored with v' = 1 - v and looked up as glTF's (v down):
/// u' = s_u u + o_u, v'' = 1 - (s_v (1 - v') + o_v) = s_v v' + (1 - s_v - o_v).
pub(in crate::scene) fn mtl_transform(offset: Vec2, scale: Vec2) -> UvTransform {
    UvTransform::from_offset_rotation_scale(
        Vec2::new(offset.x, 1.0 - scale.y - offset.y),
        0.0,
        scale,
    )
}

/// A decoded image file: RGBA8 rows from the top, and whether the file had alpha.
struct Image {
    width: u32,
    height: u32,
    texels: Vec<[u8; 4]>,
    has_alpha: bool,
}

/// The files of a material's `map_Kd` and `map_d`, by canonical path.
type MapFiles = (Option<PathBuf>, Option<PathBuf>);

/// The scene's textures as the loader gathers them: glTF ones as they come, MTL maps on
/// first use (decoded once per file), and the texture files read.
#[derive(Default)]
pub(in crate::scene) struct Textures {
    pub(in crate::scene) list: Vec<Texture>,
    /// Texture files read (for `Scene::files`), in order of first use.
    pub(in crate::scene) files: Vec<PathBuf>,
    /// By canonical path (the path as written where it has none): `None` could not be
    /// read or decoded (its warning given).
    images: HashMap<PathBuf, Option<Rc<Image>>>,
    /// (map_Kd, map_d) files -> the texture they make, and whether map_d is in it.
    made: HashMap<MapFiles, Option<(u32, bool)>>,
    /// How many images were decoded, for the tests that check the sharing.
    pub(in crate::scene) decoded: usize,
}

impl Textures {
    pub(in crate::scene) fn push(&mut self, texture: Texture) -> u32 {
        self.list.push(texture);
        self.list.len() as u32 - 1
    }

    /// The texture of a material's maps, and whether its alpha is the `map_d` (which is
    /// not when it is missing, cannot be decoded or has another size than the `map_Kd`,
    /// each said in a warning); `None` when neither map can be used.
    pub(in crate::scene) fn maps(
        &mut self,
        maps: &Maps,
        material: &str,
    ) -> Option<(TextureRef, bool)> {
        // Keyed by the files that could be decoded (canonical paths).
        let mut key: MapFiles = (None, None);
        let kd = maps.kd.as_ref().and_then(|m| {
            let (file, image) = self.image(m, material);
            let image = image?;
            key.0 = Some(file);
            Some((m, image))
        });
        let mut d = maps.d.as_ref().and_then(|m| {
            let (file, image) = self.image(m, material);
            let image = image?;
            key.1 = Some(file);
            Some((m, image))
        });
        if let (Some((km, ki)), Some((dm, di))) = (&kd, &d) {
            if (ki.width, ki.height) != (di.width, di.height) {
                log::warn!(
                    "{}: map_d '{}' is {} x {} but map_Kd '{}' of material '{}' is {} x {}: map_d ignored",
                    dm.at,
                    quote_path(&dm.path.display().to_string()),
                    di.width,
                    di.height,
                    quote_path(&km.path.display().to_string()),
                    quote(material),
                    ki.width,
                    ki.height
                );
                d = None;
                key.1 = None;
            }
        }
        // The map whose options the texture takes: map_Kd's, or map_d's alone.
        let lead = kd.as_ref().or(d.as_ref()).map(|(m, _)| *m)?;
        let sampler = Sampler {
            wrap_s: if lead.clamp {
                Wrap::ClampToEdge
            } else {
                Wrap::Repeat
            },
            wrap_t: if lead.clamp {
                Wrap::ClampToEdge
            } else {
                Wrap::Repeat
            },
            ..Sampler::DEFAULT
        };
        let made = match self.made.get(&key) {
            Some(&made) => made,
            None => {
                let made = self.make(kd.as_ref(), d.as_ref());
                self.made.insert(key, made);
                made
            }
        };
        made.map(|(texture, with_d)| {
            (
                TextureRef {
                    texture,
                    sampler,
                    transform: lead.transform,
                },
                with_d,
            )
        })
    }

    /// A texture of `map_Kd`'s colour (alpha 255: MTL's opacity is `d` and `map_d`) and
    /// `map_d`'s opacity (its alpha channel where it has one, else its first channel).
    fn make(
        &mut self,
        kd: Option<&(&Map, Rc<Image>)>,
        d: Option<&(&Map, Rc<Image>)>,
    ) -> Option<(u32, bool)> {
        let opacity = |img: &Image, k: usize| {
            let t = img.texels[k];
            if img.has_alpha {
                t[3]
            } else {
                t[0]
            }
        };
        let (name, w, h, texels, with_d) = match (kd, d) {
            // Of one size: `maps` dropped a map_d of another.
            (Some((km, ki)), Some((dm, di))) => {
                let texels = (0..ki.texels.len())
                    .map(|k| {
                        let [r, g, b, _] = ki.texels[k];
                        [r, g, b, opacity(di, k)]
                    })
                    .collect();
                let name = format!("{} with map_d {}", km.path.display(), dm.path.display());
                (name, ki.width, ki.height, texels, true)
            }
            (Some((km, ki)), _) => {
                let texels = ki
                    .texels
                    .iter()
                    .map(|&[r, g, b, _]| [r, g, b, 255])
                    .collect();
                (
                    km.path.display().to_string(),
                    ki.width,
                    ki.height,
                    texels,
                    false,
                )
            }
            (None, Some((dm, di))) => {
                let texels = (0..di.texels.len())
                    .map(|k| [255, 255, 255, opacity(di, k)])
                    .collect();
                (
                    dm.path.display().to_string(),
                    di.width,
                    di.height,
                    texels,
                    true,
                )
            }
            (None, None) => return None,
        };
        match Texture::new(name, w, h, true, texels) {
            Ok(t) => Some((self.push(t), with_d)),
            Err(why) => {
                let at = kd.or(d).map(|(m, _)| m.at.clone());
                log::warn!(
                    "{}: {}; the material keeps its colour factor",
                    at.map_or(String::new(), |a| a.to_string()),
                    quote_message(&why)
                );
                None
            }
        }
    }

    /// The decoded image of a map's file, read once, with the file's canonical path (as
    /// written where it has none); `None`, with one warning naming the file, when it
    /// cannot be read or decoded.
    fn image(&mut self, map: &Map, material: &str) -> (PathBuf, Option<Rc<Image>>) {
        // Exporters on Windows write `textures\wood.png`: where that names no file, the
        // backslashes are read as separators.
        let mut path = map.path.clone();
        let written = path.to_string_lossy().into_owned();
        if !path.exists() && written.contains('\\') {
            path = PathBuf::from(written.replace('\\', "/"));
        }
        let key = std::fs::canonicalize(&path).unwrap_or_else(|_| path.clone());
        if let Some(image) = self.images.get(&key) {
            return (key, image.clone());
        }
        let image = match decode(&path) {
            Ok(image) => {
                self.decoded += 1;
                self.files.push(path);
                Some(Rc::new(image))
            }
            Err(why) => {
                log::warn!(
                    "{}: cannot read texture '{}' of material '{}': {}; the material keeps its colour factor",
                    map.at,
                    quote_path(&path.display().to_string()),
                    quote(material),
                    quote_message(&why)
                );
                None
            }
        };
        self.images.insert(key.clone(), image.clone());
        (key, image)
    }
}

/// Decodes an image file with the `image` crate: the format its content shows (PNG, JPEG,
/// BMP), else the one its extension names (TGA has no signature). The crate's default
/// limits hold (512 MiB decoded), and a decoder's panic is an error like any other.
fn decode(path: &Path) -> Result<Image, String> {
    let bytes = read_regular_file(path).map_err(|e| io_message(&e))?;
    let mut reader = image::ImageReader::new(Cursor::new(&bytes[..]));
    if let Ok(format) = image::ImageFormat::from_path(path) {
        reader.set_format(format);
    }
    let reader = reader.with_guessed_format().map_err(|e| e.to_string())?;
    let decoded = catch_unwind(AssertUnwindSafe(|| reader.decode()))
        .map_err(|_| "the image decoder failed".to_string())?
        .map_err(|e| e.to_string())?;
    let has_alpha = decoded.color().has_alpha();
    let rgba = decoded.to_rgba8();
    Ok(Image {
        width: rgba.width(),
        height: rgba.height(),
        texels: rgba.pixels().map(|p| p.0).collect(),
        has_alpha,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn map(args: &str) -> Map {
        parse_map(args, Path::new("d"), Location::line("m.mtl", 3))
    }

    #[test]
    fn map_options_and_file_names() {
        let m = map("-clamp on -o 0.25 0.5 -s 2 4 1 tex/wood grain.png");
        assert!(m.clamp);
        assert_eq!(m.path, Path::new("d/tex/wood grain.png"));
        assert_eq!(
            m.transform,
            mtl_transform(Vec2::new(0.25, 0.5), Vec2::new(2.0, 4.0))
        );
        let plain = map("wood.png");
        assert_eq!(plain.path, Path::new("d/wood.png"));
        assert!(!plain.clamp);
        assert_eq!(plain.transform, UvTransform::IDENTITY);
        // Options igi does not use are skipped with their arguments.
        let m = map("-bm 0.5 -mm 0 1 -imfchan l -clamp off -blendu on x.tga");
        assert_eq!(m.path, Path::new("d/x.tga"));
        assert!(!m.clamp);
        // A name that starts with '-' after the options is still the name.
        assert_eq!(map("-x").path, Path::new("d/-x"));
    }

    #[test]
    fn mtl_options_map_mtl_coordinates_as_the_specification_says() {
        // MTL: U = 2u + 0.25, V = 4v + 0.5 with v up. A point stored as (u, 1 - v).
        let t = mtl_transform(Vec2::new(0.25, 0.5), Vec2::new(2.0, 4.0));
        let (u, v) = (0.3f32, 0.1f32);
        let looked_up = t.apply(Vec2::new(u, 1.0 - v));
        let expect = Vec2::new(2.0 * u + 0.25, 1.0 - (4.0 * v + 0.5));
        assert!((looked_up - expect).length() < 1e-6, "{looked_up} {expect}");
        assert_eq!(mtl_transform(Vec2::ZERO, Vec2::ONE), UvTransform::IDENTITY);
    }
}
