//! Compose (paper section 4, last stage): L = direct + (rho / pi) E, linear radiance.
//! See `shaders/compose.wgsl`.

use super::{bind, image_groups, pass_layout, pipeline};
use crate::scene_buffers::{READ, UNIFORM, WRITE};

pub struct ComposePass {
    pub layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
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
        ComposePass {
            pipeline: pipeline(device, "compose", "main", &[scene_layout, &layout]),
            layout,
        }
    }

    pub fn bind(&self, device: &wgpu::Device, buffers: &[&wgpu::Buffer; 9]) -> wgpu::BindGroup {
        bind(device, "compose", &self.layout, buffers)
    }

    pub fn steps(&self, width: u32, height: u32) -> [(&wgpu::ComputePipeline, [u32; 3]); 1] {
        [(&self.pipeline, image_groups(width, height))]
    }
}
