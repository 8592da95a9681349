//! The filters of the accelerated indirect term (paper sections 4.2 and 4.3): the
//! discontinuity buffer, and it fused with upsampling in one pass (the paper's future
//! work). Joint bilateral upsampling on its own is done by the compose pass as it writes
//! each pixel. See `shaders/filter.wgsl`.

use super::{bind, image_groups, pass_layout, pipeline, Step};
use crate::scene_buffers::{READ, UNIFORM, WRITE};

pub struct FilterPass {
    pub layout: wgpu::BindGroupLayout,
    discontinuity: wgpu::ComputePipeline,
    fused: wgpu::ComputePipeline,
}

/// Which filter a step runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Filter {
    Discontinuity,
    Fused,
}

impl Filter {
    pub fn stage_name(self) -> &'static str {
        match self {
            Filter::Discontinuity => "discontinuity",
            Filter::Fused => "fused filter",
        }
    }
}

impl FilterPass {
    pub fn new(device: &wgpu::Device, scene_layout: &wgpu::BindGroupLayout) -> FilterPass {
        // params, position, normal, filter_in, filter_out
        let layout = pass_layout(device, "filter", &[UNIFORM, READ, READ, READ, WRITE]);
        let layouts = [scene_layout, &layout];
        FilterPass {
            discontinuity: pipeline(device, "filter", "discontinuity", &layouts),
            fused: pipeline(device, "filter", "fused", &layouts),
            layout,
        }
    }

    pub fn bind(&self, device: &wgpu::Device, buffers: &[&wgpu::Buffer; 5]) -> wgpu::BindGroup {
        bind(device, "filter", &self.layout, buffers)
    }

    /// The dispatch of `filter`: the discontinuity buffer runs at the indirect term's
    /// resolution, the fused filter at full resolution.
    pub fn steps(&self, filter: Filter, full: (u32, u32), low: (u32, u32)) -> [Step<'_>; 1] {
        match filter {
            Filter::Discontinuity => [(&self.discontinuity, image_groups(low.0, low.1))],
            Filter::Fused => [(&self.fused, image_groups(full.0, full.1))],
        }
    }
}
