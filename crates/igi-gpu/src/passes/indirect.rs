//! Indirect diffuse light at the primary hits from all VPLs (paper section 4, third
//! stage), stored as the incident term E without the albedo. See `shaders/indirect.wgsl`.

use super::{bind, pass_layout, GatherPipelines};
use crate::scene_buffers::{READ, UNIFORM, WRITE};

pub struct IndirectPass {
    pub layout: wgpu::BindGroupLayout,
    /// One pair (exact, imperfect visibility) per entry of [`LANE_CHOICES`].
    pipelines: Vec<GatherPipelines>,
}

/// VPL lanes per pixel the indirect pass is built for (`VPL_LANES` of indirect.wgsl).
pub const LANE_CHOICES: [u32; 2] = [1, 8];

/// Below this many pixels of the indirect term, each pixel's VPLs are split over 8 lanes:
/// a downsampled 800 x 600 frame (30000 pixels) is a few hundred warps, far from filling
/// a large GPU; full resolution (480000) fills it with one lane. `IGI_VPL_LANES` (1 or 8)
/// overrides the choice, for measurements.
pub const LANES_BELOW_PIXELS: u32 = 200_000;

/// The lanes the indirect pass uses for an indirect term of `pixels` pixels; always one
/// on a software adapter, which has few threads to fill and whose workgroup barriers are
/// slow.
pub fn lanes_for(pixels: u32, software: bool) -> u32 {
    if let Some(l) = std::env::var("IGI_VPL_LANES")
        .ok()
        .and_then(|v| v.parse::<u32>().ok())
    {
        if LANE_CHOICES.contains(&l) {
            return l;
        }
    }
    if pixels < LANES_BELOW_PIXELS && !software {
        8
    } else {
        1
    }
}

impl IndirectPass {
    pub fn new(
        device: &wgpu::Device,
        scene_layout: &wgpu::BindGroupLayout,
        range_layout: &wgpu::BindGroupLayout,
    ) -> IndirectPass {
        // params, vpls, vpl_header, position, normal, geometric, irradiance
        let layout = pass_layout(
            device,
            "indirect",
            &[UNIFORM, READ, READ, READ, READ, READ, WRITE],
        );
        IndirectPass {
            pipelines: LANE_CHOICES
                .iter()
                .map(|&lanes| {
                    let layouts = [scene_layout, &layout, range_layout];
                    if lanes == 1 {
                        GatherPipelines::new(device, "indirect", "main", &layouts, &[])
                    } else {
                        let constants = [("VPL_LANES", lanes as f64)];
                        GatherPipelines::new(device, "indirect", "main_lanes", &layouts, &constants)
                    }
                })
                .collect(),
            layout,
        }
    }

    pub fn bind(&self, device: &wgpu::Device, buffers: &[&wgpu::Buffer; 7]) -> wgpu::BindGroup {
        bind(device, "indirect", &self.layout, buffers)
    }

    /// The dispatch over a `width` x `height` indirect term: 64-thread workgroups, each a
    /// tile of 64 / lanes pixels (see indirect.wgsl).
    pub fn steps(
        &self,
        width: u32,
        height: u32,
        imperfect_visibility: bool,
        software: bool,
    ) -> [(&wgpu::ComputePipeline, [u32; 3]); 1] {
        let lanes = lanes_for(width * height, software);
        let index = LANE_CHOICES.iter().position(|&l| l == lanes).unwrap_or(0);
        // Workgroups of 64 threads: 8 x 8 pixels with one lane, else a tile of 64 / lanes.
        let pixels = 64 / lanes;
        let tile_w = 1u32 << pixels.trailing_zeros().div_ceil(2);
        let tile_h = pixels / tile_w;
        [(
            self.pipelines[index].get(imperfect_visibility),
            [width.div_ceil(tile_w), height.div_ceil(tile_h), 1],
        )]
    }
}
