//! Direct + specular at full resolution (paper section 4, second stage), writing the
//! G-buffer of the primary hits. See `shaders/direct.wgsl`.

use super::{bind, pass_layout, GatherPipelines, Step};
use crate::scene_buffers::{READ, UNIFORM, WRITE};

/// Pixels per workgroup of the direct pass (`@workgroup_size` of direct.wgsl): one warp,
/// 8 x 4, measured faster than 8 x 8, 16 x 8, 16 x 16, 16 x 2 and 32 x 1 on the H200
/// (docs/PERFORMANCE.md, attempt 32).
pub const DIRECT_TILE: (u32, u32) = (8, 4);

/// Listed chains per workgroup of the later walks (`CHAIN_GROUP` in frame.wgsl).
pub const CHAIN_GROUP: u32 = 32;

/// The most workgroups of the later walks, which stride over the list of chains: its
/// length is known only on the GPU, and a dispatch sized there (by the first walk, or by
/// a dispatch after it) cost the frame more than a fixed grid (docs/PERFORMANCE.md
/// attempt 75). 2048 x 32 threads; a grid over every pixel, most of them skipped, took
/// 0.018 ms of the H200 in a scene without chains (attempt 50).
pub const CHAIN_WORKGROUPS: u32 = 2048;

pub struct DirectPass {
    pub layout: wgpu::BindGroupLayout,
    /// The first walk over every pixel (`main`).
    pipelines: GatherPipelines,
    /// The later walks over the listed chains (`chains_main`, dispatched indirectly).
    chains: GatherPipelines,
}

/// The buffers the direct pass reads and writes, in binding order after the parameters.
pub struct DirectBindings<'a> {
    pub vpls: &'a wgpu::Buffer,
    pub vpl_header: &'a wgpu::Buffer,
    pub direct: &'a wgpu::Buffer,
    pub position: &'a wgpu::Buffer,
    pub normal: &'a wgpu::Buffer,
    pub geometric: &'a wgpu::Buffer,
    pub albedo: &'a wgpu::Buffer,
    /// The mirrored-hit record (gathered at by the mirror indirect stage, frame.rs).
    pub mirror: [&'a wgpu::Buffer; 4],
    /// The list of pixels with a mirrored hit.
    pub mirror_list: &'a wgpu::Buffer,
    /// The list of pixels whose chain the later walks follow.
    pub chain_list: &'a wgpu::Buffer,
}

impl DirectPass {
    pub fn new(
        device: &wgpu::Device,
        scene_layout: &wgpu::BindGroupLayout,
        range_layout: &wgpu::BindGroupLayout,
    ) -> DirectPass {
        let layout = pass_layout(
            device,
            "direct",
            &[
                UNIFORM, READ, READ, WRITE, WRITE, WRITE, WRITE, WRITE, WRITE, WRITE, WRITE, WRITE,
                WRITE, WRITE,
            ],
        );
        let layouts = [scene_layout, &layout, range_layout];
        DirectPass {
            pipelines: GatherPipelines::new(device, "direct", "main", &layouts, &[]),
            chains: GatherPipelines::new(device, "direct", "chains_main", &layouts, &[]),
            layout,
        }
    }

    /// The later walks over the listed chains of a `width` x `height` image: a fixed
    /// grid, no larger than the longest list could need and `most_groups` at most, that
    /// strides over the list.
    pub fn chains_steps(
        &self,
        width: u32,
        height: u32,
        imperfect_visibility: bool,
        most_groups: u32,
    ) -> [Step<'_>; 1] {
        let most = (width as u64 * height as u64).div_ceil(CHAIN_GROUP as u64);
        let groups = most.clamp(1, most_groups.max(1) as u64) as u32;
        [(self.chains.get(imperfect_visibility), [groups, 1, 1])]
    }

    pub fn bind(
        &self,
        device: &wgpu::Device,
        params: &wgpu::Buffer,
        b: DirectBindings,
    ) -> wgpu::BindGroup {
        bind(
            device,
            "direct",
            &self.layout,
            &[
                params,
                b.vpls,
                b.vpl_header,
                b.direct,
                b.position,
                b.normal,
                b.geometric,
                b.albedo,
                b.mirror[0],
                b.mirror[1],
                b.mirror[2],
                b.mirror[3],
                b.mirror_list,
                b.chain_list,
            ],
        )
    }

    /// The first walk, over every pixel.
    pub fn steps(&self, width: u32, height: u32, imperfect_visibility: bool) -> [Step<'_>; 1] {
        [(
            self.pipelines.get(imperfect_visibility),
            [
                width.div_ceil(DIRECT_TILE.0),
                height.div_ceil(DIRECT_TILE.1),
                1,
            ],
        )]
    }
}
