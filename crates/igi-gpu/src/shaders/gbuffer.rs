//! CPU twin of `gbuffer.wgsl`'s helper that several twins use ([`representative_pixel`]),
//! and the record type of the per-pixel buffers.

use crate::layout::FrameParams;

/// One RGBA record of a per-pixel buffer, as the passes store them (`vec4<f32>`).
pub type Rgba = [f32; 4];

/// `representative_pixel` of gbuffer.wgsl: the full-resolution pixel whose G-buffer sample
/// stands for low-resolution pixel (x, y) of the indirect term, the centre of its
/// downsample x downsample block (clamped to the image at its right and bottom edges).
pub fn representative_pixel(params: &FrameParams, x: u32, y: u32) -> usize {
    let half = params.downsample / 2;
    let fx = (x * params.downsample + half).min(params.width - 1);
    let fy = (y * params.downsample + half).min(params.height - 1);
    (fy * params.width + fx) as usize
}
