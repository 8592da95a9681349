//! CPU twin of `shaders/upsample.wgsl`: joint bilateral upsampling of the downsampled
//! indirect term (paper section 4.2), and the gatherer it shares with the fused filter
//! (`filter.wgsl`, [`crate::passes::filter::cpu`]). Function by function as the WGSL, with its names;
//! the WGSL's globals (`params`, `gbuf_normal` and the includer's `low_irradiance`) are
//! the fields of [`Upsampler`].

use crate::layout::FrameParams;
use crate::shaders::gbuffer::{representative_pixel, Rgba};
use glam::Vec3;

/// What upsample.wgsl reads: the frame's parameters, the G-buffer's shading normals (w:
/// the primary hit's distance, 0 where none) and E at the indirect term's resolution
/// (`low_irradiance`, whatever buffer the including pass binds there).
pub struct Upsampler<'a> {
    pub params: &'a FrameParams,
    pub gbuf_normal: &'a [Rgba],
    pub low_irradiance: &'a [Rgba],
}

/// What a full-resolution pixel gathers from low-resolution samples: the weighted sum,
/// and the nearest surface sample as the fallback where every weight is zero.
#[derive(Clone, Copy, Debug)]
pub struct Gathered {
    pub sum: Vec3,
    pub weight: f32,
    pub nearest: Vec3,
    pub nearest_d2: f32,
}

pub fn new_gathered() -> Gathered {
    Gathered {
        sum: Vec3::ZERO,
        weight: 0.0,
        nearest: Vec3::ZERO,
        nearest_d2: 1e30,
    }
}

pub fn gathered_value(g: Gathered) -> Vec3 {
    if g.weight > 1e-6 {
        return g.sum / g.weight;
    }
    g.nearest
}

pub(crate) fn xyz(v: Rgba) -> Vec3 {
    Vec3::new(v[0], v[1], v[2])
}

impl Upsampler<'_> {
    /// E of low-resolution pixel i (the includer's `low_irradiance`).
    pub fn low_irradiance(&self, i: usize) -> Vec3 {
        xyz(self.low_irradiance[i])
    }

    /// Low-resolution coordinate of full-resolution pixel p's centre, in the frame where
    /// low-res pixel c sits at its representative pixel's centre.
    pub fn low_coordinate(&self, p: u32) -> f32 {
        let s = self.params.downsample as f32;
        (p as f32 - (self.params.downsample / 2) as f32) / s
    }

    /// Whether the primary ray of pixel q hit a surface (the shading normal's w, the
    /// hit's distance, is positive).
    pub fn has_surface(&self, q: usize) -> bool {
        self.gbuf_normal[q][3] > 0.0
    }

    /// Range weight of the upsampler between full-resolution pixel p and sample q.
    pub fn range_weight(&self, p: usize, q: usize) -> f32 {
        let nq = self.gbuf_normal[q];
        if nq[3] <= 0.0 {
            return 0.0;
        }
        let np = self.gbuf_normal[p];
        let mut w = xyz(np).dot(xyz(nq)).max(0.0).powf(self.params.normal_power);
        if self.params.upsample_depth != 0 {
            let d = (np[3] - nq[3]) / (self.params.depth_threshold * np[3]);
            w *= (-0.5 * d * d).exp();
        }
        w
    }

    /// Add low-resolution sample (x, y), inside the image, with weight w, at squared
    /// distance d2 (low-resolution pixels) from the pixel being filtered.
    pub fn gather_sample(&self, g: &mut Gathered, x: i32, y: i32, w: f32, d2: f32) {
        let q = representative_pixel(self.params, x as u32, y as u32);
        let value = self.low_irradiance((y as u32 * self.params.low_width + x as u32) as usize);
        g.sum += w * value;
        g.weight += w;
        if self.has_surface(q) && d2 < g.nearest_d2 {
            g.nearest_d2 = d2;
            g.nearest = value;
        }
    }

    pub fn inside_low(&self, x: i32, y: i32) -> bool {
        x >= 0 && y >= 0 && x < self.params.low_width as i32 && y < self.params.low_height as i32
    }

    /// E at full-resolution pixel (x, y), index `pixel`, where a surface was hit: the
    /// 4 x 4 low-resolution neighbours, each weighed by a spatial Gaussian and the range
    /// weight, in the WGSL's order (rows, then columns).
    pub fn upsampled_irradiance(&self, x: u32, y: u32, pixel: usize) -> Vec3 {
        let u = self.low_coordinate(x);
        let v = self.low_coordinate(y);
        let bx = u.floor() as i32;
        let by = v.floor() as i32;
        let mut g = new_gathered();
        let inv_two_sigma2 = 0.5 / (self.params.upsample_sigma * self.params.upsample_sigma);
        for j in -1..=2 {
            for i in -1..=2 {
                let sx = bx + i;
                let sy = by + j;
                if !self.inside_low(sx, sy) {
                    continue;
                }
                let dx = sx as f32 - u;
                let dy = sy as f32 - v;
                let d2 = dx * dx + dy * dy;
                let q = representative_pixel(self.params, sx as u32, sy as u32);
                let w = (-d2 * inv_two_sigma2).exp() * self.range_weight(pixel, q);
                self.gather_sample(&mut g, sx, sy, w, d2);
            }
        }
        gathered_value(g)
    }
}
