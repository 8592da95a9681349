//! CPU twin of `compose.wgsl`: the final image L = direct_specular +
//! (rho_d / pi) E, the mirrored hits' indirect light, the inspection buffers
//! (`params.output`) and the running mean of accumulation. Function by function as the
//! WGSL, with its names; its bindings are the fields of [`Compose`]. Entry point `main`
//! reads E at full resolution, `main_upsampled` upsamples it through
//! [`crate::shaders::upsample`], as compose.wgsl through upsample.wgsl.

use crate::layout::FrameParams;
use crate::shaders::gbuffer::Rgba;
use crate::shaders::upsample::{xyz, Upsampler};
use glam::Vec3;

/// PI of constants.wgsl (3.14159265358979 there, the same f32).
pub const PI: f32 = std::f32::consts::PI;

/// compose.wgsl's bindings but the colour buffer, which the entry points take as
/// `color_out` (read for accumulation, then written).
pub struct Compose<'a> {
    pub params: &'a FrameParams,
    /// Direct + specular radiance (the direct pass).
    pub direct_in: &'a [Rgba],
    pub gbuf_albedo: &'a [Rgba],
    /// E at full resolution (`main`) or at the indirect term's (`main_upsampled`).
    pub irradiance_in: &'a [Rgba],
    pub gbuf_position: &'a [Rgba],
    pub gbuf_normal: &'a [Rgba],
    /// Weight of the pixel's mirrored hit (w = 1 where there is one), and E there.
    pub mirror_weight: &'a [Rgba],
    pub mirror_irradiance: &'a [Rgba],
}

impl Compose<'_> {
    /// The upsampler over `irradiance_in` (the WGSL's `low_irradiance` of this pass).
    fn upsampler(&self) -> Upsampler<'_> {
        Upsampler {
            params: self.params,
            gbuf_normal: self.gbuf_normal,
            low_irradiance: self.irradiance_in,
        }
    }

    /// Entry point `main` over the whole image: E read at each pixel.
    pub fn main(&self, color_out: &mut [Rgba]) {
        let p = self.params;
        for y in 0..p.height {
            for x in 0..p.width {
                let pixel = (y * p.width + x) as usize;
                self.compose_pixel(pixel, xyz(self.irradiance_in[pixel]), color_out);
            }
        }
    }

    /// Entry point `main_upsampled` over the whole image: E upsampled from the indirect
    /// term's resolution where a surface was hit, 0 elsewhere.
    pub fn main_upsampled(&self, color_out: &mut [Rgba]) {
        let p = self.params;
        let up = self.upsampler();
        for y in 0..p.height {
            for x in 0..p.width {
                let pixel = (y * p.width + x) as usize;
                let mut e = Vec3::ZERO;
                if self.gbuf_position[pixel][3] > 0.0 {
                    e = up.upsampled_irradiance(x, y, pixel);
                }
                self.compose_pixel(pixel, e, color_out);
            }
        }
    }

    /// Writes pixel `pixel` of the chosen output, E there being `e`.
    pub fn compose_pixel(&self, pixel: usize, e: Vec3, color_out: &mut [Rgba]) {
        let p = self.params;
        let mut direct = xyz(self.direct_in[pixel]);
        let mirrored = self.mirror_weight[pixel];
        if mirrored[3] > 0.0 {
            direct += xyz(mirrored) * xyz(self.mirror_irradiance[pixel]);
        }
        let indirect = xyz(self.gbuf_albedo[pixel]) / PI * e;
        let mut c = direct + indirect;
        // position.w > 0 where the primary ray hit a surface.
        let hit = self.gbuf_position[pixel][3] > 0.0;
        match p.output {
            1 => c = direct,
            2 => c = indirect,
            3 => c = e,
            4 => {
                c = if hit {
                    0.5 + 0.5 * xyz(self.gbuf_normal[pixel])
                } else {
                    Vec3::ZERO
                }
            }
            5 => {
                let d =
                    xyz(self.gbuf_position[pixel]).distance(Vec3::from(p.cam_eye)) * p.depth_scale;
                c = if hit { Vec3::splat(d) } else { Vec3::ZERO };
            }
            _ => {}
        }
        // Accumulation: a running mean over frames with fresh VPL sets.
        let k = p.accumulate_index as f32;
        if k > 0.0 {
            c = (xyz(color_out[pixel]) * k + c) / (k + 1.0);
        }
        color_out[pixel] = [c.x, c.y, c.z, 1.0];
    }
}
