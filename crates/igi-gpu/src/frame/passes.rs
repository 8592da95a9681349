//! The passes of a frame with their pipelines (made before the scene: see [`Passes`]).

use super::Switches;
use crate::context::GpuContext;
use crate::passes::compose::ComposePass;
use crate::passes::direct::DirectPass;
use crate::passes::filter::FilterPass;
use crate::passes::indirect::IndirectPass;
use crate::passes::vpl::VplPass;
use crate::passes::{gather_range_layout, mirror_lanes, SurfaceMaps};
use crate::scene_buffers::SceneBuffers;

/// The passes of a frame with their pipelines, made from the device alone: no scene
/// goes into them, so a command can make them while it loads the scene. They are most
/// of a renderer's set-up (the driver compiles every shader). The environment switches
/// ([`Switches`]) are read here, once.
pub struct Passes {
    pub(super) switches: Switches,
    /// What the tracing passes were built to draw (texture.wgsl's overrides).
    pub(super) maps: SurfaceMaps,
    pub(super) scene_layout: wgpu::BindGroupLayout,
    pub(super) range_layout: wgpu::BindGroupLayout,
    pub(super) vpl: VplPass,
    pub(super) direct: DirectPass,
    pub(super) indirect: IndirectPass,
    pub(super) filter: FilterPass,
    pub(super) compose: ComposePass,
}

impl Passes {
    /// Passes for scenes without textures, vertex colours or alpha masks (a renderer
    /// given a scene with them builds its own: [`super::Renderer::with_passes`]).
    pub fn new(ctx: &GpuContext) -> Passes {
        Passes::for_maps(ctx, Switches::from_env(), SurfaceMaps::default())
    }

    /// The passes with the given switches instead of the environment's.
    pub fn with_switches(ctx: &GpuContext, switches: Switches) -> Passes {
        Passes::for_maps(ctx, switches, SurfaceMaps::default())
    }

    /// The passes for scenes that need at most `maps` of textures and masks.
    pub fn for_maps(ctx: &GpuContext, switches: Switches, maps: SurfaceMaps) -> Passes {
        let device = &ctx.device;
        let s = &switches;
        let layout = SceneBuffers::layout(device);
        let range_layout = gather_range_layout(device);
        let list_lanes = mirror_lanes(ctx.is_software(), s);
        Passes {
            vpl: VplPass::new(device, s, &layout, maps),
            direct: DirectPass::new(device, s, &layout, &range_layout, maps),
            indirect: IndirectPass::new(device, s, &layout, &range_layout, list_lanes, maps),
            filter: FilterPass::new(device, s, &layout),
            compose: ComposePass::new(device, s, &layout),
            scene_layout: layout,
            range_layout,
            switches,
            maps,
        }
    }
}
