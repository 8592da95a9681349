//! Indirect diffuse light at hits seen through mirrors (paper section 4; its cost is the
//! paper's future work): gathered from every VPL at the first diffuse hit of each
//! pixel's mirror chain, recorded by the direct pass. See `shaders/mirror.wgsl`.

use super::{bind, pass_layout, LanePipelines};
use crate::scene_buffers::{READ, UNIFORM, WRITE};

/// Lanes per pixel of the mirror pass: few pixels see a mirror (18000 of 480000 in the
/// conference room), so their VPL loops are split over 8 threads; one lane on a software
/// adapter. 8 beat 32 and 1 on the H200 at 800 x 600 and 1920 x 1080, canonical and
/// interleaved (docs/PERFORMANCE.md, attempt 17). `IGI_MIRROR_LANES` (1, 8 or 32)
/// overrides it, for measurements.
pub fn mirror_lanes(software: bool) -> u32 {
    if let Some(l) = std::env::var("IGI_MIRROR_LANES")
        .ok()
        .and_then(|v| v.parse::<u32>().ok())
    {
        if super::LANE_CHOICES.contains(&l) {
            return l;
        }
    }
    if software {
        1
    } else {
        8
    }
}

pub struct MirrorPass {
    pub layout: wgpu::BindGroupLayout,
    pipelines: LanePipelines,
}

impl MirrorPass {
    pub fn new(
        device: &wgpu::Device,
        scene_layout: &wgpu::BindGroupLayout,
        range_layout: &wgpu::BindGroupLayout,
    ) -> MirrorPass {
        // params, vpls, vpl_header, mirror position, normal, geometric, weight, direct
        let layout = pass_layout(
            device,
            "mirror",
            &[UNIFORM, READ, READ, READ, READ, READ, READ, WRITE],
        );
        MirrorPass {
            pipelines: LanePipelines::new(device, "mirror", &[scene_layout, &layout, range_layout]),
            layout,
        }
    }

    pub fn bind(&self, device: &wgpu::Device, buffers: &[&wgpu::Buffer; 8]) -> wgpu::BindGroup {
        bind(device, "mirror", &self.layout, buffers)
    }

    /// The dispatch over the full-resolution image.
    pub fn steps(
        &self,
        width: u32,
        height: u32,
        imperfect_visibility: bool,
        software: bool,
    ) -> [(&wgpu::ComputePipeline, [u32; 3]); 1] {
        [self
            .pipelines
            .step(width, height, imperfect_visibility, mirror_lanes(software))]
    }
}
