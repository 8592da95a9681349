//! Indirect diffuse light from the VPLs (paper section 4, third stage), stored as the
//! incident term E without the albedo, at the records of a G-buffer: the primary hits
//! (at the indirect term's resolution), and, with a second set of parameters at full
//! resolution, the first diffuse hits seen through mirrors (the "mirror indirect" stage;
//! the paper gathers every VPL there and leaves that cost as future work).
//! See `indirect.wgsl`.

pub mod cpu;

use super::bindings::{bind, compute_layout};
use super::{GatherPipelines, LanePipelines, Step, SurfaceMaps};
use crate::frame::recorder::FramePass;
use crate::frame::resources::{Buf, FrameBuffers};
use crate::frame::FrameShape;
use crate::switches::Switches;

crate::bindings! {
    /// Bind group 1 of indirect.wgsl: a G-buffer record to gather at and where E goes.
    pub struct IndirectBindings {
        params: Params,
        vpls: Read,
        vpl_header: Read,
        gbuf_position: Read,
        gbuf_normal: Read,
        gbuf_geometric: Read,
        irradiance_out: Write,
    }
}

crate::bindings! {
    /// Bind group 3 of the gather over the mirrored pixels: direct.wgsl's list of them.
    pub struct MirrorListBindings {
        mirror_list: Read,
    }
}

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
/// sized there cost the frame more than a fixed grid). Grids of 256 to 4096 workgroups
/// measured alike on the H200; 1024 was never far from the best.
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
        switches: &Switches,
        scene_layout: &wgpu::BindGroupLayout,
        range_layout: &wgpu::BindGroupLayout,
        list_lanes: u32,
        maps: SurfaceMaps,
    ) -> IndirectPass {
        let layout = compute_layout::<IndirectBindings>(device, "indirect");
        let list_layout = compute_layout::<MirrorListBindings>(device, "mirror list");
        let layouts = [scene_layout, &layout, range_layout, &list_layout];
        let constants = [
            ("VPL_LANES", list_lanes as f64),
            ("LIST_GROUP", list_group(list_lanes) as f64),
        ];
        IndirectPass {
            pipelines: LanePipelines::new(
                device,
                switches,
                "indirect",
                &[scene_layout, &layout, range_layout],
                maps,
            ),
            list: GatherPipelines::new(
                device,
                switches,
                "indirect",
                "main_list",
                &layouts,
                &constants,
                maps,
            ),
            list_pixels: list_pixels_per_group(list_lanes),
            list_layout,
            layout,
        }
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

    /// E at the primary hits, at the indirect term's resolution, each pixel's VPLs split
    /// over the frame's lanes, interleaved in its tiles.
    pub(crate) fn record_primary<'a>(
        &'a self,
        device: &wgpu::Device,
        buffers: &'a FrameBuffers,
        shape: &FrameShape<'a>,
    ) -> FramePass<'a> {
        let (low, iv) = (shape.low, shape.imperfect_visibility);
        let b = |buf| buffers.get(buf);
        let bindings = IndirectBindings {
            params: b(Buf::Params),
            vpls: b(Buf::Vpls),
            vpl_header: b(Buf::VplHeader),
            gbuf_position: b(Buf::GbufPosition),
            gbuf_normal: b(Buf::GbufNormal),
            gbuf_geometric: b(Buf::GbufGeometric),
            irradiance_out: b(Buf::Irradiance),
        };
        FramePass::new(
            "indirect",
            self.steps(low.0, low.1, iv, shape.lanes, shape.interleave)
                .to_vec(),
            bind(device, "indirect", &self.layout, &bindings),
        )
        .over(shape.ranges)
    }

    /// E at the first diffuse hits seen through mirrors (full resolution, the mirror
    /// parameters), only at the pixels the direct pass listed.
    pub(crate) fn record_mirrored<'a>(
        &'a self,
        device: &wgpu::Device,
        buffers: &'a FrameBuffers,
        shape: &FrameShape<'a>,
    ) -> FramePass<'a> {
        let (full, iv) = (shape.full, shape.imperfect_visibility);
        let b = |buf| buffers.get(buf);
        let bindings = IndirectBindings {
            params: b(Buf::MirrorParams),
            vpls: b(Buf::Vpls),
            vpl_header: b(Buf::VplHeader),
            gbuf_position: b(Buf::MirrorPosition),
            gbuf_normal: b(Buf::MirrorNormal),
            gbuf_geometric: b(Buf::MirrorGeometric),
            irradiance_out: b(Buf::MirrorIrradiance),
        };
        let list = MirrorListBindings {
            mirror_list: b(Buf::MirrorList),
        };
        FramePass::new(
            "mirror indirect",
            self.list_steps(full.0, full.1, shape.interleave, iv, shape.list_grids.0)
                .to_vec(),
            bind(device, "indirect", &self.layout, &bindings),
        )
        .over(shape.ranges)
        .with_group3(bind(device, "mirror list", &self.list_layout, &list))
    }
}
