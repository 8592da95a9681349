//! Linear RGB images: OpenEXR for measurement (float32 radiance), sRGB PNG for people,
//! and the error metric used against the path-traced references (paper section 5 measured
//! speed only; igi also measures error).
//!
//! Files are written to a temporary name beside the target and renamed into place, so an
//! interrupted run never leaves a half-written image.

use std::io::BufWriter;
use std::path::{Path, PathBuf};

/// A linear RGB image, rows top to bottom.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub data: Vec<[f32; 3]>,
}

#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    #[error("cannot write '{path}': {reason}")]
    Write { path: PathBuf, reason: String },
    #[error("cannot read '{path}': {reason}")]
    Read { path: PathBuf, reason: String },
    #[error("image sizes differ: {0}x{1} against {2}x{3}")]
    SizeMismatch(u32, u32, u32, u32),
}

impl Image {
    pub fn new(width: u32, height: u32) -> Image {
        Image {
            width,
            height,
            data: vec![[0.0; 3]; (width as usize) * (height as usize)],
        }
    }

    /// From RGBA rows as the GPU returns them (alpha dropped).
    pub fn from_rgba(width: u32, height: u32, rgba: &[[f32; 4]]) -> Image {
        Image {
            width,
            height,
            data: rgba.iter().map(|p| [p[0], p[1], p[2]]).collect(),
        }
    }

    pub fn pixel(&self, x: u32, y: u32) -> [f32; 3] {
        self.data[(y * self.width + x) as usize]
    }

    /// The image averaged over f x f blocks (a box filter, as the references' pixels are);
    /// edge blocks average what they hold.
    pub fn downsample_box(&self, f: u32) -> Image {
        let f = f.max(1);
        let (w, h) = (self.width.div_ceil(f), self.height.div_ceil(f));
        let mut out = Image::new(w, h);
        for y in 0..h {
            for x in 0..w {
                let mut sum = [0.0f64; 3];
                let mut n = 0.0;
                for yy in y * f..((y + 1) * f).min(self.height) {
                    for xx in x * f..((x + 1) * f).min(self.width) {
                        let p = self.pixel(xx, yy);
                        for c in 0..3 {
                            sum[c] += p[c] as f64;
                        }
                        n += 1.0;
                    }
                }
                out.data[(y * w + x) as usize] = sum.map(|v| (v / n) as f32);
            }
        }
        out
    }

    /// Mean of each channel.
    pub fn mean(&self) -> [f64; 3] {
        let mut m = [0.0f64; 3];
        for p in &self.data {
            for c in 0..3 {
                m[c] += p[c] as f64;
            }
        }
        let n = self.data.len().max(1) as f64;
        m.map(|v| v / n)
    }

    /// Read the first RGB(A) layer of an OpenEXR file (half or float) as linear RGB.
    pub fn read_exr(path: &Path) -> Result<Image, ImageError> {
        let image = exr::prelude::read_first_rgba_layer_from_file(
            path,
            |size, _| Self::new(size.0 as u32, size.1 as u32),
            |img: &mut Self, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                let i = pos.1 * img.width as usize + pos.0;
                img.data[i] = [r, g, b];
            },
        )
        .map_err(|e| ImageError::Read {
            path: path.to_path_buf(),
            reason: e.to_string(),
        })?;
        Ok(image.layer_data.channel_data.pixels)
    }

    /// Write float32 RGB OpenEXR (linear radiance, no exposure).
    pub fn write_exr(&self, path: &Path) -> Result<(), ImageError> {
        write_atomically(path, |tmp| {
            exr::prelude::write_rgb_file(tmp, self.width as usize, self.height as usize, |x, y| {
                let p = self.data[y * self.width as usize + x];
                (p[0], p[1], p[2])
            })
            .map_err(|e| e.to_string())
        })
    }

    /// Write an 8-bit sRGB PNG of the image times `exposure` (clamped to [0, 1]).
    pub fn write_png(&self, path: &Path, exposure: f32) -> Result<(), ImageError> {
        let bytes = self.to_srgb8(exposure);
        write_atomically(path, |tmp| {
            let file = std::fs::File::create(tmp).map_err(|e| e.to_string())?;
            let mut encoder = png::Encoder::new(BufWriter::new(file), self.width, self.height);
            encoder.set_color(png::ColorType::Rgb);
            encoder.set_depth(png::BitDepth::Eight);
            encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
            let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
            writer.write_image_data(&bytes).map_err(|e| e.to_string())?;
            writer.finish().map_err(|e| e.to_string())
        })
    }

    /// 8-bit sRGB bytes (RGB, rows top to bottom) of the image times `exposure`.
    pub fn to_srgb8(&self, exposure: f32) -> Vec<u8> {
        self.data
            .iter()
            .flat_map(|p| p.map(|v| (linear_to_srgb(v * exposure) * 255.0 + 0.5) as u8))
            .collect()
    }
}

