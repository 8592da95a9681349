//! VPL shooting (paper section 4, first stage): light paths from the point lights leave
//! VPLs at diffuse hits; a compaction step makes a dense list (and, in scenes with
//! mirrors, sizes the dispatches over the direct pass's lists). See `shaders/vpl.wgsl`.

use super::{bind, pass_layout, pipeline, pipeline_with_constants};
use crate::scene_buffers::{READ, UNIFORM, WRITE};

/// Threads per workgroup of the shooting kernel (`SHOOT_GROUP` in the WGSL).
pub const SHOOT_GROUP: u32 = 64;
/// Largest number of workgroups in one dimension of a dispatch.
const MAX_GROUPS: u32 = 65535;

pub struct VplPass {
    pub layout: wgpu::BindGroupLayout,
    shoot: wgpu::ComputePipeline,
    compact: wgpu::ComputePipeline,
    /// Bind group 3 of `compact_and_size`: the direct pass's lists of mirrored pixels and
    /// of chains, and the workgroup counts of the dispatches over them.
    lists_layout: wgpu::BindGroupLayout,
    /// Compaction that also sizes those dispatches (`compact_and_size`).
    compact_and_size: wgpu::ComputePipeline,
}

impl VplPass {
    /// `mirror_list_pixels`: listed pixels per workgroup of the mirror gather
    /// (`indirect::list_pixels_per_group`); `range_layout`: bind group 2 of
    /// `compact_and_size` (unused, before its group 3).
    pub fn new(
        device: &wgpu::Device,
        scene_layout: &wgpu::BindGroupLayout,
        range_layout: &wgpu::BindGroupLayout,
        mirror_list_pixels: u32,
    ) -> VplPass {
        // params, vpl_slots, vpls, vpl_header, halton_perms
        let layout = pass_layout(device, "vpl", &[UNIFORM, WRITE, WRITE, WRITE, READ]);
        // mirror_list, mirror_args, chain_list, chain_args
        let lists_layout = pass_layout(device, "vpl lists", &[WRITE, WRITE, WRITE, WRITE]);
        VplPass {
            shoot: pipeline(device, "vpl", "shoot", &[scene_layout, &layout]),
            compact: pipeline(device, "vpl", "compact", &[scene_layout, &layout]),
            compact_and_size: pipeline_with_constants(
                device,
                "vpl",
                "compact_and_size",
                &[scene_layout, &layout, range_layout, &lists_layout],
                &[("MIRROR_LIST_PIXELS", mirror_list_pixels as f64)],
            ),
            lists_layout,
            layout,
        }
    }

    /// Bind group 3 of the compaction step that sizes the dispatches over the direct
    /// pass's lists: `[mirror_list, mirror_args, chain_list, chain_args]`.
    pub fn bind_lists(
        &self,
        device: &wgpu::Device,
        buffers: &[&wgpu::Buffer; 4],
    ) -> wgpu::BindGroup {
        bind(device, "vpl lists", &self.lists_layout, buffers)
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

    /// The two dispatches of the stage for `paths` light paths: shoot, then compact (and,
    /// with `size_lists`, size the dispatches over the direct pass's lists: bind group 3
    /// from [`Self::bind_lists`]).
    pub fn steps(&self, paths: u32, size_lists: bool) -> [(&wgpu::ComputePipeline, [u32; 3]); 2] {
        let groups = paths.div_ceil(SHOOT_GROUP).max(1);
        let x = groups.min(MAX_GROUPS);
        let y = groups.div_ceil(x);
        let compact = if size_lists {
            &self.compact_and_size
        } else {
            &self.compact
        };
        [(&self.shoot, [x, y, 1]), (compact, [1, 1, 1])]
    }
}
