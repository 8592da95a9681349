//! Linear RGB images: OpenEXR for measurement (float32 radiance), sRGB PNG for people,
//! and the error metric used against the path-traced references (paper section 5 measured
//! speed only; igi also measures error).
//!
//! Files are written to a temporary name beside the target and renamed into place, so an
//! interrupted run never leaves a half-written image.

mod output_files;

pub use output_files::{output_target, remove_partial_files, write_atomically, OutputFiles};
use std::fs::File;
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
    /// A file of another kind where OpenEXR was expected: the decoder's own words for it
    /// ("file identifier missing", "reference to missing bytes") do not say so.
    #[error("'{path}' is not an OpenEXR file ({reason})")]
    NotExr { path: PathBuf, reason: String },
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
    /// A FIFO or device is refused, not read (which could block forever).
    pub fn read_exr(path: &Path) -> Result<Image, ImageError> {
        let bytes =
            crate::scene::loader::read_regular_file(path).map_err(|e| ImageError::Read {
                path: path.to_path_buf(),
                reason: e.to_string(),
            })?;
        Self::read_exr_bytes(&bytes, path)
    }

    /// [`Image::read_exr`] of a file's bytes already read; `path` names it in errors.
    /// The sizes its headers declare are checked against [`MAX_EXR_PIXELS`] and against
    /// the file's length before any pixel is allocated.
    pub fn read_exr_bytes(bytes: &[u8], path: &Path) -> Result<Image, ImageError> {
        let err = |reason: String| ImageError::Read {
            path: path.to_path_buf(),
            reason,
        };
        use exr::prelude::{ReadChannels, ReadLayers};
        if let Some(reason) = not_exr_reason(bytes) {
            return Err(ImageError::NotExr {
                path: path.to_path_buf(),
                reason,
            });
        }
        check_exr_sizes(bytes).map_err(err)?;
        // On this thread (not the decoder's thread pool, where a panic aborts the
        // process) and inside catch_unwind: the decoder's B44 code overflows an integer
        // on some damaged data, which panics where overflow checks are on.
        let decode = || {
            exr::prelude::read()
                .no_deep_data()
                .largest_resolution_level()
                .rgba_channels(
                    |size, _| Self::new(size.0 as u32, size.1 as u32),
                    |img: &mut Self, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                        let i = pos.1 * img.width as usize + pos.0;
                        img.data[i] = [r, g, b];
                    },
                )
                .first_valid_layer()
                .all_attributes()
                .non_parallel()
                .from_buffered(std::io::Cursor::new(bytes))
        };
        let image = std::panic::catch_unwind(decode)
            .map_err(|_| err("the OpenEXR decoder failed on its pixel data (damaged?)".into()))?
            .map_err(|e| err(e.to_string()))?;
        Ok(image.layer_data.channel_data.pixels)
    }

    /// Write float32 RGB OpenEXR (linear radiance, no exposure).
    pub fn write_exr(&self, path: &Path) -> Result<(), ImageError> {
        write_atomically(path, |file| self.write_exr_to(file))
    }

    /// [`Image::write_exr`] into an open file (an [`OutputFiles`] output).
    pub fn write_exr_to(&self, file: &mut File) -> Result<(), String> {
        use exr::prelude::{Encoding, LineOrder, SpecificChannels, Vec2, WritableImage};
        let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
            let p = self.data[y * self.width as usize + x];
            (p[0], p[1], p[2])
        });
        // The crate's default (RLE, 64 x 64 tiles) with its tiles in increasing
        // order: the default's unspecified order writes them as the threads finish
        // compressing, so one image made files of different bytes from run to run.
        let encoding = Encoding {
            line_order: LineOrder::Increasing,
            ..Encoding::FAST_LOSSLESS
        };
        exr::prelude::Image::from_encoded_channels(
            (self.width as usize, self.height as usize),
            encoding,
            channels,
        )
        .write()
        .to_unbuffered(file)
        .map_err(|e| e.to_string())
    }

    /// Write an 8-bit sRGB PNG of the image times `exposure` (clamped to [0, 1]).
    pub fn write_png(&self, path: &Path, exposure: f32) -> Result<(), ImageError> {
        write_atomically(path, |file| self.write_png_to(file, exposure))
    }

    /// [`Image::write_png`] into an open file (an [`OutputFiles`] output).
    pub fn write_png_to(&self, file: &mut File, exposure: f32) -> Result<(), String> {
        let bytes = self.to_srgb8(exposure);
        // Flushed by hand below: a BufWriter dropped unflushed drops the error of its
        // last write (a full disk, a file-size limit) and the file would look complete.
        let mut buffered = BufWriter::new(file);
        let mut encoder = png::Encoder::new(&mut buffered, self.width, self.height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
        // fdeflate's fast mode: tens of times faster than the default (Balanced) for
        // files up to a quarter larger; the default took longer than a frame's GPU work
        // in `igi render` and seconds of a full `igi bench` table (figures in the lab
        // log, BENCHMARKS-history.md).
        encoder.set_compression(png::Compression::Fast);
        let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
        writer.write_image_data(&bytes).map_err(|e| e.to_string())?;
        writer.finish().map_err(|e| e.to_string())?;
        std::io::Write::flush(&mut buffered).map_err(|e| e.to_string())
    }

    /// 8-bit sRGB bytes (RGB, rows top to bottom) of the image times `exposure`.
    pub fn to_srgb8(&self, exposure: f32) -> Vec<u8> {
        self.data
            .iter()
            .flat_map(|p| p.map(|v| (linear_to_srgb(v * exposure) * 255.0 + 0.5) as u8))
            .collect()
    }
}

