//! Indirect diffuse light from the VPLs (paper section 4, third stage), stored as the
//! incident term E without the albedo, at the records of a G-buffer: the primary hits
//! (at the indirect term's resolution), and, with a second set of parameters at full
//! resolution, the first diffuse hits seen through mirrors (the "mirror indirect" stage;
//! the paper gathers every VPL there and leaves that cost as future work).
//! See `shaders/indirect.wgsl`.

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

    /// The dispatch over a `width` x `height` record, each pixel's VPLs split over
    /// `lanes` threads (see [`super::lanes_for`] and [`super::mirror_lanes`]).
    pub fn steps(
        &self,
        width: u32,
        height: u32,
        imperfect_visibility: bool,
        lanes: u32,
    ) -> [(&wgpu::ComputePipeline, [u32; 3]); 1] {
        [self
            .pipelines
            .step(width, height, imperfect_visibility, lanes)]
    }
}
