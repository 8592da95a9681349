//! Shader assembly: every pass's WGSL is the shared modules (scene bindings, traversal,
//! frame types and sampling, VPL gathering, upsampling) followed by the pass's own file. Composition is
//! plain concatenation in a fixed order, done once at pipeline creation; a naga test
//! parses and validates every composed shader, so a broken shader fails a test, not a user.

use crate::passes::PassSource;

pub mod resolve;

/// Shared WGSL modules, in the order they are prepended.
pub const SCENE: &str = include_str!("../shaders/scene.wgsl");
pub const TRAVERSE: &str = include_str!("../shaders/traverse.wgsl");
pub const FRAME: &str = include_str!("../shaders/frame.wgsl");
pub const GATHER: &str = include_str!("../shaders/gather.wgsl");
pub const UPSAMPLE: &str = include_str!("../shaders/upsample.wgsl");

/// A pass's full shader: the shared modules, then the pass, its parameter blocks bound as
/// uniform buffers (as written).
pub fn compose(pass: &PassSource) -> String {
    compose_for(pass, ParamsBinding::Uniform)
}

/// A pass's full shader with its parameter blocks bound as `params` says.
pub fn compose_for(pass: &PassSource, params: ParamsBinding) -> String {
    let gather = if pass.gathers { GATHER } else { "" };
    let upsample = if pass.upsamples { UPSAMPLE } else { "" };
    let wgsl = [SCENE, TRAVERSE, FRAME, gather, upsample, pass.wgsl].join("\n");
    match params {
        ParamsBinding::Uniform => wgsl,
        ParamsBinding::Storage => wgsl.replace(UNIFORM_DECLARATION, "var<storage, read>"),
    }
}

/// How the shaders' parameter blocks (the frame's `params`, the gathers' VPL range, the
/// viewer's display parameters: every `var<uniform>` of the WGSL) are bound on a device.
///
/// GPUs read them as uniform buffers, through their constant caches. Software adapters
/// read them as read-only storage buffers instead: lavapipe (Mesa 22.3, the software
/// Vulkan of Debian 12 and of CI) compiles a new copy of a shader each time its pipeline
/// is bound when the shader's branches or loops depend on uniform values alone (it
/// inlines them), and keeps every copy until the pipeline is dropped. That made each
/// frame compile shaders again, 3-4x its time, and grow the process by about 1.35 MB:
/// 3.9 GB after 3,000 accumulated frames (docs/PERFORMANCE.md attempt 123).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ParamsBinding {
    Uniform,
    Storage,
}

/// How WGSL declares a parameter block; [`ParamsBinding::Storage`] rewrites it.
const UNIFORM_DECLARATION: &str = "var<uniform>";

impl ParamsBinding {
    /// Both bindings, GPUs' first: what the shader tests go through.
    pub const ALL: [ParamsBinding; 2] = [ParamsBinding::Uniform, ParamsBinding::Storage];

    /// The binding for `device`.
    pub fn of(device: &wgpu::Device) -> ParamsBinding {
        ParamsBinding::for_type(device.adapter_info().device_type)
    }

    /// The binding for an adapter of type `device_type`: storage on software adapters,
    /// uniform elsewhere.
    pub fn for_type(device_type: wgpu::DeviceType) -> ParamsBinding {
        if device_type == wgpu::DeviceType::Cpu {
            ParamsBinding::Storage
        } else {
            ParamsBinding::Uniform
        }
    }

    /// The bind group layout's buffer type of a parameter block.
    pub fn buffer_type(self) -> wgpu::BufferBindingType {
        match self {
            ParamsBinding::Uniform => wgpu::BufferBindingType::Uniform,
            ParamsBinding::Storage => wgpu::BufferBindingType::Storage { read_only: true },
        }
    }

    /// The usage a parameter block's buffer needs.
    pub fn usage(self) -> wgpu::BufferUsages {
        match self {
            ParamsBinding::Uniform => wgpu::BufferUsages::UNIFORM,
            ParamsBinding::Storage => wgpu::BufferUsages::STORAGE,
        }
    }
}

/// Every composed shader igi builds, by name, as GPUs get them (uniform parameter
/// blocks), for the layout and constant tests; `every_pass_shader_validates` goes through
/// both bindings itself.
pub fn all_shaders() -> Vec<(&'static str, String)> {
    crate::passes::SOURCES
        .iter()
        .map(|pass| (pass.name, compose(pass)))
        .collect()
}
