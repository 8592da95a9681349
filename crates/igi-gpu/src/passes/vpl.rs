//! VPL shooting (paper section 4, first stage): light paths from the point lights leave
//! VPLs at diffuse hits; a compaction step makes a dense list. See `shaders/vpl.wgsl`.

use super::{bind, pass_layout, pipeline};
use crate::scene_buffers::{READ, UNIFORM, WRITE};

/// Threads per workgroup of the shooting kernel (`SHOOT_GROUP` in the WGSL).
pub const SHOOT_GROUP: u32 = 64;
/// Largest number of workgroups in one dimension of a dispatch.
const MAX_GROUPS: u32 = 65535;

pub struct VplPass {
    pub layout: wgpu::BindGroupLayout,
    shoot: wgpu::ComputePipeline,
    compact: wgpu::ComputePipeline,
}

impl VplPass {
    pub fn new(device: &wgpu::Device, scene_layout: &wgpu::BindGroupLayout) -> VplPass {
        // params, vpl_slots, vpls, vpl_header, halton_perms
        let layout = pass_layout(device, "vpl", &[UNIFORM, WRITE, WRITE, WRITE, READ]);
        VplPass {
            shoot: pipeline(device, "vpl", "shoot", &[scene_layout, &layout]),
            compact: pipeline(device, "vpl", "compact", &[scene_layout, &layout]),
            layout,
        }
    }

    pub fn bind(
        &self,
        device: &wgpu::Device,
        params: &wgpu::Buffer,
        slots: &wgpu::Buffer,
        vpls: &wgpu::Buffer,
        header: &wgpu::Buffer,
        halton_perms: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        bind(
            device,
            "vpl",
            &self.layout,
            &[params, slots, vpls, header, halton_perms],
        )
    }

    /// The two dispatches of the stage for `paths` light paths: shoot, then compact.
    pub fn steps(&self, paths: u32) -> [(&wgpu::ComputePipeline, [u32; 3]); 2] {
        let groups = paths.div_ceil(SHOOT_GROUP).max(1);
        let x = groups.min(MAX_GROUPS);
        let y = groups.div_ceil(x);
        [(&self.shoot, [x, y, 1]), (&self.compact, [1, 1, 1])]
    }
}
