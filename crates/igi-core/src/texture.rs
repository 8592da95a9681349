//! Textures as the renderer samples them: RGBA8 images with their mip chain, the
//! sampler of a glTF texture (wrap modes, filters) and the texture transform of the
//! material that uses it. This module is the CPU twin of `shaders/texture.wgsl`, function
//! by function: the GPU keeps the same texels (`Texture::levels`, in one storage buffer)
//! and filters them in its own code, so the two sample the same values.
//!
//! Conventions (glTF's, which the OBJ loader converts to): texture coordinate (0, 0) is
//! the top-left corner of the image's first row, u grows to the right and v downwards;
//! texel (i, j) covers [i, i + 1) x [j, j + 1) in units of texels, so its centre is at
//! ((i + 0.5) / width, (j + 0.5) / height).

use glam::{Vec2, Vec3, Vec4};

#[cfg(test)]
use crate::image::linear_to_srgb;

/// How coordinates outside [0, 1] map into the image (glTF sampler `wrapS`/`wrapT`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Wrap {
    /// The image tiles the plane (glTF's default, 10497).
    #[default]
    Repeat,
    /// Coordinates are clamped to the edge texels (33071).
    ClampToEdge,
    /// The image tiles the plane, every other copy mirrored (33648).
    MirroredRepeat,
}

/// How texels between samples are filtered.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Filter {
    /// The texel that covers the point.
    Nearest,
    /// Bilinear interpolation of the four nearest texel centres.
    #[default]
    Linear,
}

/// A glTF sampler, as igi uses it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Sampler {
    pub wrap_s: Wrap,
    pub wrap_t: Wrap,
    /// Filter where a texel covers more than a pixel (level 0).
    pub mag: Filter,
    /// Filter within a mip level where texels are smaller than a pixel.
    pub min: Filter,
    /// How mip levels are chosen under minification: `None` samples level 0 only (glTF
    /// NEAREST or LINEAR min filters), `Some(Nearest)` the nearest level, `Some(Linear)`
    /// blends the two nearest (trilinear; the default when the file says nothing).
    pub mip: Option<Filter>,
}

impl Sampler {
    /// glTF's defaults where a file leaves the sampler out: repeat, bilinear, trilinear.
    pub const DEFAULT: Sampler = Sampler {
        wrap_s: Wrap::Repeat,
        wrap_t: Wrap::Repeat,
        mag: Filter::Linear,
        min: Filter::Linear,
        mip: Some(Filter::Linear),
    };
}

/// A texture transform (glTF `KHR_texture_transform`): `uv' = M (u, v, 1)`, the 2x3 matrix
/// given by rows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvTransform {
    pub rows: [Vec3; 2],
}

impl UvTransform {
    pub const IDENTITY: UvTransform = UvTransform {
        rows: [Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0)],
    };

    /// `KHR_texture_transform`'s matrix: translation T, rotation R (radians,
    /// counter-clockwise in the image as the extension defines it) and scale S,
    /// applied as T * R * S.
    pub fn from_offset_rotation_scale(offset: Vec2, rotation: f32, scale: Vec2) -> UvTransform {
        let (s, c) = rotation.sin_cos();
        UvTransform {
            rows: [
                Vec3::new(c * scale.x, s * scale.y, offset.x),
                Vec3::new(-s * scale.x, c * scale.y, offset.y),
            ],
        }
    }

    pub fn apply(&self, uv: Vec2) -> Vec2 {
        let p = uv.extend(1.0);
        Vec2::new(self.rows[0].dot(p), self.rows[1].dot(p))
    }

    /// How much the transform stretches texture space: the square root of |det|, which
    /// multiplies the texel footprint of a ray cone.
    pub fn scale(&self) -> f32 {
        let [a, b] = self.rows;
        (a.x * b.y - a.y * b.x).abs().sqrt()
    }
}

