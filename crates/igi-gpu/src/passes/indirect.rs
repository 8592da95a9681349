//! Indirect diffuse light at the primary hits from all VPLs (paper section 4, third
//! stage), stored as the incident term E without the albedo. See `shaders/indirect.wgsl`.

use super::{bind, pass_layout, LanePipelines};
use crate::scene_buffers::{READ, UNIFORM, WRITE};

pub struct IndirectPass {
    pub layout: wgpu::BindGroupLayout,
    pipelines: LanePipelines,
}

impl IndirectPass {
    pub fn new(
        device: &wgpu::Device,
        scene_layout: &wgpu::BindGroupLayout,
        range_layout: &wgpu::BindGroupLayout,
    ) -> IndirectPass {
        // params, vpls, vpl_header, position, normal, geometric, irradiance
        let layout = pass_layout(
            device,
            "indirect",
            &[UNIFORM, READ, READ, READ, READ, READ, WRITE],
        );
        IndirectPass {
            pipelines: LanePipelines::new(
                device,
                "indirect",
                &[scene_layout, &layout, range_layout],
            ),
            layout,
        }
    }

    pub fn bind(&self, device: &wgpu::Device, buffers: &[&wgpu::Buffer; 7]) -> wgpu::BindGroup {
        bind(device, "indirect", &self.layout, buffers)
    }

    /// The dispatch over a `width` x `height` indirect term.
    pub fn steps(
        &self,
        width: u32,
        height: u32,
        imperfect_visibility: bool,
        vpls_per_pixel: u32,
        software: bool,
    ) -> [(&wgpu::ComputePipeline, [u32; 3]); 1] {
        [self.pipelines.step(
            width,
            height,
            imperfect_visibility,
            super::lanes_for(width * height, vpls_per_pixel, software),
        )]
    }
}
