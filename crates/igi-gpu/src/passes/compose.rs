//! Compose (paper section 4, last stage): L = direct + (rho / pi) E, linear radiance,
//! with E at full resolution or upsampled on the way (joint bilateral upsampling, paper
//! section 4.2). See `shaders/compose.wgsl`.

use super::{bind, image_groups, pass_layout, pipeline, Step};
use crate::scene_buffers::{READ, UNIFORM, WRITE};

pub struct ComposePass {
    pub layout: wgpu::BindGroupLayout,
    /// E read at full resolution (`main`).
    pipeline: wgpu::ComputePipeline,
    /// E upsampled from the indirect term's resolution (`main_upsampled`).
    upsampled: wgpu::ComputePipeline,
}

impl ComposePass {
    pub fn new(device: &wgpu::Device, scene_layout: &wgpu::BindGroupLayout) -> ComposePass {
        // params, direct, albedo, irradiance, color, G-buffer position and normal, the
        // mirrored hits' weight and E
        let layout = pass_layout(
            device,
            "compose",
            &[UNIFORM, READ, READ, READ, WRITE, READ, READ, READ, READ],
        );
        let layouts = [scene_layout, &layout];
        ComposePass {
            pipeline: pipeline(device, "compose", "main", &layouts),
            upsampled: pipeline(device, "compose", "main_upsampled", &layouts),
            layout,
        }
    }

    pub fn bind(&self, device: &wgpu::Device, buffers: &[&wgpu::Buffer; 9]) -> wgpu::BindGroup {
        bind(device, "compose", &self.layout, buffers)
    }

    /// The dispatch over a `width` x `height` image; with `upsample`, the E buffer bound
    /// is at the indirect term's resolution and is upsampled pixel by pixel.
    pub fn steps(&self, width: u32, height: u32, upsample: bool) -> [Step<'_>; 1] {
        let pipeline = if upsample {
            &self.upsampled
        } else {
            &self.pipeline
        };
        [(pipeline, image_groups(width, height))]
    }
}
