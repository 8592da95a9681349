//! The viewer's display (after the paper's frame, section 4): the composed linear image
//! onto a window's surface, and optionally the frame's VPLs drawn as dots. A render pass,
//! not a compute stage: `igi render` never runs it. See `display.wgsl`.

use super::bindings::{bind, layout_of, Bindings};
use crate::layout::DisplayParams;
use crate::shader::ParamsBinding;

crate::bindings! {
    /// Bind group 1 of display.wgsl.
    pub struct DisplayBindings {
        /// The frame's parameters (the image's size).
        params: Params,
        /// How to show it (viewport, exposure, dots).
        display: Params,
        color_in: Read,
        vpls: Read,
        vpl_header: Read,
    }
}

/// What the display reads from the renderer (see `Renderer::display_inputs`).
pub struct DisplayInputs<'a> {
    pub params: &'a wgpu::Buffer,
    pub color: &'a wgpu::Buffer,
    pub vpls: &'a wgpu::Buffer,
    pub vpl_header: &'a wgpu::Buffer,
    pub width: u32,
    pub height: u32,
    /// VPL slots of the buffer: the most dots there can be.
    pub vpl_slots: u32,
}

/// How to show the image.
#[derive(Clone, Copy, Debug)]
pub struct DisplayOptions {
    /// The image's rectangle in the target, in target pixels: x, y, width, height.
    pub viewport: [f32; 4],
    /// Multiplier before clamping and sRGB encoding (as `igi render --exposure`).
    pub exposure: f32,
    /// Draw the VPLs as dots of this half side in pixels (None: no dots).
    pub vpl_dots: Option<f32>,
    /// Colour of the target outside the viewport.
    pub background: wgpu::Color,
}

pub struct DisplayPass {
    layout: wgpu::BindGroupLayout,
    image: wgpu::RenderPipeline,
    dots: wgpu::RenderPipeline,
    params: wgpu::Buffer,
    /// Whether the target format needs the shader to encode sRGB.
    encode_srgb: bool,
}

impl DisplayPass {
    /// Pipelines drawing into targets of `format`.
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> DisplayPass {
        let params = ParamsBinding::of(device);
        let layout = layout_of(
            device,
            "display",
            DisplayBindings::BINDINGS,
            wgpu::ShaderStages::VERTEX_FRAGMENT,
        );
        let source = super::SOURCES
            .iter()
            .find(|s| s.name == "display")
            .expect("display source");
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("display"),
            source: wgpu::ShaderSource::Wgsl(crate::shader::compose_for(source, params).into()),
        });
        // Group 0 (the scene) is declared by the shared modules but unused here.
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("display"),
            bind_group_layouts: &[None, Some(&layout)],
            immediate_size: 0,
        });
        let make = |vs: &str, fs: &str| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(vs),
                layout: Some(&pipeline_layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some(vs),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: wgpu::PrimitiveState::default(),
                depth_stencil: None,
                multisample: wgpu::MultisampleState::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(fs),
                    compilation_options: Default::default(),
                    targets: &[Some(format.into())],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        DisplayPass {
            image: make("vs_image", "fs_image"),
            dots: make("vs_vpl", "fs_vpl"),
            layout,
            params: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("display params"),
                size: std::mem::size_of::<DisplayParams>() as u64,
                usage: params.usage() | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            encode_srgb: !format.is_srgb(),
        }
    }

    /// Clear `target` and draw the image (and the dots) into `options.viewport`.
    pub fn draw(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        inputs: &DisplayInputs,
        options: &DisplayOptions,
    ) {
        let params = DisplayParams {
            viewport: options.viewport,
            image_width: inputs.width,
            image_height: inputs.height,
            exposure: options.exposure,
            encode_srgb: self.encode_srgb as u32,
            dot_radius: options.vpl_dots.unwrap_or(0.0),
            _pad: [0; 3],
        };
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
        let bindings = DisplayBindings {
            params: inputs.params,
            display: &self.params,
            color_in: inputs.color,
            vpls: inputs.vpls,
            vpl_header: inputs.vpl_header,
        };
        let bind_group = bind(device, "display", &self.layout, &bindings).group;
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("display"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(options.background),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        let [x, y, w, h] = options.viewport;
        if w < 1.0 || h < 1.0 {
            return;
        }
        pass.set_viewport(x, y, w, h, 0.0, 1.0);
        pass.set_bind_group(1, &bind_group, &[]);
        pass.set_pipeline(&self.image);
        pass.draw(0..3, 0..1);
        if options.vpl_dots.is_some() && inputs.vpl_slots > 0 {
            pass.set_pipeline(&self.dots);
            pass.draw(0..6, 0..inputs.vpl_slots);
        }
    }
}