/// A material's use of a texture: which, with which coordinates, sampled how.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextureRef {
    /// Index into [`crate::scene::Scene::textures`].
    pub texture: u32,
    pub sampler: Sampler,
    pub transform: UvTransform,
}

/// An image as the renderer keeps it: RGBA8, rows from the top. Colour channels of
/// `srgb` textures are sRGB-encoded and decoded per texel before filtering (glTF's base
/// colour textures, MTL colour maps); alpha is always linear.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// What the texture came from (a file, or `FILE image N`), for messages.
    pub name: String,
    pub width: u32,
    pub height: u32,
    pub srgb: bool,
    /// The mip chain, level 0 first, each level half the size of the one before (rounded
    /// down, at least 1), down to 1 x 1: see [`Texture::new`].
    pub levels: Vec<Level>,
}

/// One mip level: `width * height` texels, row by row from the top, RGBA8.
#[derive(Clone, Debug, PartialEq)]
pub struct Level {
    pub width: u32,
    pub height: u32,
    pub texels: Vec<[u8; 4]>,
}

/// The largest side of a texture, in texels (the largest that GPUs' own textures take).
pub const MAX_TEXTURE_SIDE: u32 = 16384;

impl Texture {
    /// A texture of `texels` (`width * height`, rows from the top) with its mip chain: each
    /// level's texel is the mean of the 2 x 2 texels it covers in the level above (the
    /// last row or column repeated where a side is odd), averaged in linear values (sRGB
    /// decoded and encoded again), so a level is as bright as the one it was made from.
    pub fn new(
        name: String,
        width: u32,
        height: u32,
        srgb: bool,
        texels: Vec<[u8; 4]>,
    ) -> Result<Texture, String> {
        if width == 0 || height == 0 {
            return Err(format!(
                "{name}: the image has no texels ({width} x {height})"
            ));
        }
        if width > MAX_TEXTURE_SIDE || height > MAX_TEXTURE_SIDE {
            return Err(format!(
                "{name}: the image is {width} x {height}, more than {MAX_TEXTURE_SIDE} texels on a side"
            ));
        }
        if texels.len() != width as usize * height as usize {
            return Err(format!(
                "{name}: {} texels for a {width} x {height} image",
                texels.len()
            ));
        }
        let mut levels = vec![Level {
            width,
            height,
            texels,
        }];
        while let Some(last) = levels.last().filter(|l| l.width > 1 || l.height > 1) {
            levels.push(last.half(srgb));
        }
        Ok(Texture {
            name,
            width,
            height,
            srgb,
            levels,
        })
    }

    /// One colour for the whole texture: its 1 x 1 mip level, decoded (the mean of the
    /// image, to the rounding of each level's 8 bits).
    pub fn mean(&self) -> Vec4 {
        let last = self.levels.last().expect("a texture has a level");
        decode(last.texels[0], self.srgb)
    }

    /// Texels in all levels.
    pub fn texel_count(&self) -> usize {
        self.levels.iter().map(|l| l.texels.len()).sum()
    }
}

impl Level {
    fn half(&self, srgb: bool) -> Level {
        let (w, h) = ((self.width / 2).max(1), (self.height / 2).max(1));
        let mut texels = Vec::with_capacity(w as usize * h as usize);
        for y in 0..h {
            for x in 0..w {
                let mut sum = Vec4::ZERO;
                for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let sx = (2 * x + dx).min(self.width - 1);
                    let sy = (2 * y + dy).min(self.height - 1);
                    sum += decode(self.texels[(sy * self.width + sx) as usize], srgb);
                }
                texels.push(encode(sum * 0.25, srgb));
            }
        }
        Level {
            width: w,
            height: h,
            texels,
        }
    }
}

/// The sRGB transfer function's inverse (IEC 61966-2-1): encoded [0, 1] to linear.
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The linear value of each sRGB byte, and the linear values halfway between
/// consecutive bytes' encodings, where encoding rounds up: tables, so that making a mip
/// chain costs lookups instead of a `powf` per channel and texel.
struct SrgbTables {
    decoded: [f32; 256],
    /// `rounds_up[k]`: linear values at or above it encode to byte k + 1 or more.
    rounds_up: [f32; 255],
}