/// The most pixels one layer of an OpenEXR file may hold for igi to read it: 2^27 (a
/// 16,384 x 8,192 image), 1.5 GiB as RGB floats, plus what the decoder holds beside.
pub const MAX_EXR_PIXELS: u64 = 1 << 27;

/// The most an OpenEXR file's pixel data can expand when decoded, rounded up: deflate
/// (ZIP, ZIPS, PXR24) reaches about 1,032 to 1, PIZ's Huffman code with its runs about
/// 450, RLE 64, B44 11; decoding to RGB floats can double half samples.
pub const MAX_EXR_EXPANSION: u64 = 2048;

/// Decoded sizes up to this many bytes (64 MiB) are read from files of any length: the
/// expansion bound only matters for larger images.
const EXR_BOMB_FLOOR: u64 = 64 << 20;

/// Errors where the headers of OpenEXR `bytes` declare more than igi reads or more than
/// the file can hold, from the headers alone: a layer of more than [`MAX_EXR_PIXELS`],
/// more pixels than the file's length can decode to ([`MAX_EXR_EXPANSION`]), or more
/// blocks than the file has room for in its offset tables (8 bytes a block), so that a
/// small file cannot make the decoder allocate for a huge image.
fn check_exr_sizes(bytes: &[u8]) -> Result<(), String> {
    let meta = exr::meta::MetaData::read_from_buffered(bytes, false).map_err(|e| e.to_string())?;
    let mut blocks = 0u64;
    let most_decoded = (bytes.len() as u64)
        .saturating_mul(MAX_EXR_EXPANSION)
        .max(EXR_BOMB_FLOOR);
    for h in &meta.headers {
        let (w, h_px) = (h.layer_size.0 as u64, h.layer_size.1 as u64);
        let pixels = w.saturating_mul(h_px);
        if pixels > MAX_EXR_PIXELS {
            return Err(format!(
                "its header declares a {w} x {h_px} image ({pixels} pixels); igi reads at most {MAX_EXR_PIXELS}"
            ));
        }
        // What reading it allocates: the image as RGB floats.
        let decoded = pixels.saturating_mul(12);
        if decoded > most_decoded {
            return Err(format!(
                "its header declares a {w} x {h_px} image ({decoded} bytes as RGB floats) in a file of {} bytes: more than any OpenEXR compression expands to (at most {MAX_EXR_EXPANSION} times); the file is damaged",
                bytes.len()
            ));
        }
        blocks = blocks.saturating_add(h.chunk_count as u64);
    }
    let table = blocks.saturating_mul(8);
    if table > bytes.len() as u64 {
        return Err(format!(
            "its headers declare {blocks} blocks, whose offset tables alone take {table} bytes, but the file has {}: it is cut short or damaged",
            bytes.len()
        ));
    }
    Ok(())
}

