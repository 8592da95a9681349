//! Direct + specular at full resolution (paper section 4, second stage), writing the
//! G-buffer of the primary hits, the record of the first diffuse hits seen through
//! mirrors and the lists of the pixels that see one. Its later walks gather the VPLs at
//! hits seen in a mirror seen in a mirror. See `direct.wgsl`.

use super::bindings::{bind, compute_layout};
use super::{GatherPipelines, Step, SurfaceMaps};
use crate::frame::recorder::FramePass;
use crate::frame::resources::{Buf, FrameBuffers};
use crate::frame::FrameShape;
use crate::switches::Switches;

/// Pixels per workgroup of the direct pass (`@workgroup_size` of direct.wgsl): one warp,
/// 8 x 4, which measured faster on the H200 than square or wider tiles.
pub const DIRECT_TILE: (u32, u32) = (8, 4);

/// Listed chains per workgroup of the later walks (`CHAIN_GROUP` in the WGSL).
pub const CHAIN_GROUP: u32 = 32;

/// The most workgroups of the later walks, which stride over the list of chains: its
/// length is known only on the GPU, and a dispatch sized there (by the first walk, or by
/// a dispatch after it) cost the frame more than a fixed grid; a grid over every pixel,
/// most of them skipped, cost a scene without chains a little too.
pub const CHAIN_WORKGROUPS: u32 = 2048;

crate::bindings! {
    /// Bind group 1 of direct.wgsl.
    pub struct DirectBindings {
        params: Params,
        /// The VPLs, gathered by the later walks (the first walk binds an empty list).
        vpls: Read,
        vpl_header: Read,
        direct_out: Write,
        gbuf_position: Write,
        gbuf_normal: Write,
        gbuf_geometric: Write,
        gbuf_albedo: Write,
        /// The mirrored-hit record, gathered at by the mirror indirect stage.
        mirror_position: Write,
        mirror_normal: Write,
        mirror_geometric: Write,
        mirror_weight: Write,
        /// The list of pixels with a mirrored hit.
        mirror_list: Write,
        /// The list of pixels whose chain the later walks follow.
        chain_list: Write,
    }
}

pub struct DirectPass {
    pub layout: wgpu::BindGroupLayout,
    /// The first walk over every pixel (`main`).
    pipelines: GatherPipelines,
    /// The later walks over the listed chains (`chains_main`, a fixed grid striding over
    /// the list).
    chains: GatherPipelines,
}

impl DirectPass {
    pub fn new(
        device: &wgpu::Device,
        switches: &Switches,
        scene_layout: &wgpu::BindGroupLayout,
        range_layout: &wgpu::BindGroupLayout,
        maps: SurfaceMaps,
    ) -> DirectPass {
        let layout = compute_layout::<DirectBindings>(device, "direct");
        let layouts = [scene_layout, &layout, range_layout];
        DirectPass {
            pipelines: GatherPipelines::new(
                device,
                switches,
                "direct",
                "main",
                &layouts,
                &[],
                maps,
            ),
            chains: GatherPipelines::new(
                device,
                switches,
                "direct",
                "chains_main",
                &layouts,
                &[],
                maps,
            ),
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

    /// The first walk over every pixel of a `width` x `height` image: primary hits,
    /// direct light and mirror reflections, the G-buffer, the mirror record and its
    /// lists. It gathers no VPLs (an empty list is bound, and its range entry says so),
    /// so it runs beside VPL shooting.
    pub(crate) fn record_first_walk<'a>(
        &'a self,
        device: &wgpu::Device,
        buffers: &'a FrameBuffers,
        shape: &FrameShape<'a>,
    ) -> FramePass<'a> {
        let ((width, height), iv) = (shape.full, shape.imperfect_visibility);
        let b = |buf| buffers.get(buf);
        let bindings = DirectBindings {
            params: b(Buf::Params),
            vpls: b(Buf::NoVpls),
            vpl_header: b(Buf::NoVplHeader),
            direct_out: b(Buf::Direct),
            gbuf_position: b(Buf::GbufPosition),
            gbuf_normal: b(Buf::GbufNormal),
            gbuf_geometric: b(Buf::GbufGeometric),
            gbuf_albedo: b(Buf::GbufAlbedo),
            mirror_position: b(Buf::MirrorPosition),
            mirror_normal: b(Buf::MirrorNormal),
            mirror_geometric: b(Buf::MirrorGeometric),
            mirror_weight: b(Buf::MirrorWeight),
            mirror_list: b(Buf::MirrorList),
            chain_list: b(Buf::ChainList),
        };
        FramePass::new(
            "direct",
            self.steps(width, height, iv).to_vec(),
            bind(device, "direct", &self.layout, &bindings),
        )
        .over(shape.first_walk)
    }

    /// The later walks over the chains the first walk listed: the VPL light at hits seen
    /// in a mirror seen in a mirror, added to the direct radiance. Only that is written;
    /// the first walk's other outputs are bound to scratch buffers, so that the walks
    /// share nothing with the gathers beside them.
    pub(crate) fn record_chain_walks<'a>(
        &'a self,
        device: &wgpu::Device,
        buffers: &'a FrameBuffers,
        shape: &FrameShape<'a>,
    ) -> FramePass<'a> {
        let ((width, height), iv) = (shape.full, shape.imperfect_visibility);
        let b = |buf| buffers.get(buf);
        let [s0, s1, s2, s3, s4, s5, s6, s7, s8] = buffers.copies(Buf::ChainScratch) else {
            unreachable!("the scratch buffers are declared with one copy per binding")
        };
        let bindings = DirectBindings {
            params: b(Buf::Params),
            vpls: b(Buf::Vpls),
            vpl_header: b(Buf::VplHeader),
            direct_out: b(Buf::Direct),
            gbuf_position: s0,
            gbuf_normal: s1,
            gbuf_geometric: s2,
            gbuf_albedo: s3,
            mirror_position: s4,
            mirror_normal: s5,
            mirror_geometric: s6,
            mirror_weight: s7,
            mirror_list: s8,
            chain_list: b(Buf::ChainList),
        };
        FramePass::new(
            "mirror chains",
            self.chains_steps(width, height, iv, shape.list_grids.1)
                .to_vec(),
            bind(device, "direct", &self.layout, &bindings),
        )
        .over(shape.ranges)
    }
}

#[cfg(test)]
mod tests {
    /// igi-core's largest image side is what the direct pass's tiles can dispatch.
    #[test]
    fn the_largest_image_side_fits_the_dispatch_limit() {
        let tile = super::DIRECT_TILE.0.min(super::DIRECT_TILE.1);
        assert_eq!(igi_core::settings::MAX_IMAGE_SIDE, 65_535 * tile);
    }
}