fn srgb_tables() -> &'static SrgbTables {
    static TABLES: std::sync::OnceLock<SrgbTables> = std::sync::OnceLock::new();
    TABLES.get_or_init(|| SrgbTables {
        decoded: std::array::from_fn(|k| srgb_to_linear(k as f32 / 255.0)),
        rounds_up: std::array::from_fn(|k| srgb_to_linear((k as f32 + 0.5) / 255.0)),
    })
}

/// A texel's linear RGBA (twin of texture.wgsl's `decode_texel`).
pub fn decode(t: [u8; 4], srgb: bool) -> Vec4 {
    if srgb {
        let d = &srgb_tables().decoded;
        Vec4::new(
            d[t[0] as usize],
            d[t[1] as usize],
            d[t[2] as usize],
            t[3] as f32 / 255.0,
        )
    } else {
        Vec4::from_array(t.map(|x| x as f32 / 255.0))
    }
}

/// The byte nearest to linear `x` once encoded (`round(255 linear_to_srgb(x))`).
fn encode_srgb(x: f32) -> u8 {
    srgb_tables().rounds_up.partition_point(|&t| t <= x) as u8
}

fn encode(v: Vec4, srgb: bool) -> [u8; 4] {
    let unorm = |x: f32| (x.clamp(0.0, 1.0) * 255.0).round() as u8;
    if srgb {
        [
            encode_srgb(v.x),
            encode_srgb(v.y),
            encode_srgb(v.z),
            unorm(v.w),
        ]
    } else {
        [unorm(v.x), unorm(v.y), unorm(v.z), unorm(v.w)]
    }
}

/// The texel index that integer coordinate `i` reads along a side of `n` texels (twin of
/// texture.wgsl's `wrap_index`).
pub fn wrap_index(i: i32, n: u32, wrap: Wrap) -> u32 {
    let n = n as i32;
    match wrap {
        Wrap::Repeat => i.rem_euclid(n) as u32,
        Wrap::ClampToEdge => i.clamp(0, n - 1) as u32,
        Wrap::MirroredRepeat => {
            let k = i.rem_euclid(2 * n);
            (if k < n { k } else { 2 * n - 1 - k }) as u32
        }
    }
}

/// Coordinates past this size are first brought into one period of the image (in texel
/// units the f32 spacing would reach a texel past 2^24; twin of texture.wgsl's `reduce`).
fn reduce(x: f32, n: u32) -> f32 {
    let period = 2.0 * n as f32;
    x - (x / period).floor() * period
}

/// The value of one level at `uv` with `filter` (twin of texture.wgsl's `sample_level`).
pub fn sample_level(
    level: &Level,
    srgb: bool,
    uv: Vec2,
    filter: Filter,
    wrap: (Wrap, Wrap),
) -> Vec4 {
    let (w, h) = (level.width, level.height);
    let x = reduce(uv.x * w as f32, w);
    let y = reduce(uv.y * h as f32, h);
    let texel = |i: i32, j: i32| {
        let i = wrap_index(i, w, wrap.0);
        let j = wrap_index(j, h, wrap.1);
        decode(level.texels[(j * w + i) as usize], srgb)
    };
    match filter {
        Filter::Nearest => texel(x.floor() as i32, y.floor() as i32),
        Filter::Linear => {
            let (fx, fy) = (x - 0.5, y - 0.5);
            let (i, j) = (fx.floor(), fy.floor());
            let (a, b) = (fx - i, fy - j);
            let (i, j) = (i as i32, j as i32);
            let top = texel(i, j) * (1.0 - a) + texel(i + 1, j) * a;
            let bottom = texel(i, j + 1) * (1.0 - a) + texel(i + 1, j + 1) * a;
            top * (1.0 - b) + bottom * b
        }
    }
}