/// Why `bytes` cannot be OpenEXR at all, or `None` where they begin as OpenEXR does (its
/// magic number 76 2f 31 01).
fn not_exr_reason(bytes: &[u8]) -> Option<String> {
    const EXR: &[u8] = &[0x76, 0x2f, 0x31, 0x01];
    const PNG: &[u8] = b"\x89PNG\r\n\x1a\n";
    if bytes.starts_with(EXR) {
        None
    } else if bytes.is_empty() {
        Some("the file is empty".into())
    } else if bytes.starts_with(PNG) {
        Some("it is a PNG image".into())
    } else {
        Some("it does not begin with the OpenEXR magic number".into())
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

/// What `igi compare` reports of an image against a reference of the same size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Comparison {
    pub rel_mse: f64,
    /// Channel means of the image and of the reference.
    pub means: ([f64; 3], [f64; 3]),
    pub pixels: PixelDifferences,
}

impl Comparison {
    /// `image` against `reference`; an error where their sizes differ.
    pub fn of(image: &Image, reference: &Image) -> Result<Comparison, ImageError> {
        Ok(Comparison {
            rel_mse: rel_mse(image, reference)?,
            means: (image.mean(), reference.mean()),
            pixels: pixel_differences(image, reference)?,
        })
    }
}

/// Where two images of one size differ, pixel by pixel: what `igi compare` reports
/// beside the relMSE, which rounds small differences to 0 and does not tell a few wrong
/// pixels from many slightly different ones.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelDifferences {
    /// Pixels with a channel whose bits differ (NaN against NaN counts as equal only in
    /// the same bits).
    pub differing: usize,
    pub pixels: usize,
    /// The largest |image - reference| of a channel, its pixel (x, y) and the
    /// reference's value there; `None` where no pixel differs.
    pub largest: Option<(f32, (u32, u32), f32)>,
}

