//! The scene file's TOML schema (`docs/SCENE_FORMAT.md`): the shapes serde reads it into,
//! with the spans of their values, and the checks of the camera, the film, the lights and
//! the `[materials.NAME]` tables, each failure naming the key and where it is written.

use std::collections::BTreeMap;
use std::ops::Range;

use glam::{DVec3, Vec3};
use serde::Deserialize;
use toml::Spanned;

use super::error::{fmt3, quote, quote_message, Location, SceneError};
use super::{Camera, Film, PointLight};

/// Image size when the scene file has no `[film]` (or leaves a key out).
pub const DEFAULT_FILM: Film = Film {
    width: 800,
    height: 600,
};

/// `camera.up` when the scene file leaves it out.
pub const DEFAULT_UP: Vec3 = Vec3::Y;

pub(super) type V3 = Spanned<Num3>;

/// `[x, y, z]` in the TOML: exactly three numbers, each within the range of f32. Serde's
/// `[f32; 3]` reads three elements and ignores the rest (so `[0, 1, 3.9, 1]` passed), and
/// turns a number beyond the f32 range into inf (so `1e300` was reported as `inf`).
#[derive(Clone, Copy, Debug)]
pub(super) struct Num3(pub(super) [f32; 3]);

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
pub(super) struct SceneDesc {
    pub(super) camera: Spanned<CameraDesc>,
    pub(super) film: Option<FilmDesc>,
    #[serde(default)]
    pub(super) mesh: Vec<MeshDesc>,
    #[serde(default)]
    pub(super) point_light: Vec<LightDesc>,
    #[serde(default)]
    pub(super) materials: BTreeMap<String, Spanned<MaterialDesc>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct CameraDesc {
    pub(super) eye: V3,
    pub(super) target: V3,
    pub(super) up: Option<V3>,
    /// f64, so that a value beyond the f32 range is reported as written, not as inf.
    pub(super) fov_y_deg: Spanned<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct FilmDesc {
    pub(super) width: Option<Spanned<u32>>,
    pub(super) height: Option<Spanned<u32>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct MeshDesc {
    pub(super) path: Spanned<String>,
    pub(super) default_material: Option<Spanned<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct LightDesc {
    pub(super) position: V3,
    pub(super) intensity: V3,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct MaterialDesc {
    pub(super) diffuse: Option<V3>,
    pub(super) mirror: Option<V3>,
    /// `false`: the texture replaced by its mean colour, and the material made opaque.
    pub(super) texture: Option<Spanned<bool>>,
}

/// The TOML text and its name, to turn spans into locations.
pub(super) struct TomlFile<'a> {
    pub(super) text: &'a str,
    pub(super) name: &'a str,
}

impl TomlFile<'_> {
    pub(super) fn at(&self, span: Range<usize>) -> Location {
        Location::offset(self.name, self.text, span.start)
    }

    pub(super) fn invalid(&self, span: Range<usize>, message: impl AsRef<str>) -> SceneError {
        SceneError::invalid(self.at(span), message)
    }

    /// A value as the file writes it (its span), for messages.
    pub(super) fn written(&self, span: Range<usize>) -> String {
        quote(self.text.get(span).unwrap_or(""))
    }

    pub(super) fn finite(&self, v: &V3, key: &str) -> Result<Vec3, SceneError> {
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

/// The toml crate's message, prefixed with the key path where it knows one
/// ("camera.fov_y_deg: invalid type: string \"wide\", expected f32"). The path is not
/// public API, but its `Display` adds a line "in `a.b`" when it has no input text to show.
pub(super) fn toml_message(e: &toml::de::Error) -> String {
    let mut bare = e.clone();
    bare.set_input(None);
    let shown = bare.to_string();
    let keys = shown
        .lines()
        .find_map(|l| l.strip_prefix("in `").and_then(|k| k.strip_suffix('`')));
    let message = match keys {
        Some(k) if !k.is_empty() => format!("{}: {}", quote(k), e.message()),
        _ => e.message().to_string(),
    };
    quote_message(&message)
}

pub(super) fn camera(tf: &TomlFile, c: &Spanned<CameraDesc>) -> Result<Camera, SceneError> {
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

pub(super) fn film(tf: &TomlFile, f: Option<&FilmDesc>) -> Result<Film, SceneError> {
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

pub(super) fn light(tf: &TomlFile, l: &LightDesc) -> Result<PointLight, SceneError> {
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
pub(super) fn light_power_f64(intensity: Vec3) -> f64 {
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
pub(super) fn check_total_power(lights: &[PointLight], name: &str) -> Result<(), SceneError> {
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

pub(super) fn check_toml_material(
    tf: &TomlFile,
    name: &str,
    m: &MaterialDesc,
) -> Result<(), SceneError> {
    for (v, key) in [(&m.diffuse, "diffuse"), (&m.mirror, "mirror")] {
        if let Some(v) = v {
            let a = v.get_ref().0;
            if !a.iter().all(|x| (0.0..=1.0).contains(x)) {
                return Err(tf.invalid(
                    v.span(),
                    format!(
                        "materials.{}.{key} = {}: each channel must be in [0, 1]",
                        quote(name),
                        fmt3(a)
                    ),
                ));
            }
        }
    }
    Ok(())
}
