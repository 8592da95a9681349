//! Perceptual image error: LDR FLIP (Andersson et al. 2020, "FLIP: A Difference Evaluator
//! for Alternating Images"), computed by NVIDIA's C++ reference implementation through the
//! `nv-flip` bindings.
//!
//! Both images are tone-mapped as igi's PNGs are ([`Image::to_srgb8`]: times `exposure`,
//! sRGB curve, clamped to [0, 1], 8 bits), so the value is the one NVIDIA's `flip` tool
//! gives on the two PNG files. FLIP then goes sRGB -> linear -> YCxCz, filters with the
//! contrast sensitivity functions at [`PIXELS_PER_DEGREE`] (0.7 m from a 0.7 m wide
//! 3840-pixel monitor), takes the HyAB distance of the Hunt-adjusted L*a*b* colours, and
//! raises it to a power given by the edge and point differences of the achromatic channel.
//! The result lies in [0, 1]: 0 for identical images.

use crate::image::{Image, ImageError};

/// The standard FLIP viewing condition: 67 pixels per degree of visual angle.
pub const PIXELS_PER_DEGREE: f32 = 67.0;

/// FLIP of a test image against a reference.
#[derive(Clone, Debug, PartialEq)]
pub struct FlipResult {
    /// Mean of the per-pixel FLIP errors (what the FLIP authors recommend reporting).
    pub mean: f64,
    /// Largest per-pixel error.
    pub max: f32,
    pub width: u32,
    pub height: u32,
    /// Per-pixel error in [0, 1], rows top to bottom; only from [`flip_with_map`].
    pub error_map: Option<Vec<f32>>,
}

impl FlipResult {
    /// The error map through FLIP's magma colour map as 8-bit sRGB bytes (RGB, rows top to
    /// bottom), as the `flip` tool shows it; `None` without an error map.
    pub fn error_map_magma(&self) -> Option<Vec<u8>> {
        let map = self.error_map.as_ref()?;
        if map.is_empty() {
            return Some(Vec::new());
        }
        let errors = nv_flip::FlipImageFloat::with_data(self.width, self.height, map);
        Some(errors.apply_color_lut(&nv_flip::magma_lut()).to_vec())
    }
}

/// Mean LDR FLIP of `test` against `reference`, both tone-mapped with `exposure`.
pub fn flip(test: &Image, reference: &Image, exposure: f32) -> Result<FlipResult, ImageError> {
    flip_impl(test, reference, exposure, false)
}

/// As [`flip`], keeping the per-pixel error map.
pub fn flip_with_map(
    test: &Image,
    reference: &Image,
    exposure: f32,
) -> Result<FlipResult, ImageError> {
    flip_impl(test, reference, exposure, true)
}

