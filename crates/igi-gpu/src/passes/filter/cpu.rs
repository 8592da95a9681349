//! CPU twin of `filter.wgsl`: the discontinuity buffer at the indirect term's
//! resolution (paper section 4.3) and the fused filter that also upsamples (the paper's
//! future work). Function by function as the WGSL, with its names; the WGSL's bindings
//! are the fields of [`Filter`], and each entry point becomes a function of one
//! invocation plus one that runs it over the whole grid, as the dispatch does. The fused
//! filter gathers through [`crate::shaders::upsample`], as filter.wgsl through upsample.wgsl.

use crate::layout::FrameParams;
use crate::shaders::gbuffer::{representative_pixel, Rgba};
use crate::shaders::upsample::{gathered_value, new_gathered, xyz, Upsampler};
use glam::Vec3;

/// filter.wgsl's bindings: the frame's parameters (the main ones, or the mirror pass's
/// at full resolution), the G-buffer's positions and shading normals (or the mirror
/// record's), and the interleaved term it filters.
pub struct Filter<'a> {
    pub params: &'a FrameParams,
    pub gbuf_position: &'a [Rgba],
    pub gbuf_normal: &'a [Rgba],
    pub filter_in: &'a [Rgba],
}

impl Filter<'_> {
    /// The upsampler over `filter_in` (the WGSL's `low_irradiance` of this pass).
    fn upsampler(&self) -> Upsampler<'_> {
        Upsampler {
            params: self.params,
            gbuf_normal: self.gbuf_normal,
            low_irradiance: self.filter_in,
        }
    }

    /// Whether full-resolution G-buffer samples a and b lie on one continuous surface.
    pub fn continuous(&self, a: usize, b: usize) -> bool {
        if self.gbuf_position[b][3] <= 0.0 {
            return false;
        }
        let na = self.gbuf_normal[a];
        let nb = self.gbuf_normal[b];
        let depth_ok = (na[3] - nb[3]).abs() <= self.params.depth_threshold * na[3];
        depth_ok && xyz(na).dot(xyz(nb)) >= self.params.normal_threshold
    }

    /// The discontinuity entry point at low-resolution pixel (x, y): the mean of the
    /// n x m window's samples continuous with the centre.
    pub fn discontinuity(&self, x: u32, y: u32) -> Rgba {
        let p = self.params;
        let centre = representative_pixel(p, x, y);
        if self.gbuf_position[centre][3] <= 0.0 {
            return [0.0, 0.0, 0.0, 1.0];
        }
        let mut sum = Vec3::ZERO;
        let mut weight = 0.0f32;
        let x0 = window_start(x, p.interleave_n);
        let y0 = window_start(y, p.interleave_m);
        for j in 0..p.interleave_m as i32 {
            for i in 0..p.interleave_n as i32 {
                let x = x0 + i;
                let y = y0 + j;
                if x < 0 || y < 0 || x >= p.low_width as i32 || y >= p.low_height as i32 {
                    continue;
                }
                let q = representative_pixel(p, x as u32, y as u32);
                if self.continuous(centre, q) {
                    sum += xyz(self.filter_in[(y as u32 * p.low_width + x as u32) as usize]);
                    weight += 1.0;
                }
            }
        }
        let e = sum / weight.max(1.0);
        [e.x, e.y, e.z, 1.0]
    }

    /// The discontinuity pass over the whole indirect term (low_width x low_height).
    pub fn discontinuity_image(&self) -> Vec<Rgba> {
        let p = self.params;
        (0..p.low_height)
            .flat_map(|y| (0..p.low_width).map(move |x| (x, y)))
            .map(|(x, y)| self.discontinuity(x, y))
            .collect()
    }

    /// The full-resolution pixel (x, y), or `None` where no surface was hit (the WGSL's
    /// `surface_pixel` returning NO_HIT; its E is written as zero there).
    pub fn surface_pixel(&self, x: u32, y: u32) -> Option<usize> {
        let pixel = (y * self.params.width + x) as usize;
        (self.gbuf_position[pixel][3] > 0.0).then_some(pixel)
    }

    /// The fused entry point at full-resolution pixel (x, y): for each of the four
    /// low-resolution pixels around it (bilinear weights), the n x m window around that
    /// one, each sample weighed by its continuity with (x, y) itself.
    pub fn fused(&self, x: u32, y: u32) -> Rgba {
        let Some(pixel) = self.surface_pixel(x, y) else {
            return [0.0, 0.0, 0.0, 1.0];
        };
        let p = self.params;
        let up = self.upsampler();
        let u = up.low_coordinate(x);
        let v = up.low_coordinate(y);
        let bx = u.floor() as i32;
        let by = v.floor() as i32;
        let fx = u - bx as f32;
        let fy = v - by as f32;
        let mut g = new_gathered();
        for cj in 0..=1 {
            for ci in 0..=1 {
                let bilinear =
                    if ci == 1 { fx } else { 1.0 - fx } * if cj == 1 { fy } else { 1.0 - fy };
                let x0 = bx + ci - (p.interleave_n / 2) as i32;
                let y0 = by + cj - (p.interleave_m / 2) as i32;
                for j in 0..p.interleave_m as i32 {
                    for i in 0..p.interleave_n as i32 {
                        let sx = x0 + i;
                        let sy = y0 + j;
                        if !up.inside_low(sx, sy) {
                            continue;
                        }
                        let q = representative_pixel(p, sx as u32, sy as u32);
                        let mut w = 0.0;
                        if self.continuous(pixel, q) {
                            let cos = xyz(self.gbuf_normal[pixel]).dot(xyz(self.gbuf_normal[q]));
                            w = bilinear * cos.max(0.0).powf(p.normal_power);
                        }
                        let dx = sx as f32 - u;
                        let dy = sy as f32 - v;
                        up.gather_sample(&mut g, sx, sy, w, dx * dx + dy * dy);
                    }
                }
            }
        }
        let e = gathered_value(g);
        [e.x, e.y, e.z, 1.0]
    }

    /// The fused pass over the whole image (width x height).
    pub fn fused_image(&self) -> Vec<Rgba> {
        let p = self.params;
        (0..p.height)
            .flat_map(|y| (0..p.width).map(move |x| (x, y)))
            .map(|(x, y)| self.fused(x, y))
            .collect()
    }
}

/// The n x m window around low-res pixel (x, y): offsets -(n/2) ..= (n-1)/2.
pub fn window_start(c: u32, size: u32) -> i32 {
    c as i32 - (size / 2) as i32
}
