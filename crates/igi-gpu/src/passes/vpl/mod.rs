//! VPL shooting (paper section 4, first stage): light paths from the point lights leave
//! VPLs at diffuse hits, compacted into a dense list. See `vpl.wgsl`; its CPU twin is
//! `igi_core::vpl`.

use super::bindings::{bind, compute_layout};
use super::{pipeline_with_constants, Step, SurfaceMaps};
use crate::frame::recorder::FramePass;
use crate::frame::resources::{Buf, FrameBuffers};
use crate::switches::Switches;

/// Threads per workgroup of the shooting kernel (`SHOOT_GROUP` in the WGSL).
pub const SHOOT_GROUP: u32 = 64;
/// The most paths that one workgroup shoots and compacts (`COMPACT_GROUP` in the WGSL).
pub const COMPACT_GROUP: u32 = 256;
/// Largest number of workgroups in one dimension of a dispatch.
const MAX_GROUPS: u32 = 65535;

crate::bindings! {
    /// Bind group 1 of vpl.wgsl.
    pub struct VplBindings {
        params: Params,
        /// A slot per path and bounce, written as the paths go.
        vpl_slots: Write,
        /// The dense list, written by the compaction.
        vpls: Write,
        vpl_header: Write,
        /// The scrambled Halton sequence's digit permutations.
        halton_perms: Read,
    }
}

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
    pub fn new(
        device: &wgpu::Device,
        switches: &Switches,
        scene_layout: &wgpu::BindGroupLayout,
        maps: SurfaceMaps,
    ) -> VplPass {
        let layout = compute_layout::<VplBindings>(device, "vpl");
        let layouts = [scene_layout, &layout];
        let constants = maps.constants();
        let build =
            |entry| pipeline_with_constants(device, switches, "vpl", entry, &layouts, &constants);
        VplPass {
            shoot: build("shoot"),
            compact: build("compact"),
            shoot_and_compact: build("shoot_and_compact"),
            layout,
        }
    }

    /// The bindings of the frame's buffers, with the permutations of the frame's seed.
    pub fn bindings<'a>(
        buffers: &'a FrameBuffers,
        halton_perms: &'a wgpu::Buffer,
    ) -> VplBindings<'a> {
        VplBindings {
            params: buffers.get(Buf::Params),
            vpl_slots: buffers.get(Buf::VplSlots),
            vpls: buffers.get(Buf::Vpls),
            vpl_header: buffers.get(Buf::VplHeader),
            halton_perms,
        }
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

    /// The frame's VPL list from `paths` light paths: shooting, and the compaction as a
    /// pass of its own when it needs one (it reads every workgroup's slots). The frame
    /// lists the compaction after the direct pass, so that shooting runs beside it.
    pub(crate) fn record<'a>(
        &'a self,
        device: &wgpu::Device,
        bindings: &VplBindings<'a>,
        paths: u32,
    ) -> (FramePass<'a>, Option<FramePass<'a>>) {
        let steps = self.steps(paths);
        let pass = |name, step| {
            FramePass::new(
                name,
                vec![step],
                bind(device, "vpl", &self.layout, bindings),
            )
        };
        (
            pass("vpl shooting", steps.shoot),
            steps.compact.map(|step| pass("vpl list", step)),
        )
    }

    /// Shooting and compaction as one pass (the pilot run and the VPL count, outside a
    /// frame).
    pub(crate) fn record_alone<'a>(
        &'a self,
        device: &wgpu::Device,
        bindings: &VplBindings<'a>,
        paths: u32,
    ) -> FramePass<'a> {
        let steps = self.steps(paths);
        FramePass::new(
            "vpl",
            std::iter::once(steps.shoot).chain(steps.compact).collect(),
            bind(device, "vpl", &self.layout, bindings),
        )
    }
}
