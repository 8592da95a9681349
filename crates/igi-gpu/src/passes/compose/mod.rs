//! Compose (paper section 4, last stage): L = direct + (rho / pi) E, linear radiance,
//! with E at full resolution or upsampled on the way (joint bilateral upsampling, paper
//! section 4.2), averaged over accumulated frames. See `compose.wgsl`.

pub mod cpu;

use super::bindings::{bind, compute_layout};
use super::{image_groups, pipeline, Step};
use crate::frame::recorder::FramePass;
use crate::frame::resources::{Buf, FrameBuffers};
use crate::frame::FrameShape;
use crate::switches::Switches;

crate::bindings! {
    /// Bind group 1 of compose.wgsl.
    pub struct ComposeBindings {
        params: Params,
        /// The G-buffer's position and normal, which the upsampler weighs by, and E, at
        /// full resolution or at the indirect term's (then upsampled): at the bindings
        /// the filter has them at (upsample.wgsl declares the normal and E).
        gbuf_position: Read,
        gbuf_normal: Read,
        irradiance_in: Read,
        color_out: Write,
        direct_in: Read,
        gbuf_albedo: Read,
        /// The mirrored hits' weight and E.
        mirror_weight: Read,
        mirror_irradiance: Read,
    }
}

pub struct ComposePass {
    pub layout: wgpu::BindGroupLayout,
    /// E read at full resolution (`main`).
    pipeline: wgpu::ComputePipeline,
    /// E upsampled from the indirect term's resolution (`main_upsampled`).
    upsampled: wgpu::ComputePipeline,
}

impl ComposePass {
    pub fn new(
        device: &wgpu::Device,
        switches: &Switches,
        scene_layout: &wgpu::BindGroupLayout,
    ) -> ComposePass {
        let layout = compute_layout::<ComposeBindings>(device, "compose");
        let layouts = [scene_layout, &layout];
        ComposePass {
            pipeline: pipeline(device, switches, "compose", "main", &layouts),
            upsampled: pipeline(device, switches, "compose", "main_upsampled", &layouts),
            layout,
        }
    }

    /// The bind group of `bindings` (for tests that run the pass alone).
    pub fn bind(&self, device: &wgpu::Device, bindings: &ComposeBindings) -> wgpu::BindGroup {
        bind(device, "compose", &self.layout, bindings).group
    }

    /// The dispatch over a `width` x `height` image; with `upsample`, the E buffer bound
    /// is at the indirect term's resolution and is upsampled pixel by pixel.
    pub fn steps(&self, width: u32, height: u32, upsample: bool) -> [Step<'_>; 1] {
        let pipeline = if upsample {
            &self.upsampled
        } else {
            &self.pipeline
        };
        [(pipeline, image_groups(width, height))]
    }

    /// The frame's colour from the direct light, the albedo and `e` (upsampled when
    /// `upsample`), with `mirror_e` at the mirrored hits.
    pub(crate) fn record<'a>(
        &'a self,
        device: &wgpu::Device,
        buffers: &'a FrameBuffers,
        shape: &FrameShape<'a>,
        e: Buf,
        mirror_e: Buf,
        upsample: bool,
    ) -> FramePass<'a> {
        let b = |buf| buffers.get(buf);
        let bindings = ComposeBindings {
            params: b(Buf::Params),
            direct_in: b(Buf::Direct),
            gbuf_albedo: b(Buf::GbufAlbedo),
            irradiance_in: b(e),
            color_out: b(Buf::Color),
            gbuf_position: b(Buf::GbufPosition),
            gbuf_normal: b(Buf::GbufNormal),
            mirror_weight: b(Buf::MirrorWeight),
            mirror_irradiance: b(mirror_e),
        };
        // With downsampling (two-pass filters), compose upsamples E as it writes each
        // pixel: a pass of its own cost the frame more.
        let name = if upsample {
            "upsample + compose"
        } else {
            "compose"
        };
        FramePass::new(
            name,
            self.steps(shape.full.0, shape.full.1, upsample).to_vec(),
            bind(device, "compose", &self.layout, &bindings),
        )
    }
}
