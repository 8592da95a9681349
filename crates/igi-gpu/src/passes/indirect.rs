//! Indirect diffuse light from the VPLs (paper section 4, third stage), stored as the
//! incident term E without the albedo, at the records of a G-buffer: the primary hits
//! (at the indirect term's resolution), and, with a second set of parameters at full
//! resolution, the first diffuse hits seen through mirrors (the "mirror indirect" stage;
//! the paper gathers every VPL there and leaves that cost as future work).
//! See `shaders/indirect.wgsl`.

use super::{bind, pass_layout, GatherPipelines, LanePipelines, Step};
use crate::scene_buffers::{READ, UNIFORM, WRITE};

/// Threads of a workgroup of the gather over the list of mirrored pixels (indirect.wgsl
/// `LIST_GROUP`) with `lanes` lanes per pixel: 256, or 32 per lane where that is more, so
/// that a warp always holds one lane of 32 pixels.
pub fn list_group(lanes: u32) -> u32 {
    256.max(32 * lanes)
}

/// Listed pixels per workgroup of that gather.
pub fn list_pixels_per_group(lanes: u32) -> u32 {
    list_group(lanes) / lanes
}

/// The most workgroups of the gather over the list of mirrored pixels, over all its
/// buckets: they stride over the list, whose length is known only on the GPU (a dispatch
/// sized there cost the frame more than a fixed grid, docs/PERFORMANCE.md attempt 75).
/// Grids of 256 to 4096 took the same time within 0.005 ms on the H200 (conference room,
/// 800 x 600 and 1920 x 1080, interleaved or not); 1024 was never more than that from the
/// best.
pub const LIST_WORKGROUPS: u32 = 1024;

pub struct IndirectPass {
    pub layout: wgpu::BindGroupLayout,
    pipelines: LanePipelines,
    /// Bind group 3 of the gather over the list of mirrored pixels: the list
    /// (direct.wgsl's mirror_list), read-only.
    list_layout: wgpu::BindGroupLayout,
    /// The gather over the listed pixels (`main_list`).
    list: GatherPipelines,
    /// Listed pixels per workgroup of `main_list`.
    list_pixels: u32,
}

impl IndirectPass {
    /// `list_lanes`: lanes per pixel of the gather over the list of mirrored pixels
    /// ([`super::mirror_lanes`]).
    pub fn new(
        device: &wgpu::Device,
        scene_layout: &wgpu::BindGroupLayout,
        range_layout: &wgpu::BindGroupLayout,
        list_lanes: u32,
    ) -> IndirectPass {
        // params, vpls, vpl_header, position, normal, geometric, irradiance
        let layout = pass_layout(
            device,
            "indirect",
            &[UNIFORM, READ, READ, READ, READ, READ, WRITE],
        );
        let list_layout = pass_layout(device, "mirror list", &[READ]);
        let layouts = [scene_layout, &layout, range_layout, &list_layout];
        let constants = [
            ("VPL_LANES", list_lanes as f64),
            ("LIST_GROUP", list_group(list_lanes) as f64),
        ];
        IndirectPass {
            pipelines: LanePipelines::new(
                device,
                "indirect",
                &[scene_layout, &layout, range_layout],
            ),
            list: GatherPipelines::new(device, "indirect", "main_list", &layouts, &constants),
            list_pixels: list_pixels_per_group(list_lanes),
            list_layout,
            layout,
        }
    }

    /// Bind group 3 of the list gather (the list).
    pub fn bind_list(&self, device: &wgpu::Device, list: &wgpu::Buffer) -> wgpu::BindGroup {
        bind(device, "mirror list", &self.list_layout, &[list])
    }

    /// The gather over the listed pixels of a `width` x `height` image interleaved in
    /// `subsets` subsets (one bucket each, a z layer each): a fixed grid per bucket, no
    /// larger than the fullest bucket could need, about `most_groups` in all at most
    /// (at least one per bucket).
    pub fn list_steps(
        &self,
        width: u32,
        height: u32,
        interleave: (u32, u32),
        imperfect_visibility: bool,
        most_groups: u32,
    ) -> [Step<'_>; 1] {
        let (n, m) = interleave;
        let subsets = n * m;
        let bucket = width.div_ceil(n) as u64 * height.div_ceil(m) as u64;
        let most = bucket.div_ceil(self.list_pixels as u64);
        let groups = most.clamp(1, most_groups.div_ceil(subsets).max(1) as u64) as u32;
        [(self.list.get(imperfect_visibility), [groups, 1, subsets])]
    }

    pub fn bind(&self, device: &wgpu::Device, buffers: &[&wgpu::Buffer; 7]) -> wgpu::BindGroup {
        bind(device, "indirect", &self.layout, buffers)
    }

    /// The dispatch over a `width` x `height` record interleaved in tiles of
    /// `interleave` pixels, each pixel's VPLs split over `lanes` threads (see
    /// [`super::lanes_for`]).
    pub fn steps(
        &self,
        width: u32,
        height: u32,
        imperfect_visibility: bool,
        lanes: u32,
        interleave: (u32, u32),
    ) -> [Step<'_>; 1] {
        [self
            .pipelines
            .step(width, height, imperfect_visibility, lanes, interleave)]
    }
}
