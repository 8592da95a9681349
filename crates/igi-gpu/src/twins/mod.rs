//! CPU twins of the passes that compute pixels from the G-buffer: each file mirrors one
//! WGSL file function by function, with the WGSL's names, so that a test can run the
//! twin on the GPU's own inputs (read back with `Renderer::read_frame_buffer`) and compare
//! its output with the GPU's. Plain slices in, plain vectors out: no wgpu here.
//!
//! - [`filter`]: `shaders/filter.wgsl` (discontinuity buffer, fused filter).
//! - [`upsample`]: `shaders/upsample.wgsl` (joint bilateral upsampling).
//! - [`compose`]: `shaders/compose.wgsl` (the final image and the inspection buffers).
//! - [`gather`]: `shaders/gather.wgsl` with `shaders/indirect.wgsl` (E from the VPLs).
//!
//! The VPL pass's twin is `igi_core::vpl`, the traversal's `igi_core::bvh`.
//!
//! The twins compose as their WGSL does: the fused filter and compose's upsampling share
//! [`upsample`]'s gatherer, and this module holds the one helper of `shaders/frame.wgsl`
//! that several of them use ([`representative_pixel`]).

pub mod compose;
pub mod filter;
pub mod gather;
pub mod upsample;

use crate::layout::FrameParams;

/// One RGBA record of a per-pixel buffer, as the passes store them (`vec4<f32>`).
pub type Rgba = [f32; 4];

/// `representative_pixel` of frame.wgsl: the full-resolution pixel whose G-buffer sample
/// stands for low-resolution pixel (x, y) of the indirect term, the centre of its
/// downsample x downsample block (clamped to the image at its right and bottom edges).
pub fn representative_pixel(params: &FrameParams, x: u32, y: u32) -> usize {
    let half = params.downsample / 2;
    let fx = (x * params.downsample + half).min(params.width - 1);
    let fy = (y * params.downsample + half).min(params.height - 1);
    (fy * params.width + fx) as usize
}