fn flip_impl(
    test: &Image,
    reference: &Image,
    exposure: f32,
    keep_map: bool,
) -> Result<FlipResult, ImageError> {
    crate::image::same_size(test, reference)?;
    let (width, height) = (test.width, test.height);
    let n = width as usize * height as usize;
    if test.data.len() != n || reference.data.len() != n {
        return Err(ImageError::Read {
            path: "<memory>".into(),
            reason: format!(
                "pixel data of {} and {} values for a {width}x{height} image",
                test.data.len(),
                reference.data.len()
            ),
        });
    }
    let errors = if n == 0 {
        Vec::new()
    } else {
        let r = nv_flip::FlipImageRgb8::with_data(width, height, &reference.to_srgb8(exposure));
        let t = nv_flip::FlipImageRgb8::with_data(width, height, &test.to_srgb8(exposure));
        nv_flip::flip(r, t, PIXELS_PER_DEGREE).to_vec()
    };
    let sum: f64 = errors.iter().map(|&e| e as f64).sum();
    let max = errors.iter().copied().fold(0.0f32, f32::max);
    Ok(FlipResult {
        mean: if n == 0 { 0.0 } else { sum / n as f64 },
        max,
        width,
        height,
        error_map: keep_map.then_some(errors),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn uniform(w: u32, h: u32, c: [f32; 3]) -> Image {
        Image {
            width: w,
            height: h,
            data: vec![c; (w * h) as usize],
        }
    }

    /// FLIP of two uniform images, derived by hand from the paper's formulas (in f64, with
    /// the reference implementation's colour matrices): the CSF filters are normalised, so
    /// a uniform image stays uniform; the edge and point detectors see nothing, so the
    /// error is the colour term alone: HyAB distance of the Hunt-adjusted L*a*b* colours,
    /// to the power 0.7, remapped with (pc, pt) = (0.4, 0.95) against the green-blue
    /// distance.
    fn uniform_flip(a: [u8; 3], b: [u8; 3]) -> f64 {
        fn lin(c: u8) -> f64 {
            let s = c as f64 / 255.0;
            if s <= 0.04045 {
                s / 12.92
            } else {
                ((s + 0.055) / 1.055).powf(2.4)
            }
        }
        fn lab_hunt(rgb: [f64; 3]) -> [f64; 3] {
            let m = [
                [
                    10135552.0 / 24577794.0,
                    8788810.0 / 24577794.0,
                    4435075.0 / 24577794.0,
                ],
                [
                    2613072.0 / 12288897.0,
                    8788810.0 / 12288897.0,
                    887015.0 / 12288897.0,
                ],
                [
                    1425312.0 / 73733382.0,
                    8788810.0 / 73733382.0,
                    70074185.0 / 73733382.0,
                ],
            ];
            let white = [0.950428545, 1.0, 1.088900371];
            let d: f64 = 6.0 / 29.0;
            let f = |t: f64| {
                if t > d * d * d {
                    t.cbrt()
                } else {
                    t / (3.0 * d * d) + 4.0 / 29.0
                }
            };
            let xyz: Vec<f64> = (0..3)
                .map(|i| (m[i][0] * rgb[0] + m[i][1] * rgb[1] + m[i][2] * rgb[2]) / white[i])
                .map(f)
                .collect();
            let l = 116.0 * xyz[1] - 16.0;
            let a = 500.0 * (xyz[0] - xyz[1]);
            let b = 200.0 * (xyz[1] - xyz[2]);
            [l, 0.01 * l * a, 0.01 * l * b]
        }
        fn hyab(p: [f64; 3], q: [f64; 3]) -> f64 {
            (p[0] - q[0]).abs() + ((p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
        }
        let (qc, pc, pt) = (0.7, 0.4, 0.95);
        let cmax = hyab(lab_hunt([0.0, 1.0, 0.0]), lab_hunt([0.0, 0.0, 1.0])).powf(qc);
        let e = hyab(lab_hunt(a.map(lin)), lab_hunt(b.map(lin))).powf(qc);
        if e < pc * cmax {
            e * pt / (pc * cmax)
        } else {
            pt + (e - pc * cmax) / (cmax - pc * cmax) * (1.0 - pt)
        }
    }

    #[test]
    fn identical_images_give_zero() {
        let mut img = Image::new(40, 30);
        for (i, p) in img.data.iter_mut().enumerate() {
            *p = [(i % 7) as f32 * 0.2, (i % 13) as f32 * 0.05, 0.3];
        }
        let r = flip_with_map(&img, &img, 1.0).unwrap();
        assert_eq!(r.mean, 0.0);
        assert_eq!(r.max, 0.0);
        assert_eq!(r.error_map.as_ref().unwrap().len(), 40 * 30);
        assert!(r.error_map.unwrap().iter().all(|&e| e == 0.0));
        assert_eq!(flip(&img, &img, 3.0).unwrap().mean, 0.0);
    }

    #[test]
    fn black_against_white_is_near_maximal() {
        let black = uniform(32, 32, [0.0; 3]);
        let white = uniform(32, 32, [1.0; 3]);
        let r = flip_with_map(&black, &white, 1.0).unwrap();
        let expected = uniform_flip([0; 3], [255; 3]);
        // The derivation gives 0.9677: above pt = 0.95, as the paper intends for a
        // difference larger than 0.4 of the green-blue one.
        assert!((expected - 0.9677).abs() < 1e-3, "{expected}");
        assert!((r.mean - expected).abs() < 5e-4, "{} vs {expected}", r.mean);
        for &e in r.error_map.as_ref().unwrap() {
            assert!((e as f64 - expected).abs() < 5e-4, "{e}");
        }
        // Symmetric for uniform images, and exposure only scales the input.
        assert!((flip(&white, &black, 1.0).unwrap().mean - r.mean).abs() < 1e-6);
        let grey = uniform(32, 32, [0.5; 3]);
        assert!((flip(&black, &grey, 2.0).unwrap().mean - r.mean).abs() < 1e-6);
    }

    #[test]
    fn uniform_colours_match_the_derivation() {
        let cases: [([f32; 3], [f32; 3]); 5] = [
            ([0.5; 3], [0.6; 3]),
            ([0.2; 3], [0.21; 3]),
            ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
            ([0.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
            ([0.8, 0.4, 0.1], [0.7, 0.45, 0.15]),
        ];
        for (a, b) in cases {
            let (ia, ib) = (uniform(24, 20, a), uniform(24, 20, b));
            let got = flip(&ia, &ib, 1.0).unwrap().mean;
            let sa = ia.to_srgb8(1.0);
            let sb = ib.to_srgb8(1.0);
            let expected = uniform_flip([sa[0], sa[1], sa[2]], [sb[0], sb[1], sb[2]]);
            assert!(
                (got - expected).abs() < 5e-4,
                "{a:?} vs {b:?}: {got} against {expected}"
            );
        }
        // Green against blue is cmax itself: exactly 1 by construction.
        let g = uniform(8, 8, [0.0, 1.0, 0.0]);
        let b = uniform(8, 8, [0.0, 0.0, 1.0]);
        assert!((flip(&g, &b, 1.0).unwrap().mean - 1.0).abs() < 1e-3);
    }

    #[test]
    fn small_change_small_error_and_ordering() {
        let mut base = Image::new(32, 32);
        for (i, p) in base.data.iter_mut().enumerate() {
            let (x, y) = (i % 32, i / 32);
            *p = [x as f32 / 31.0, y as f32 / 31.0, 0.25];
        }
        let mut one = base.clone();
        one.data[16 * 32 + 16] = [1.0, 1.0, 1.0];
        let r1 = flip_with_map(&one, &base, 1.0).unwrap();
        assert!(r1.mean > 0.0 && r1.mean < 0.01, "{}", r1.mean);
        // The error is local: largest at the changed pixel, none far away.
        let map = r1.error_map.unwrap();
        assert_eq!(map[16 * 32 + 16], r1.max);
        assert_eq!(map[0], 0.0);

        let mut four = one.clone();
        for (x, y) in [(4, 4), (27, 4), (4, 27), (27, 27)] {
            four.data[y * 32 + x] = [1.0, 1.0, 1.0];
        }
        let r4 = flip(&four, &base, 1.0).unwrap();
        assert!(r4.mean > r1.mean * 2.0, "{} vs {}", r4.mean, r1.mean);

        // Noise of growing amplitude: growing FLIP.
        let mut last = 0.0;
        for amp in [0.02f32, 0.1, 0.4] {
            let mut noisy = base.clone();
            for (i, p) in noisy.data.iter_mut().enumerate() {
                let s = if (i * 2654435761) % 7 < 3 { amp } else { -amp };
                *p = p.map(|v| (v + s).max(0.0));
            }
            let m = flip(&noisy, &base, 1.0).unwrap().mean;
            assert!(m > last, "amplitude {amp}: {m} after {last}");
            last = m;
        }
        assert!(last < 1.0);
    }

    #[test]
    fn size_mismatch_and_empty() {
        let e = flip(&Image::new(4, 4), &Image::new(4, 5), 1.0).unwrap_err();
        assert!(matches!(e, ImageError::SizeMismatch(4, 4, 4, 5)), "{e}");
        let r = flip(&Image::new(0, 0), &Image::new(0, 0), 1.0).unwrap();
        assert_eq!(r.mean, 0.0);
    }

    #[test]
    fn magma_map_has_the_image_size() {
        let a = uniform(5, 3, [0.0; 3]);
        let b = uniform(5, 3, [1.0; 3]);
        let r = flip_with_map(&a, &b, 1.0).unwrap();
        assert_eq!(r.error_map_magma().unwrap().len(), 5 * 3 * 3);
        assert!(flip(&a, &b, 1.0).unwrap().error_map_magma().is_none());
    }
}
