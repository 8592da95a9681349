//! glTF materials as diffuse + mirror ([`super::pbr_to_material`]), with their base
//! colour texture (an RGBA8 [`Texture`], decoded once per image file or buffer view
//! however many image entries, textures or materials name it; its sampler and
//! KHR_texture_transform in the material's [`TextureRef`]) and their alpha mode.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;

use glam::{Vec2, Vec3};

use super::accessors::Reader;
use super::messages::{fmt3, invalid, quote, quote_message, quote_path};
use super::{pbr_to_material, GltfMaterial, DEFAULT_MATERIAL};
use crate::image::linear_to_srgb;
use crate::scene::loader::SceneError;
use crate::scene::{Alpha, AlphaMode};
use crate::texture::{Filter, Sampler, Texture, TextureRef, UvTransform, Wrap};

/// The alpha cutoff of a MASK material that gives none (the glTF default), and the one
/// BLEND materials are drawn with (as cut-outs: the renderer does not blend).
pub const DEFAULT_ALPHA_CUTOFF: f32 = 0.5;

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

/// A glTF sampler as the renderer's: its wrap modes and filters, glTF's defaults where it
/// leaves one out (repeat; bilinear, trilinear under minification).
pub(super) fn sampler(s: &::gltf::texture::Sampler) -> Sampler {
    use ::gltf::texture::{MagFilter, MinFilter, WrappingMode};
    let wrap = |w: WrappingMode| match w {
        WrappingMode::ClampToEdge => Wrap::ClampToEdge,
        WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
        WrappingMode::Repeat => Wrap::Repeat,
    };
    let mag = match s.mag_filter() {
        Some(MagFilter::Nearest) => Filter::Nearest,
        Some(MagFilter::Linear) => Filter::Linear,
        None => Sampler::DEFAULT.mag,
    };
    // NEAREST and LINEAR read level 0 only; the MIPMAP filters name the filter within a
    // level first, then how levels are chosen.
    let (min, mip) = match s.min_filter() {
        Some(MinFilter::Nearest) => (Filter::Nearest, None),
        Some(MinFilter::Linear) => (Filter::Linear, None),
        Some(MinFilter::NearestMipmapNearest) => (Filter::Nearest, Some(Filter::Nearest)),
        Some(MinFilter::LinearMipmapNearest) => (Filter::Linear, Some(Filter::Nearest)),
        Some(MinFilter::NearestMipmapLinear) => (Filter::Nearest, Some(Filter::Linear)),
        Some(MinFilter::LinearMipmapLinear) => (Filter::Linear, Some(Filter::Linear)),
        None => (Sampler::DEFAULT.min, Sampler::DEFAULT.mip),
    };
    Sampler {
        wrap_s: wrap(s.wrap_s()),
        wrap_t: wrap(s.wrap_t()),
        mag,
        min,
        mip,
    }
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
        let opacity = factor[3];
        if !unit(opacity) {
            return Err(invalid(
                &self.file,
                format!("{label}: baseColorFactor alpha {opacity} must be in [0, 1]"),
            ));
        }
        let base = Vec3::from(base);
        let (texture, uv_set) = match pbr.base_color_texture() {
            Some(info) => self.base_color_texture(&info, &label)?,
            None => (None, None),
        };
        if doc_mat.emissive_factor().iter().any(|&e| e != 0.0) {
            self.warn.emissive += 1;
        }
        // KHR_materials_unlit: its base colour, shaded as a diffuse surface (the nearest
        // igi has to a surface that shows its colour whatever the light).
        let (diffuse, mirror) = if doc_mat.unlit() {
            self.warn.unlit += 1;
            (base, Vec3::ZERO)
        } else {
            pbr_to_material(base, metallic, roughness)
        };
        use ::gltf::material::AlphaMode as Mode;
        let alpha = match doc_mat.alpha_mode() {
            Mode::Opaque => Alpha::OPAQUE,
            Mode::Mask => {
                let cutoff = doc_mat.alpha_cutoff().unwrap_or(DEFAULT_ALPHA_CUTOFF);
                if !(cutoff.is_finite() && cutoff >= 0.0) {
                    return Err(invalid(
                        &self.file,
                        format!("{label}: alphaCutoff {cutoff} must be a number >= 0"),
                    ));
                }
                Alpha {
                    mode: AlphaMode::Mask { cutoff },
                    factor: opacity,
                }
            }
            Mode::Blend => {
                self.warn.blend += 1;
                Alpha {
                    mode: AlphaMode::Mask {
                        cutoff: DEFAULT_ALPHA_CUTOFF,
                    },
                    factor: opacity,
                }
            }
        };
        let i = self.out.materials.len();
        self.out.materials.push(GltfMaterial {
            name,
            index: key,
            diffuse,
            mirror,
            texture,
            // Set by the primitives that use it with COLOR_0.
            vertex_colors: false,
            alpha,
            triangles: 0,
        });
        self.uv_sets.push(uv_set);
        self.materials.insert(key, i);
        Ok(i)
    }

    /// The texture of a `baseColorTexture` and the texture coordinate set it reads
    /// (KHR_texture_transform's `texCoord` where it gives one); `(None, None)`, with a
    /// warning, when its image cannot be read or decoded (the factor is used alone).
    fn base_color_texture(
        &mut self,
        info: &::gltf::texture::Info,
        label: &str,
    ) -> Result<(Option<TextureRef>, Option<u32>), SceneError> {
        let tex = info.texture();
        let mut set = info.tex_coord();
        let mut transform = UvTransform::IDENTITY;
        if let Some(t) = info.texture_transform() {
            let (offset, rotation, scale) = (t.offset(), t.rotation(), t.scale());
            let all = [offset[0], offset[1], rotation, scale[0], scale[1]];
            if !all.iter().all(|x| x.is_finite()) {
                return Err(invalid(
                    &self.file,
                    format!(
                        "{label}: baseColorTexture KHR_texture_transform offset {offset:?}, rotation {rotation}, scale {scale:?} must be finite numbers"
                    ),
                ));
            }
            transform = UvTransform::from_offset_rotation_scale(
                Vec2::from(offset),
                rotation,
                Vec2::from(scale),
            );
            set = t.tex_coord().unwrap_or(set);
        }
        let Some(index) = self.texture_index(&tex.source(), label) else {
            return Ok((None, None));
        };
        let texture = TextureRef {
            texture: index,
            sampler: sampler(&tex.sampler()),
            transform,
        };
        Ok((Some(texture), Some(set)))
    }

    /// The index in `out.textures` of an image, decoded by the gltf crate on first use;
    /// `None` (with a warning) when it cannot be read or decoded.
    pub(super) fn texture_index(
        &mut self,
        image: &::gltf::image::Image,
        label: &str,
    ) -> Option<u32> {
        if let Some(&index) = self.textures.get(&image.index()) {
            return index;
        }
        let source = self.image_source(image);
        if let Some(&index) = self.shared.images.get(&source) {
            self.textures.insert(image.index(), index);
            return index;
        }
        let name = match &source {
            ImageSource::File(path, _) => path.display().to_string(),
            _ => format!("{} image {}", self.file, image.index()),
        };
        let texture = self
            .decode(image)
            .and_then(|data| Texture::new(name, data.width, data.height, true, rgba8(&data)));
        let index = match texture {
            Ok(texture) => {
                self.out.textures.push(texture);
                Some(self.out.textures.len() as u32 - 1)
            }
            Err(why) => {
                log::warn!(
                    "{}: {label}: cannot use baseColorTexture image {}: {}; its factor is used alone",
                    self.file,
                    image.index(),
                    quote_message(&why)
                );
                None
            }
        };
        self.textures.insert(image.index(), index);
        self.shared.images.insert(source, index);
        index
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

/// An image's texels as RGBA8, rows from the top: grey is equal RGB, a missing alpha is
/// 255, 16-bit channels are rounded to 8 bits (they are sRGB-encoded as the 8-bit ones),
/// and float channels (linear light) are clamped to [0, 1] and sRGB-encoded (alpha stays
/// linear), so every format becomes what an sRGB base colour texture holds.
pub(super) fn rgba8(data: &::gltf::image::Data) -> Vec<[u8; 4]> {
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
    // The crate's pixels are the decoder's samples in native byte order. `srgb`: whether
    // a float sample is a colour channel (encoded) or alpha (linear).
    let value = |s: &[u8], srgb: bool| -> u8 {
        match bytes {
            1 => s[0],
            2 => ((u32::from(u16::from_ne_bytes([s[0], s[1]])) * 255 + 32767) / 65535) as u8,
            _ => {
                let x = f32::from_ne_bytes([s[0], s[1], s[2], s[3]]);
                // NaN counts as 0.
                let x = if x > 0.0 { x.min(1.0) } else { 0.0 };
                let e = if srgb { linear_to_srgb(x) } else { x };
                (e * 255.0).round() as u8
            }
        }
    };
    let texel = channels * bytes;
    data.pixels
        .chunks_exact(texel)
        .map(|px| {
            let ch = |c: usize, srgb: bool| value(&px[c * bytes..(c + 1) * bytes], srgb);
            match channels {
                1 => {
                    let g = ch(0, true);
                    [g, g, g, 255]
                }
                2 => {
                    let g = ch(0, true);
                    [g, g, g, ch(1, false)]
                }
                3 => [ch(0, true), ch(1, true), ch(2, true), 255],
                _ => [ch(0, true), ch(1, true), ch(2, true), ch(3, false)],
            }
        })
        .collect()
}
