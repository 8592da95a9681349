//! The frame's passes in order (paper section 4). [`Renderer::frame_passes`] is the one
//! place that says what a frame runs; the recorder (`recorder.rs`) decides which of them
//! run side by side, from what each binds.

use super::recorder::FramePass;
use super::resources::Buf;
use super::Renderer;
use crate::passes::filter::Filter;
use crate::passes::vpl::VplPass;
use crate::passes::{lanes_for, GatherRanges};
use igi_core::settings::{Accelerations, FilterMode, RenderSettings};

/// What the passes need to know of a frame's shape.
pub(crate) struct FrameShape<'a> {
    /// The image.
    pub full: (u32, u32),
    /// The indirect term's resolution ([`low_resolution`]).
    pub low: (u32, u32),
    pub imperfect_visibility: bool,
    /// Interleaving tiles (1 x 1: none).
    pub interleave: (u32, u32),
    /// Lanes per pixel of the indirect gather ([`lanes_for`]).
    pub lanes: u32,
    /// The most workgroups of the mirror gather and of the chain walks, which stride over
    /// lists whose lengths only the GPU knows.
    pub list_grids: (u32, u32),
    /// The VPL ranges every gather runs over (see `Renderer::ensure_ranges`).
    pub ranges: GatherRanges<'a>,
    /// The range entry of the direct pass's first walk: no VPLs.
    pub first_walk: GatherRanges<'a>,
}

impl Renderer {
    /// The passes of one frame of `settings` from `paths` light paths, in order.
    pub(crate) fn frame_passes<'a>(
        &'a self,
        device: &wgpu::Device,
        settings: &RenderSettings,
        paths: u32,
    ) -> Vec<FramePass<'a>> {
        let (b, a, shape) = (&self.buffers, &settings.accelerations, self.shape(settings));
        let interleaved = a.interleave.0 * a.interleave.1 > 1;
        let mut frame = vec![];
        // 1. VPL shooting (light paths leave VPLs) and, beside it, direct + specular
        //    (primary hits, the G-buffer, mirrors, the mirror record); then the VPLs'
        //    compaction into a dense list where it is a pass of its own.
        let vpl_bindings = VplPass::bindings(b, &self.halton_perms.1);
        let (shooting, compaction) = self.vpl.record(device, &vpl_bindings, paths);
        frame.push(shooting);
        frame.push(self.direct.record_first_walk(device, b, &shape));
        frame.extend(compaction);
        // 2. Indirect light: at hits seen in a mirror seen in a mirror (later walks of the
        //    direct pass), at the mirrored hits, and at the primary hits.
        if self.has_mirrors && settings.mirror_depth >= 2 {
            frame.push(self.direct.record_chain_walks(device, b, &shape));
        }
        if self.has_mirrors {
            frame.push(self.indirect.record_mirrored(device, b, &shape));
        }
        frame.push(self.indirect.record_primary(device, b, &shape));
        // 3. The accelerations' filters: of the indirect term, and the discontinuity
        //    buffer over the mirrored hits of an interleaved frame.
        let (filter, upsample) = filter_chain(a);
        let e = filter.map_or(Buf::Irradiance, |f| {
            frame.push(self.filter.record(device, b, &shape, f));
            f.output()
        });
        let mirror_e = if self.has_mirrors && interleaved {
            frame.push(self.filter.record_mirrored(device, b, &shape));
            Buf::MirrorFiltered
        } else {
            Buf::MirrorIrradiance
        };
        // 4. Compose: L = direct + (rho / pi) E, upsampling E on the way.
        frame.push(
            self.compose
                .record(device, b, &shape, e, mirror_e, upsample),
        );
        frame
    }

    /// The shape of a frame of `settings` (its VPL ranges must be written).
    fn shape(&self, settings: &RenderSettings) -> FrameShape<'_> {
        let a = &settings.accelerations;
        let low = low_resolution(settings);
        let (_, range_group, range_count) = self.range_buffer.as_ref().expect("ranges written");
        let interleaved = a.interleave.0 * a.interleave.1 > 1;
        FrameShape {
            full: (settings.width, settings.height),
            low,
            imperfect_visibility: a.imperfect_visibility,
            interleave: a.interleave,
            lanes: lanes_for(low.0 * low.1, interleaved, self.software, &self.switches),
            list_grids: self.list_grids,
            // Entry 0 of the range buffer is the first walk's, then the VPL ranges.
            ranges: GatherRanges {
                bind_group: range_group,
                first: 1,
                count: *range_count,
            },
            first_walk: GatherRanges {
                bind_group: range_group,
                first: 0,
                count: 1,
            },
        }
    }
}

/// The resolution of the indirect term: full / downsample, rounded up.
pub fn low_resolution(settings: &RenderSettings) -> (u32, u32) {
    let s = settings.accelerations.downsample.max(1);
    (settings.width.div_ceil(s), settings.height.div_ceil(s))
}

/// The filter an acceleration set-up runs on the indirect term (if any), and whether the
/// compose pass then upsamples its result (joint bilateral upsampling, the second of the
/// two passes of [`FilterMode::TwoPass`]).
pub fn filter_chain(a: &Accelerations) -> (Option<Filter>, bool) {
    let interleaved = a.interleave.0 * a.interleave.1 > 1;
    let downsampled = a.downsample > 1;
    match a.filter {
        _ if !interleaved && !downsampled => (None, false),
        FilterMode::Fused => (Some(Filter::Fused), false),
        FilterMode::TwoPass if interleaved => (Some(Filter::Discontinuity), downsampled),
        FilterMode::TwoPass => (None, downsampled),
    }
}