/// The sRGB transfer curve, input clamped to [0, 1] (NaN counts as 0).
pub fn linear_to_srgb(v: f32) -> f32 {
    let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// Error unless `a` and `b` have the same size (every comparison of two images needs it).
pub fn same_size(a: &Image, b: &Image) -> Result<(), ImageError> {
    if a.width != b.width || a.height != b.height {
        return Err(ImageError::SizeMismatch(
            a.width, a.height, b.width, b.height,
        ));
    }
    Ok(())
}

/// Regulariser of [`rel_mse`]: keeps dark pixels from dominating (the usual 0.01).
pub const REL_MSE_EPSILON: f64 = 0.01;

/// Relative mean squared error of `image` against `reference` on linear radiance:
/// mean over pixels and channels of (x - r)^2 / (r^2 + 0.01).
pub fn rel_mse(image: &Image, reference: &Image) -> Result<f64, ImageError> {
    same_size(image, reference)?;
    let mut sum = 0.0f64;
    for (p, r) in image.data.iter().zip(&reference.data) {
        for c in 0..3 {
            let (x, y) = (p[c] as f64, r[c] as f64);
            sum += (x - y) * (x - y) / (y * y + REL_MSE_EPSILON);
        }
    }
    Ok(sum / (3 * image.data.len().max(1)) as f64)
}

/// Write through `write` to a temporary file beside `path`, then rename it into place. The
/// directory is checked first so that a missing one gives a clear error.
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), String>,
) -> Result<(), ImageError> {
    let err = |reason: String| ImageError::Write {
        path: path.to_path_buf(),
        reason,
    };
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    if !dir.is_dir() {
        return Err(err(format!("directory '{}' does not exist", dir.display())));
    }
    let name = path
        .file_name()
        .ok_or_else(|| err("not a file name".into()))?
        .to_string_lossy()
        .to_string();
    // Keep the extension last: the EXR writer does not care, but tools looking at the
    // directory meanwhile see what kind of file it is.
    let tmp = dir.join(format!(".{name}.{}.partial", std::process::id()));
    match write(&tmp) {
        Ok(()) => std::fs::rename(&tmp, path).map_err(|e| {
            let _ = std::fs::remove_file(&tmp);
            err(e.to_string())
        }),
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(err(e))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rel_mse_known_values() {
        let mut a = Image::new(2, 1);
        a.data = vec![[1.0, 1.0, 1.0], [0.0, 0.0, 0.0]];
        assert_eq!(rel_mse(&a, &a).unwrap(), 0.0);
        let mut b = a.clone();
        // One channel off by 0.1 at a pixel of value 1: 0.01 / 1.01 over 6 samples.
        b.data[0][0] = 1.1;
        let expected = (0.1f64 * 0.1) / (1.0 + 0.01) / 6.0;
        assert!((rel_mse(&b, &a).unwrap() - expected).abs() < 1e-7);
        assert!(rel_mse(&Image::new(1, 1), &a).is_err());
    }

    #[test]
    fn exr_round_trip_and_png() {
        let dir = std::env::temp_dir().join(format!("igi-image-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut img = Image::new(3, 2);
        for (i, p) in img.data.iter_mut().enumerate() {
            *p = [i as f32 * 0.25, 1.5, 1e-3];
        }
        let exr = dir.join("a.exr");
        img.write_exr(&exr).unwrap();
        assert_eq!(Image::read_exr(&exr).unwrap(), img);
        img.write_png(&dir.join("a.png"), 1.0).unwrap();
        // A missing directory is a clear error and leaves nothing behind.
        let missing = dir.join("no/such/dir/a.png");
        let e = img.write_png(&missing, 1.0).unwrap_err().to_string();
        assert!(e.contains("does not exist"), "{e}");
        let leftovers: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().ends_with(".partial"))
            .collect();
        assert!(leftovers.is_empty());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn box_downsampling_averages_blocks() {
        let mut a = Image::new(3, 2);
        a.data = vec![[1.0; 3], [3.0; 3], [5.0; 3], [3.0; 3], [5.0; 3], [7.0; 3]];
        let d = a.downsample_box(2);
        assert_eq!((d.width, d.height), (2, 1));
        assert_eq!(d.data, vec![[3.0; 3], [6.0; 3]]);
    }

    #[test]
    fn srgb_curve() {
        assert_eq!(linear_to_srgb(0.0), 0.0);
        assert!((linear_to_srgb(1.0) - 1.0).abs() < 1e-6);
        assert!((linear_to_srgb(0.5) - 0.7354).abs() < 1e-3);
        assert_eq!(linear_to_srgb(f32::NAN), 0.0);
    }
}
