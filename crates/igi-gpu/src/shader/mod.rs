//! Shader assembly: each pass's WGSL file names the shared modules it uses on `#import`
//! lines at its top, and each module names its own; [`resolve`] puts every module a pass
//! needs before it, each once, its imports before it. Done once at pipeline creation; a
//! naga test parses and validates every composed shader and every module on its own, so a
//! broken shader, or a module that relies on what its includer declares, fails a test, not
//! a user.

pub mod resolve;

pub use resolve::ResolveError;

/// Every WGSL module a shader may `#import`, by name. Shared modules live in `shaders/`,
/// a pass's own file in its pass's folder.
pub const MODULES: &[(&str, &str)] = &[
    ("scene", include_str!("../shaders/scene.wgsl")),
    ("traverse", include_str!("../shaders/traverse.wgsl")),
    ("texture", include_str!("../shaders/texture.wgsl")),
    ("params", include_str!("../shaders/params.wgsl")),
    ("constants", include_str!("../shaders/constants.wgsl")),
    ("sampling", include_str!("../shaders/sampling.wgsl")),
    ("surface", include_str!("../shaders/surface.wgsl")),
    ("ray_count", include_str!("../shaders/ray_count.wgsl")),
    ("vpl_record", include_str!("../shaders/vpl_record.wgsl")),
    (
        "geometry_term",
        include_str!("../shaders/geometry_term.wgsl"),
    ),
    ("gbuffer", include_str!("../shaders/gbuffer.wgsl")),
    ("mirror_list", include_str!("../shaders/mirror_list.wgsl")),
    ("gather", include_str!("../shaders/gather.wgsl")),
    ("upsample", include_str!("../shaders/upsample.wgsl")),
    // The ray bench's any-hit and closest-hit kernels, which its refill schedule extends.
    ("rays", include_str!("../raybench/rays.wgsl")),
];

/// The source of module `name`, if [`MODULES`] has one.
pub fn module(name: &str) -> Option<&'static str> {
    MODULES.iter().find(|(n, _)| *n == name).map(|(_, s)| *s)
}

/// A pass's own WGSL (its `#import` lines name the modules composed before it).
pub struct PassSource {
    pub name: &'static str,
    pub wgsl: &'static str,
    /// Whether it uses subgroup operations (built only where the device has
    /// `Features::SUBGROUP`; validated with naga's subgroup capability).
    pub subgroups: bool,
}

/// Each pass's own WGSL, by name (composed with the modules it imports by [`compose`]).
pub const SOURCES: &[PassSource] = &[
    PassSource {
        name: "vpl",
        wgsl: include_str!("../passes/vpl/vpl.wgsl"),
        subgroups: false,
    },
    PassSource {
        name: "direct",
        wgsl: include_str!("../passes/direct/direct.wgsl"),
        subgroups: false,
    },
    PassSource {
        name: "indirect",
        wgsl: include_str!("../passes/indirect/indirect.wgsl"),
        subgroups: false,
    },
    PassSource {
        name: "filter",
        wgsl: include_str!("../passes/filter/filter.wgsl"),
        subgroups: false,
    },
    PassSource {
        name: "rays",
        wgsl: include_str!("../raybench/rays.wgsl"),
        subgroups: false,
    },
    PassSource {
        name: "rays_refill",
        // Imports rays.wgsl: its bindings and kernels, then the refill schedule's.
        wgsl: include_str!("../raybench/rays_refill.wgsl"),
        subgroups: true,
    },
    PassSource {
        name: "compose",
        wgsl: include_str!("../passes/compose/compose.wgsl"),
        subgroups: false,
    },
    PassSource {
        name: "display",
        wgsl: include_str!("../passes/display/display.wgsl"),
        subgroups: false,
    },
];

/// A pass's full shader: the modules it imports, then the pass, its parameter blocks bound
/// as uniform buffers (as written).
pub fn compose(pass: &PassSource) -> String {
    compose_for(pass, ParamsBinding::Uniform)
}

/// A pass's full shader with its parameter blocks bound as `params` says.
///
/// Panics if the imports do not resolve: the sources are fixed when igi is built, and
/// `every_pass_shader_validates` composes each of them.
pub fn compose_for(pass: &PassSource, params: ParamsBinding) -> String {
    try_compose(pass.name, pass.wgsl, params).unwrap_or_else(|e| panic!("{}: {e}", pass.name))
}

/// WGSL `source` (called `name` in errors) after the modules it imports, its parameter
/// blocks bound as `params` says.
pub fn try_compose(
    name: &str,
    source: &str,
    params: ParamsBinding,
) -> Result<String, ResolveError> {
    let wgsl = resolve::resolve(name, source, module)?;
    Ok(match params {
        ParamsBinding::Uniform => wgsl,
        // Software adapters: parameter blocks in storage buffers, and walks that count
        // being cut short by llvmpipe's loop limit (traverse.wgsl's LOOP_CUTS_COUNTED).
        ParamsBinding::Storage => wgsl
            .replace(UNIFORM_DECLARATION, "var<storage, read>")
            .replace(LOOP_CUTS_OFF, LOOP_CUTS_ON),
    })
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
/// 3.9 GB after 3,000 accumulated frames.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ParamsBinding {
    Uniform,
    Storage,
}

/// How WGSL declares a parameter block; [`ParamsBinding::Storage`] rewrites it.
const UNIFORM_DECLARATION: &str = "var<uniform>";

/// traverse.wgsl's switch of the loop-cut counting, off, and as software adapters'
/// shaders have it.
const LOOP_CUTS_OFF: &str = "const LOOP_CUTS_COUNTED: bool = false;";
const LOOP_CUTS_ON: &str = "const LOOP_CUTS_COUNTED: bool = true;";

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
    SOURCES
        .iter()
        .map(|pass| (pass.name, compose(pass)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The software composition turns the loop-cut counting on in every pass that walks
    /// the BVH: the text it replaces is traverse.wgsl's.
    #[test]
    fn software_shaders_count_cut_walks() {
        let traverse = module("traverse").expect("traverse module");
        assert_eq!(traverse.matches(LOOP_CUTS_OFF).count(), 1);
        for pass in SOURCES {
            let gpu = compose_for(pass, ParamsBinding::Uniform);
            let software = compose_for(pass, ParamsBinding::Storage);
            if gpu.contains(LOOP_CUTS_OFF) {
                assert!(
                    software.contains(LOOP_CUTS_ON) && !software.contains(LOOP_CUTS_OFF),
                    "{}",
                    pass.name
                );
            }
            assert!(!gpu.contains(LOOP_CUTS_ON), "{}", pass.name);
        }
    }
}