/// The texture's value at `uv` for a footprint of `lod` (log2 of the footprint's side in
/// level-0 texels; at most 0 is magnification): the sampler's filters and mip mode (twin
/// of texture.wgsl's `sample_texture`).
pub fn sample(texture: &Texture, sampler: &Sampler, uv: Vec2, lod: f32) -> Vec4 {
    let wrap = (sampler.wrap_s, sampler.wrap_t);
    let top = (texture.levels.len() - 1) as f32;
    // NaN (a degenerate cone) reads level 0 like magnification.
    if lod.is_nan() || lod <= 0.0 || sampler.mip.is_none() {
        let filter = if lod > 0.0 { sampler.min } else { sampler.mag };
        return sample_level(&texture.levels[0], texture.srgb, uv, filter, wrap);
    }
    let lod = lod.min(top);
    match sampler.mip {
        Some(Filter::Nearest) => {
            let l = (lod + 0.5).floor() as usize;
            sample_level(&texture.levels[l], texture.srgb, uv, sampler.min, wrap)
        }
        _ => {
            let l0 = lod.floor();
            let f = lod - l0;
            let l0 = l0 as usize;
            let l1 = (l0 + 1).min(top as usize);
            let a = sample_level(&texture.levels[l0], texture.srgb, uv, sampler.min, wrap);
            let b = sample_level(&texture.levels[l1], texture.srgb, uv, sampler.min, wrap);
            a * (1.0 - f) + b * f
        }
    }
}

