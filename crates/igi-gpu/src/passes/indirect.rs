//! Indirect diffuse light from the VPLs (paper section 4, third stage), stored as the
//! incident term E without the albedo, at the records of a G-buffer: the primary hits
//! (at the indirect term's resolution), and, with a second set of parameters at full
//! resolution, the first diffuse hits seen through mirrors (the "mirror indirect" stage;
//! the paper gathers every VPL there and leaves that cost as future work).
//! See `shaders/indirect.wgsl`.

use super::{bind, pass_layout, pipeline_with_constants, GatherPipelines, LanePipelines};
use crate::scene_buffers::{READ, UNIFORM, WRITE};

pub struct IndirectPass {
    pub layout: wgpu::BindGroupLayout,
    pipelines: LanePipelines,
    /// Bind group 3 of the gather over the list of mirrored pixels: the list
    /// (direct.wgsl's mirror_list); of the step that sizes its dispatch: the list and the
    /// dispatch's workgroup counts (not in the gather's group: a buffer read as indirect
    /// arguments may not be bound for storage in the same dispatch).
    list_layout: wgpu::BindGroupLayout,
    args_layout: wgpu::BindGroupLayout,
    /// The gather over the listed pixels (`main_list`).
    list: GatherPipelines,
    /// Reads the list's length and writes the indirect dispatch (`mirror_args_main`).
    args: wgpu::ComputePipeline,
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
        let list_layout = pass_layout(device, "mirror list", &[WRITE]);
        let args_layout = pass_layout(device, "mirror list and dispatch", &[WRITE, WRITE]);
        let layouts = [scene_layout, &layout, range_layout, &list_layout];
        let args_layouts = [scene_layout, &layout, range_layout, &args_layout];
        let lanes = [("VPL_LANES", list_lanes as f64)];
        IndirectPass {
            pipelines: LanePipelines::new(
                device,
                "indirect",
                &[scene_layout, &layout, range_layout],
            ),
            list: GatherPipelines::new(device, "indirect", "main_list", &layouts, &lanes),
            args: pipeline_with_constants(
                device,
                "indirect",
                "mirror_args_main",
                &args_layouts,
                &lanes,
            ),
            list_layout,
            args_layout,
            layout,
        }
    }

    /// Bind group 3 of the list gather (the list) and of its sizing step (the list and
    /// the dispatch arguments).
    pub fn bind_list(
        &self,
        device: &wgpu::Device,
        list: &wgpu::Buffer,
        args: &wgpu::Buffer,
    ) -> (wgpu::BindGroup, wgpu::BindGroup) {
        (
            bind(device, "mirror list", &self.list_layout, &[list]),
            bind(
                device,
                "mirror list and dispatch",
                &self.args_layout,
                &[list, args],
            ),
        )
    }

    /// The one-thread step that sizes the list gather's dispatch.
    pub fn args_step(&self) -> (&wgpu::ComputePipeline, [u32; 3]) {
        (&self.args, [1, 1, 1])
    }

    /// The gather over the listed pixels (dispatched indirectly, see [`Self::args_step`]).
    pub fn list_pipeline(&self, imperfect_visibility: bool) -> &wgpu::ComputePipeline {
        self.list.get(imperfect_visibility)
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
    ) -> [(&wgpu::ComputePipeline, [u32; 3]); 1] {
        [self
            .pipelines
            .step(width, height, imperfect_visibility, lanes, interleave)]
    }
}