/// The [`PixelDifferences`] of `image` against `reference`.
pub fn pixel_differences(image: &Image, reference: &Image) -> Result<PixelDifferences, ImageError> {
    same_size(image, reference)?;
    let mut differing = 0;
    let mut largest: Option<(f32, (u32, u32), f32)> = None;
    for (i, (p, r)) in image.data.iter().zip(&reference.data).enumerate() {
        if p.map(f32::to_bits) == r.map(f32::to_bits) {
            continue;
        }
        differing += 1;
        for c in 0..3 {
            let d = (p[c] - r[c]).abs();
            // A NaN difference (one side NaN or infinite) is the largest there is.
            let d = if d.is_nan() { f32::INFINITY } else { d };
            if largest.is_none_or(|(l, _, _)| d > l) {
                let at = (
                    (i % image.width as usize) as u32,
                    (i / image.width as usize) as u32,
                );
                largest = Some((d, at, r[c]));
            }
        }
    }
    Ok(PixelDifferences {
        differing,
        pixels: image.data.len(),
        largest,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One image makes one file, byte for byte: its tiles in increasing order, whatever
    /// order the threads compress them in.
    #[test]
    fn exr_files_of_one_image_are_the_same_bytes() {
        let dir = std::env::temp_dir().join(format!("igi-exr-bytes-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // 20 tiles of 64 x 64, of uneven content so that they compress unevenly.
        let mut image = Image::new(320, 256);
        for (i, p) in image.data.iter_mut().enumerate() {
            let v = if (i / 320) % 64 < 32 {
                0.5
            } else {
                (i as f32 * 0.618).fract()
            };
            *p = [v, v * 0.5, 1.0 - v];
        }
        let paths = [dir.join("a.exr"), dir.join("b.exr")];
        for p in &paths {
            image.write_exr(p).unwrap();
        }
        let meta = exr::meta::MetaData::read_from_file(&paths[0], false).unwrap();
        assert_eq!(
            meta.headers[0].line_order,
            exr::meta::attribute::LineOrder::Increasing
        );
        assert_eq!(
            std::fs::read(&paths[0]).unwrap(),
            std::fs::read(&paths[1]).unwrap()
        );
        assert_eq!(Image::read_exr(&paths[0]).unwrap().data, image.data);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn pixel_differences_count_pixels_and_find_the_largest() {
        let mut a = Image::new(4, 3);
        a.data.fill([0.5, 0.25, 1.0]);
        let mut b = a.clone();
        let same = pixel_differences(&a, &b).unwrap();
        assert_eq!((same.differing, same.pixels, same.largest), (0, 12, None));
        // Two pixels differ: one by an ulp, one by 0.125 in blue at (1, 2).
        b.data[5][0] = f32::from_bits(0.5f32.to_bits() + 1);
        b.data[9][2] = 0.875;
        let d = pixel_differences(&a, &b).unwrap();
        assert_eq!(d.differing, 2);
        assert_eq!(d.largest, Some((0.125, (1, 2), 0.875)));
        // A NaN pixel is the largest difference; the same NaN on both sides is none.
        b.data[2][1] = f32::NAN;
        let d = pixel_differences(&a, &b).unwrap();
        assert_eq!(
            (d.differing, d.largest.map(|l| (l.0, l.1))),
            (3, Some((f32::INFINITY, (2, 0))))
        );
        a.data[2][1] = f32::NAN;
        assert_eq!(pixel_differences(&a, &b).unwrap().differing, 2);
        assert!(pixel_differences(&a, &Image::new(3, 4)).is_err());
    }

    #[test]
    fn files_of_other_kinds_are_not_openexr() {
        let dir = std::env::temp_dir().join(format!("igi-not-exr-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let empty = dir.join("empty.exr");
        std::fs::write(&empty, b"").unwrap();
        let e = Image::read_exr(&empty).unwrap_err().to_string();
        assert!(
            e.contains("is not an OpenEXR file (the file is empty)"),
            "{e}"
        );
        let png = dir.join("image.exr");
        Image::new(2, 2).write_png(&png, 1.0).unwrap();
        let e = Image::read_exr(&png).unwrap_err().to_string();
        assert!(
            e.contains("is not an OpenEXR file (it is a PNG image)"),
            "{e}"
        );
        // A damaged OpenEXR file keeps the decoder's words.
        std::fs::write(&empty, [0x76, 0x2f, 0x31, 0x01, 2]).unwrap();
        let e = Image::read_exr(&empty).unwrap_err().to_string();
        assert!(e.starts_with("cannot read"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

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
        // The PNG decodes to the image's sRGB bytes (here a larger one, so that the
        // compressor's matches and filters run).
        let mut big = Image::new(97, 61);
        for (i, p) in big.data.iter_mut().enumerate() {
            let (x, y) = ((i % 97) as f32, (i / 97) as f32);
            *p = [
                x / 97.0,
                (x * y * 0.37).sin().abs(),
                if (i / 7) % 2 == 0 { 0.2 } else { 2.0 },
            ];
        }
        big.write_png(&dir.join("big.png"), 0.8).unwrap();
        let decoder = png::Decoder::new(std::io::BufReader::new(
            std::fs::File::open(dir.join("big.png")).unwrap(),
        ));
        let mut reader = decoder.read_info().unwrap();
        let mut decoded = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut decoded).unwrap();
        assert_eq!((info.width, info.height), (97, 61));
        assert_eq!(info.color_type, png::ColorType::Rgb);
        assert_eq!(&decoded[..info.buffer_size()], &big.to_srgb8(0.8)[..]);
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

    fn fresh_dir(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("igi-image-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn mkfifo(path: &Path) {
        let status = std::process::Command::new("mkfifo")
            .arg(path)
            .status()
            .unwrap();
        assert!(status.success());
    }

    #[cfg(unix)]
    #[test]
    fn writes_follow_links_and_refuse_what_is_not_a_regular_file() {
        use std::os::unix::fs::FileTypeExt;
        let dir = fresh_dir("targets");
        let img = Image::new(2, 2);
        // A link keeps being a link; its target gets the image.
        std::fs::write(dir.join("target.exr"), "old").unwrap();
        std::os::unix::fs::symlink("target.exr", dir.join("link.exr")).unwrap();
        img.write_exr(&dir.join("link.exr")).unwrap();
        let link = std::fs::symlink_metadata(dir.join("link.exr")).unwrap();
        assert!(link.file_type().is_symlink());
        assert_eq!(Image::read_exr(&dir.join("target.exr")).unwrap(), img);
        assert_eq!(
            output_target(&dir.join("link.exr")).unwrap(),
            dir.canonicalize().unwrap().join("target.exr")
        );
        // A FIFO or a directory is neither replaced nor written.
        mkfifo(&dir.join("fifo.png"));
        std::fs::create_dir(dir.join("dir.png")).unwrap();
        for name in ["fifo.png", "dir.png"] {
            let e = img.write_png(&dir.join(name), 1.0).unwrap_err().to_string();
            assert!(e.contains("not a regular file"), "{e}");
        }
        let fifo = std::fs::symlink_metadata(dir.join("fifo.png")).unwrap();
        assert!(fifo.file_type().is_fifo());
        assert!(dir.join("dir.png").is_dir());
        let mut names: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
            .collect();
        names.sort();
        assert_eq!(names, ["dir.png", "fifo.png", "link.exr", "target.exr"]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn a_fifo_is_refused_not_read_forever() {
        let dir = fresh_dir("fifo-read");
        let fifo = dir.join("in.exr");
        mkfifo(&fifo);
        // Reading a FIFO without a writer would block: the test ends either way.
        let (tx, rx) = std::sync::mpsc::channel();
        let path = fifo.clone();
        std::thread::spawn(move || tx.send(Image::read_exr(&path).map_err(|e| e.to_string())));
        let result = rx
            .recv_timeout(std::time::Duration::from_secs(20))
            .expect("read_exr blocked on a FIFO");
        let e = result.unwrap_err();
        assert!(
            e.contains("in.exr") && e.contains("not a regular file"),
            "{e}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// An uncompressed scanline OpenEXR file of float RGB whose header declares a
    /// `width` x `height` data window and whose offset table and pixels are those of
    /// `lines` lines of `width` pixels (fewer than declared makes a damaged file).
    fn declared_exr(width: i32, height: i32, lines: i32) -> Vec<u8> {
        let attr = |name: &str, kind: &str, data: &[u8]| {
            let mut a = [name.as_bytes(), b"\0", kind.as_bytes(), b"\0"].concat();
            a.extend((data.len() as i32).to_le_bytes());
            a.extend(data);
            a
        };
        let mut chlist = vec![];
        for c in ["B", "G", "R"] {
            chlist.extend(c.as_bytes());
            chlist.push(0);
            chlist.extend(2i32.to_le_bytes());
            chlist.extend([0u8; 4]);
            chlist.extend(1i32.to_le_bytes());
            chlist.extend(1i32.to_le_bytes());
        }
        chlist.push(0);
        let window: Vec<u8> = [0, 0, width - 1, height - 1]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let mut header = [
            attr("channels", "chlist", &chlist),
            attr("compression", "compression", &[0]),
            attr("dataWindow", "box2i", &window),
            attr("displayWindow", "box2i", &window),
            attr("lineOrder", "lineOrder", &[0]),
            attr("pixelAspectRatio", "float", &1f32.to_le_bytes()),
            attr("screenWindowCenter", "v2f", &[0; 8]),
            attr("screenWindowWidth", "float", &1f32.to_le_bytes()),
        ]
        .concat();
        header.push(0);
        let mut file = vec![0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0];
        file.extend(&header);
        let line_bytes = 12 * width as usize;
        let start = file.len() + 8 * lines as usize;
        for y in 0..lines as usize {
            file.extend(((start + y * (8 + line_bytes)) as u64).to_le_bytes());
        }
        for y in 0..lines {
            file.extend(y.to_le_bytes());
            file.extend((line_bytes as i32).to_le_bytes());
            file.extend(std::iter::repeat_n(0u8, line_bytes));
        }
        file
    }

    #[test]
    fn exr_headers_cannot_ask_for_more_than_the_file_holds() {
        let path = Path::new("x.exr");
        // A whole small file reads.
        let ok = Image::read_exr_bytes(&declared_exr(5, 3, 3), path).unwrap();
        assert_eq!((ok.width, ok.height), (5, 3));
        // 1e10 pixels declared: refused from the header, before any allocation.
        let e = Image::read_exr_bytes(&declared_exr(100_000, 100_000, 1), path)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("x.exr") && e.contains("igi reads at most"),
            "{e}"
        );
        // 25 M pixels (300 MB as floats) declared in a file of a few kilobytes.
        let e = Image::read_exr_bytes(&declared_exr(5_000, 5_000, 0), path)
            .unwrap_err()
            .to_string();
        assert!(e.contains("more than any OpenEXR compression"), "{e}");
        // Within the pixel limit, but 10,000 lines declared of a file that has 2: its
        // offset table alone would be longer than the file.
        let e = Image::read_exr_bytes(&declared_exr(100, 10_000, 2), path)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("offset tables") && e.contains("cut short"),
            "{e}"
        );
    }
}