/// The colour multiplier (rgb) and opacity (a) of triangle `tri`'s material at
/// barycentrics (u, v): its texture times its vertex colours (twin of texture.wgsl's
/// `surface_color`; the GPU keeps colours to 16 bits).
pub fn surface_color(scene: &crate::scene::Scene, tri: usize, u: f32, v: f32, lod: f32) -> Vec4 {
    let m = &scene.materials[scene.triangles[tri].material as usize];
    let mut c = Vec4::ONE;
    let Some(a) = scene.attributes.get(tri) else {
        return c;
    };
    let w = 1.0 - u - v;
    if m.vertex_colors {
        c = w * a.color[0] + u * a.color[1] + v * a.color[2];
    }
    if let Some(t) = &m.texture {
        let uv = t.transform.apply(w * a.uv[0] + u * a.uv[1] + v * a.uv[2]);
        c *= sample(&scene.textures[t.texture as usize], &t.sampler, uv, lod);
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;

    fn checker(n: u32) -> Texture {
        let texels = (0..n * n)
            .map(|k| {
                let v = if (k % n + k / n).is_multiple_of(2) {
                    255
                } else {
                    0
                };
                [v, v, v, 255]
            })
            .collect();
        Texture::new("checker".into(), n, n, true, texels).unwrap()
    }

    #[test]
    fn mip_levels_keep_the_mean_in_linear_values() {
        let t = checker(8);
        assert_eq!(t.levels.len(), 4);
        // Half white, half black: linear 0.5, not the encoded 0.5 (0.214 linear).
        let m = t.mean();
        assert!((m.x - 0.5).abs() < 0.003, "{m}");
        assert_eq!(m.w, 1.0);
    }

    #[test]
    fn srgb_tables_round_as_the_transfer_function() {
        for k in 0..=255u8 {
            let linear = srgb_to_linear(k as f32 / 255.0);
            assert_eq!(decode([k, 0, 0, 0], true).x, linear);
            assert_eq!(encode_srgb(linear), k);
        }
        for i in 0..=10000 {
            let x = i as f32 / 10000.0;
            let direct = (linear_to_srgb(x) * 255.0).round();
            let got = encode_srgb(x) as f32;
            // Ties between two bytes may go either way by a rounding of powf.
            assert!((got - direct).abs() <= 1.0, "{x}: {got} vs {direct}");
        }
        assert_eq!(encode_srgb(-1.0), 0);
        assert_eq!(encode_srgb(2.0), 255);
    }

    #[test]
    fn odd_sizes_halve_down_to_one_texel() {
        let t = Texture::new("odd".into(), 5, 3, false, vec![[10, 20, 30, 40]; 15]).unwrap();
        let sizes: Vec<_> = t.levels.iter().map(|l| (l.width, l.height)).collect();
        assert_eq!(sizes, [(5, 3), (2, 1), (1, 1)]);
        assert!(t
            .levels
            .iter()
            .all(|l| l.texels.iter().all(|&x| x == [10, 20, 30, 40])));
    }

    #[test]
    fn wrap_modes_at_and_past_the_edges() {
        let r: Vec<_> = (-4..8).map(|i| wrap_index(i, 3, Wrap::Repeat)).collect();
        assert_eq!(r, [2, 0, 1, 2, 0, 1, 2, 0, 1, 2, 0, 1]);
        let c: Vec<_> = (-2..5)
            .map(|i| wrap_index(i, 3, Wrap::ClampToEdge))
            .collect();
        assert_eq!(c, [0, 0, 0, 1, 2, 2, 2]);
        let m: Vec<_> = (-4..8)
            .map(|i| wrap_index(i, 3, Wrap::MirroredRepeat))
            .collect();
        // Texel -1 mirrors to 0, -3 to 2, 3 to 2 (a copy reflected at each edge).
        assert_eq!(m, [2, 2, 1, 0, 0, 1, 2, 2, 1, 0, 0, 1]);
    }

    #[test]
    fn nearest_and_bilinear_at_texel_centres_and_between() {
        let t = Texture::new(
            "ramp".into(),
            2,
            1,
            false,
            vec![[0, 0, 0, 0], [255, 255, 255, 255]],
        )
        .unwrap();
        let l = &t.levels[0];
        let w = (Wrap::ClampToEdge, Wrap::ClampToEdge);
        let at = |u: f32, f| sample_level(l, false, Vec2::new(u, 0.5), f, w).x;
        assert_eq!(at(0.25, Filter::Nearest), 0.0);
        assert_eq!(at(0.74, Filter::Nearest), 1.0);
        assert_eq!(at(0.25, Filter::Linear), 0.0);
        assert_eq!(at(0.75, Filter::Linear), 1.0);
        assert!((at(0.5, Filter::Linear) - 0.5).abs() < 1e-6);
        // Repeat blends the last texel with the first across the edge.
        let r = sample_level(
            l,
            false,
            Vec2::new(0.0, 0.5),
            Filter::Linear,
            (Wrap::Repeat, Wrap::Repeat),
        );
        assert!((r.x - 0.5).abs() < 1e-6);
    }

    #[test]
    fn texture_transform_is_translation_rotation_scale() {
        let t = UvTransform::from_offset_rotation_scale(
            Vec2::new(0.5, 0.0),
            std::f32::consts::FRAC_PI_2,
            Vec2::new(2.0, 2.0),
        );
        let p = t.apply(Vec2::new(1.0, 0.0));
        assert!((p - Vec2::new(0.5, -2.0)).length() < 1e-6, "{p}");
        assert!((t.scale() - 2.0).abs() < 1e-6);
    }

    #[test]
    fn minification_reads_the_mip_chain() {
        let t = checker(16);
        let s = Sampler::DEFAULT;
        let far = sample(&t, &s, Vec2::new(0.3, 0.7), 10.0);
        assert!((far.x - 0.5).abs() < 0.003, "{far}");
        let near = sample(&t, &s, Vec2::new(0.5 / 16.0, 0.5 / 16.0), -1.0);
        assert_eq!(near.x, 1.0);
        let level0_only = Sampler {
            mip: None,
            min: Filter::Nearest,
            ..s
        };
        let v = sample(&t, &level0_only, Vec2::new(0.5 / 16.0, 0.5 / 16.0), 5.0);
        assert_eq!(v.x, 1.0);
    }
}
