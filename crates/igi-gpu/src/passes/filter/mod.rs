//! The filters of the accelerated indirect term (paper sections 4.2 and 4.3): the
//! discontinuity buffer, and it fused with upsampling in one pass (the paper's future
//! work). Joint bilateral upsampling on its own is done by the compose pass as it writes
//! each pixel. See `filter.wgsl`.

pub mod cpu;

use super::bindings::{bind, compute_layout};
use super::{image_groups, pipeline, Step};
use crate::frame::recorder::FramePass;
use crate::frame::resources::{Buf, FrameBuffers};
use crate::frame::FrameShape;
use crate::switches::Switches;

crate::bindings! {
    /// Bind group 1 of filter.wgsl: the G-buffer record that tells what is continuous,
    /// E in and E out.
    pub struct FilterBindings {
        params: Params,
        gbuf_position: Read,
        gbuf_normal: Read,
        irradiance_in: Read,
        filter_out: Write,
    }
}

pub struct FilterPass {
    pub layout: wgpu::BindGroupLayout,
    discontinuity: wgpu::ComputePipeline,
    fused: wgpu::ComputePipeline,
}

/// Which filter a step runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Filter {
    Discontinuity,
    Fused,
}

impl Filter {
    pub fn stage_name(self) -> &'static str {
        match self {
            Filter::Discontinuity => "discontinuity",
            Filter::Fused => "fused filter",
        }
    }

    /// The buffer the filter of the indirect term writes.
    pub fn output(self) -> Buf {
        match self {
            Filter::Discontinuity => Buf::FilteredLow,
            Filter::Fused => Buf::Filtered,
        }
    }
}

impl FilterPass {
    pub fn new(
        device: &wgpu::Device,
        switches: &Switches,
        scene_layout: &wgpu::BindGroupLayout,
    ) -> FilterPass {
        let layout = compute_layout::<FilterBindings>(device, "filter");
        let layouts = [scene_layout, &layout];
        FilterPass {
            discontinuity: pipeline(device, switches, "filter", "discontinuity", &layouts),
            fused: pipeline(device, switches, "filter", "fused", &layouts),
            layout,
        }
    }

    /// The dispatch of `filter`: the discontinuity buffer runs at the indirect term's
    /// resolution, the fused filter at full resolution.
    pub fn steps(&self, filter: Filter, full: (u32, u32), low: (u32, u32)) -> [Step<'_>; 1] {
        match filter {
            Filter::Discontinuity => [(&self.discontinuity, image_groups(low.0, low.1))],
            Filter::Fused => [(&self.fused, image_groups(full.0, full.1))],
        }
    }

    /// `filter` over the indirect term E at the primary hits, into [`Filter::output`].
    pub(crate) fn record<'a>(
        &'a self,
        device: &wgpu::Device,
        buffers: &'a FrameBuffers,
        shape: &FrameShape<'a>,
        filter: Filter,
    ) -> FramePass<'a> {
        let b = |buf| buffers.get(buf);
        let bindings = FilterBindings {
            params: b(Buf::Params),
            gbuf_position: b(Buf::GbufPosition),
            gbuf_normal: b(Buf::GbufNormal),
            irradiance_in: b(Buf::Irradiance),
            filter_out: b(filter.output()),
        };
        FramePass::new(
            filter.stage_name(),
            self.steps(filter, shape.full, shape.low).to_vec(),
            bind(device, "filter", &self.layout, &bindings),
        )
    }

    /// The discontinuity buffer over E at the mirrored hits (full resolution, the mirror
    /// parameters), for interleaved frames.
    pub(crate) fn record_mirrored<'a>(
        &'a self,
        device: &wgpu::Device,
        buffers: &'a FrameBuffers,
        shape: &FrameShape<'a>,
    ) -> FramePass<'a> {
        let b = |buf| buffers.get(buf);
        let bindings = FilterBindings {
            params: b(Buf::MirrorParams),
            gbuf_position: b(Buf::MirrorPosition),
            gbuf_normal: b(Buf::MirrorNormal),
            irradiance_in: b(Buf::MirrorIrradiance),
            filter_out: b(Buf::MirrorFiltered),
        };
        FramePass::new(
            "mirror discontinuity",
            self.steps(Filter::Discontinuity, shape.full, shape.full)
                .to_vec(),
            bind(device, "filter", &self.layout, &bindings),
        )
    }
}
