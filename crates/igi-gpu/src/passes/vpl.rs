//! VPL shooting (paper section 4, first stage): light paths from the point lights leave
//! VPLs at diffuse hits, compacted into a dense list. See `shaders/vpl.wgsl`.

use super::{bind, pass_layout, pipeline, Step};
use crate::scene_buffers::{READ, UNIFORM, WRITE};

/// Threads per workgroup of the shooting kernel (`SHOOT_GROUP` in the WGSL).
pub const SHOOT_GROUP: u32 = 64;
/// The most paths that one workgroup shoots and compacts (`COMPACT_GROUP` in the WGSL).
pub const COMPACT_GROUP: u32 = 256;
/// Largest number of workgroups in one dimension of a dispatch.
const MAX_GROUPS: u32 = 65535;

pub struct VplPass {
    pub layout: wgpu::BindGroupLayout,
    shoot: wgpu::ComputePipeline,
    compact: wgpu::ComputePipeline,
    /// Shooting and compaction in one workgroup (`shoot_and_compact`).
    shoot_and_compact: wgpu::ComputePipeline,
}

/// The dispatches that make the VPL list: `shoot`, then `compact` where it is a dispatch
/// of its own (more paths than one workgroup holds), after a barrier.
pub struct VplSteps<'a> {
    pub shoot: Step<'a>,
    pub compact: Option<Step<'a>>,
}

impl VplPass {
    pub fn new(device: &wgpu::Device, scene_layout: &wgpu::BindGroupLayout) -> VplPass {
        // params, vpl_slots, vpls, vpl_header, halton_perms
        let layout = pass_layout(device, "vpl", &[UNIFORM, WRITE, WRITE, WRITE, READ]);
        let layouts = [scene_layout, &layout];
        VplPass {
            shoot: pipeline(device, "vpl", "shoot", &layouts),
            compact: pipeline(device, "vpl", "compact", &layouts),
            shoot_and_compact: pipeline(device, "vpl", "shoot_and_compact", &layouts),
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

    /// The dispatches for `paths` light paths: one workgroup that shoots and compacts for
    /// up to [`COMPACT_GROUP`] paths, else shooting over as many workgroups as needed and
    /// the compaction after it.
    pub fn steps(&self, paths: u32) -> VplSteps<'_> {
        if paths <= COMPACT_GROUP {
            return VplSteps {
                shoot: (&self.shoot_and_compact, [1, 1, 1]),
                compact: None,
            };
        }
        let groups = paths.div_ceil(SHOOT_GROUP);
        let x = groups.min(MAX_GROUPS);
        let y = groups.div_ceil(x);
        VplSteps {
            shoot: (&self.shoot, [x, y, 1]),
            compact: Some((&self.compact, [1, 1, 1])),
        }
    }
}
