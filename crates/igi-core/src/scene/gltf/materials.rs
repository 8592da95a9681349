//! glTF materials as diffuse + mirror ([`super::pbr_to_material`]), with the average
//! linear colour of a base colour texture, decoded once per image file or buffer view
//! (however many image entries, textures or materials name it).

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;

use glam::Vec3;

use super::accessors::Reader;
use super::messages::{fmt3, invalid, quote, quote_message, quote_path};
use super::{pbr_to_material, GltfMaterial, DEFAULT_MATERIAL};
use crate::scene::loader::SceneError;

/// Where an image's bytes are: what tells two image entries of one picture apart from two
/// pictures (with the MIME type, which chooses the decoder when given).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub(super) enum ImageSource {
    View(usize, String),
    /// A `data:` URI, whole.
    Data(String, Option<String>),
    /// A file, as the URI resolves.
    File(PathBuf, Option<String>),
    /// An image that cannot be decoded for a reason found before decoding (its index).
    Unreadable(usize),
}

impl Reader {
    /// The index in `out.materials` of `mat`, read on first use.
    pub(super) fn material(&mut self, doc_mat: ::gltf::Material) -> Result<usize, SceneError> {
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
            Some(i) => format!("material {i} ('{}')", quote(&name)),
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
    pub(super) fn texture_average(
        &mut self,
        image: &::gltf::image::Image,
        label: &str,
    ) -> Option<Vec3> {
        if let Some(&avg) = self.textures.get(&image.index()) {
            return avg;
        }
        let source = self.image_source(image);
        if let Some(&avg) = self.shared.images.get(&source) {
            self.textures.insert(image.index(), avg);
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
                    quote_message(&why)
                );
                None
            }
        };
        self.textures.insert(image.index(), avg);
        self.shared.images.insert(source, avg);
        avg
    }

    /// Where `image`'s bytes are (see [`ImageSource`]).
    fn image_source(&self, image: &::gltf::image::Image) -> ImageSource {
        use ::gltf::image::Source;
        if self.bad_images.contains_key(&image.index()) {
            return ImageSource::Unreadable(image.index());
        }
        match image.source() {
            Source::View { view, mime_type } => ImageSource::View(view.index(), mime_type.into()),
            Source::Uri { uri, mime_type } => {
                let mime = mime_type.map(str::to_string);
                if uri.starts_with("data:") {
                    ImageSource::Data(uri.to_string(), mime)
                } else {
                    match self.resolve_uri(uri) {
                        Ok(path) => ImageSource::File(path, mime),
                        Err(_) => ImageSource::Unreadable(image.index()),
                    }
                }
            }
        }
    }

    pub(super) fn decode(
        &mut self,
        image: &::gltf::image::Image,
    ) -> Result<::gltf::image::Data, String> {
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
                    return Err(format!(
                        "'{}' is not a file",
                        quote_path(&p.display().to_string())
                    ));
                }
                file = Some(p);
            }
        }
        self.stats.images_decoded += 1;
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
}

pub(super) fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The mean linear RGB of an image's texels: integer texels are sRGB-encoded (the glTF
/// spec for baseColorTexture) and are decoded one by one before averaging (averaging the
/// encoded values would darken); grey images count as equal RGB; alpha is ignored.
pub(super) fn average_linear(data: &::gltf::image::Data) -> Option<Vec3> {
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
