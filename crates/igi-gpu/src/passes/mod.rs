//! The passes of the frame (paper section 4), one folder each: its Rust (the pipelines,
//! its typed bindings, the dispatches it records into the frame), its WGSL and, where it
//! computes pixels, a CPU twin. A pass owns its pipelines and the layouts of its bind
//! groups; bind group 0 is always the scene (`scene_buffers.rs`).

pub mod bindings;
pub mod compose;
pub mod direct;
pub mod display;
pub mod filter;
pub mod indirect;
pub mod vpl;

use crate::shader::ParamsBinding;
use crate::switches::Switches;

/// The passes' WGSL sources, kept by the shader module with the modules they import.
pub use crate::shader::{PassSource, SOURCES};

/// The two builds of a gathering pass: VPL shadow rays against triangles, or against
/// the triangles' bounding boxes (imperfect visibility, paper section 4.1). One pipeline
/// each, set by the `IMPERFECT_VISIBILITY` override of gather.wgsl: no branch per ray.
pub(crate) struct GatherPipelines {
    exact: wgpu::ComputePipeline,
    imperfect: wgpu::ComputePipeline,
}

impl GatherPipelines {
    pub(crate) fn new(
        device: &wgpu::Device,
        switches: &Switches,
        name: &str,
        entry: &str,
        layouts: &[&wgpu::BindGroupLayout],
        constants: &[(&str, f64)],
        maps: SurfaceMaps,
    ) -> GatherPipelines {
        let build = |iv: f64| {
            let mut all = vec![("IMPERFECT_VISIBILITY", iv)];
            all.extend_from_slice(constants);
            all.extend_from_slice(&maps.constants());
            pipeline_with_constants(device, switches, name, entry, layouts, &all)
        };
        GatherPipelines {
            exact: build(0.0),
            imperfect: build(1.0),
        }
    }

    pub(crate) fn get(&self, imperfect_visibility: bool) -> &wgpu::ComputePipeline {
        if imperfect_visibility {
            &self.imperfect
        } else {
            &self.exact
        }
    }
}

/// What a scene's materials need of texture.wgsl: the values of its `SURFACE_MAPS` and
/// `ALPHA_MASKS` overrides, which every pass that traces rays (direct, VPL, indirect) is
/// built with. Without them the shaders leave out the code of textures and masks, which
/// slowed the frames of scenes without any and lengthened lavapipe's compiles
/// (docs/lab/textures.md has the figures).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SurfaceMaps {
    /// Textures or vertex colours.
    pub colors: bool,
    /// Alpha-tested materials (every ray tests their masks).
    pub masks: bool,
}

impl SurfaceMaps {
    /// Whether passes built for `self` draw a scene that needs `needed`.
    pub fn covers(self, needed: SurfaceMaps) -> bool {
        (self.colors || !needed.colors) && (self.masks || !needed.masks)
    }

    /// The values of texture.wgsl's overrides.
    pub(crate) fn constants(self) -> [(&'static str, f64); 2] {
        [
            ("SURFACE_MAPS", f64::from(u8::from(self.colors))),
            ("ALPHA_MASKS", f64::from(u8::from(self.masks))),
        ]
    }

    pub fn of(scene: &igi_core::scene::Scene) -> SurfaceMaps {
        let m = &scene.materials;
        SurfaceMaps {
            colors: m.iter().any(|m| m.uses_attributes()),
            masks: m.iter().any(|m| m.alpha_tested()),
        }
    }
}

/// VPL lanes per pixel the indirect pass is built for: `main` (one) and `main_coherent`
/// (more: a warp holds one lane of 32 pixels of one interleaving subset).
pub const LANE_CHOICES: [u32; 4] = [1, 4, 8, 16];

/// Lanes per pixel of the indirect pass at the mirrored hits (the mirror indirect stage,
/// over the list of those pixels): few pixels see a mirror, so their VPL loops are split
/// over 4 threads to fill the GPU; one lane on a software adapter. 4 measured best on
/// the H200 once the gathers ran side by side (docs/lab/PERFORMANCE.md keeps the
/// comparison with 1 to 32). `IGI_MIRROR_LANES` overrides it ([`Switches`]).
pub fn mirror_lanes(software: bool, switches: &Switches) -> u32 {
    if let Some(l) = switches.mirror_lanes {
        return l;
    }
    if software {
        1
    } else {
        4
    }
}

/// Below this many pixels of the indirect term each pixel's VPLs are split over 8 lanes
/// (`main_coherent`, a warp holding one lane of 32 pixels of one interleaving subset),
/// from it on over 4: more lanes fill the GPU when there are few pixels, fewer lanes
/// waste less of a warp's work when there are many. The threshold sits between the two
/// sizes measured on the H200 where 4 and 8 lanes trade places, so that the worse choice
/// there costs least (docs/lab/PERFORMANCE.md has the table). One lane per pixel (`main`,
/// 8 x 8 pixels a workgroup, not grouped by subset) loses everywhere on a GPU, and 2
/// lanes never win, so the pass is not built for them. Small images that are not
/// interleaved take 16 lanes (see [`LANES_16_MAX_PIXELS`]). `IGI_VPL_LANES` overrides
/// the choice ([`Switches`]).
pub const LANES_BELOW_PIXELS: u32 = 200_000;

/// Up to this many pixels of an indirect term that is not interleaved (every pixel
/// gathers every VPL), each pixel's VPLs are split over 16 lanes: so few pixels leave a
/// GPU idle with fewer. Interleaved terms gather a fraction of the VPLs per pixel and
/// lose with 16 lanes.
pub const LANES_16_MAX_PIXELS: u32 = 65_536;

/// The lanes a gathering pass uses over `pixels` pixels, `interleaved` or not; always one
/// on a software adapter, which has few threads to fill and whose workgroup barriers are
/// slow.
pub fn lanes_for(pixels: u32, interleaved: bool, software: bool, switches: &Switches) -> u32 {
    if let Some(l) = switches.vpl_lanes {
        return l;
    }
    if software {
        1
    } else if !interleaved && pixels <= LANES_16_MAX_PIXELS {
        16
    } else if pixels < LANES_BELOW_PIXELS {
        8
    } else {
        4
    }
}

/// A gathering pass built for each entry of [`LANE_CHOICES`]: entry point `main` (one
/// thread per pixel, 8 x 8 per workgroup) and `main_coherent` (n lanes per pixel, 32 n
/// threads per workgroup), each with and without imperfect visibility.
pub(crate) struct LanePipelines {
    by_lanes: Vec<GatherPipelines>,
}

impl LanePipelines {
    pub(crate) fn new(
        device: &wgpu::Device,
        switches: &Switches,
        name: &str,
        layouts: &[&wgpu::BindGroupLayout],
        maps: SurfaceMaps,
    ) -> LanePipelines {
        LanePipelines {
            by_lanes: LANE_CHOICES
                .iter()
                .map(|&lanes| {
                    if lanes == 1 {
                        GatherPipelines::new(device, switches, name, "main", layouts, &[], maps)
                    } else {
                        let constants = [("COHERENT_LANES", lanes as f64)];
                        GatherPipelines::new(
                            device,
                            switches,
                            name,
                            "main_coherent",
                            layouts,
                            &constants,
                            maps,
                        )
                    }
                })
                .collect(),
        }
    }

    /// The dispatch over `width` x `height` pixels with `lanes` lanes per pixel (one of
    /// [`LANE_CHOICES`]), interleaved in tiles of `interleave` pixels.
    pub(crate) fn step(
        &self,
        width: u32,
        height: u32,
        imperfect_visibility: bool,
        lanes: u32,
        interleave: (u32, u32),
    ) -> Step<'_> {
        let index = LANE_CHOICES.iter().position(|&l| l == lanes).unwrap_or(0);
        let pipeline = self.by_lanes[index].get(imperfect_visibility);
        if lanes > 1 {
            // main_coherent: 8 x 4 interleaving tiles per workgroup, one subset each.
            let (n, m) = (interleave.0.max(1), interleave.1.max(1));
            (
                pipeline,
                [width.div_ceil(8 * n), height.div_ceil(4 * m), n * m],
            )
        } else {
            // main: 8 x 8 pixels per workgroup.
            (pipeline, image_groups(width, height))
        }
    }
}

/// Workgroup edge of the image passes (8 x 8 threads).
pub const TILE: u32 = 8;

/// What wgpu checks at run time in the pass shaders: everything it checks by default
/// except index bounds and loop bounding, which cost every BVH walk several per cent on
/// a GPU (docs/lab/PERFORMANCE.md has the figures). `IGI_SHADER_CHECKS=1` restores wgpu's
/// defaults, to look for a bug or to measure ([`Switches`]).
///
/// What the pass shaders promise instead:
/// * Every loop ends. Loops count up to a frame parameter or a count of a buffer, in steps
///   of at least 1 (lanes and strides are 1 or more); the Halton digit loop ends within 32
///   steps (its reach grows by the base, at least 2); the BVH walks visit each node at
///   most once, because the nodes form a tree (built by `igi_core::bvh`, whose tests walk
///   it). With wgpu's loop bound a loop that did not end would end early with a wrong
///   result; without it, it hangs the GPU. Both are bugs, which the tests would show.
/// * Every index into a function or workgroup array is in bounds: the traversal stack
///   holds at most `STACK_SIZE` = `igi_core::bvh::MAX_DEPTH` entries (proved at
///   `MAX_DEPTH`, checked by a test), the irregular pattern's permutation has n x m <= 64
///   entries (the frame refuses larger interleaving), the Halton tables are indexed
///   modulo 64, and the workgroup sums by invocation indices below the workgroup size.
///   Storage buffers stay bounds-checked by the device itself on Vulkan (robust buffer
///   access, which wgpu enables where the device has it).
pub const TRUSTED_CHECKS: wgpu::ShaderRuntimeChecks = {
    let mut checks = wgpu::ShaderRuntimeChecks::checked();
    checks.bounds_checks = false;
    checks.force_loop_bounding = false;
    checks
};

/// A compute pipeline for `entry` of the named pass; `layouts` are its bind groups in
/// order (the scene first).
pub(crate) fn pipeline(
    device: &wgpu::Device,
    switches: &Switches,
    name: &str,
    entry: &str,
    layouts: &[&wgpu::BindGroupLayout],
) -> wgpu::ComputePipeline {
    pipeline_with_constants(device, switches, name, entry, layouts, &[])
}

/// [`pipeline`] with values for the shader's pipeline-overridable constants.
pub(crate) fn pipeline_with_constants(
    device: &wgpu::Device,
    switches: &Switches,
    name: &str,
    entry: &str,
    layouts: &[&wgpu::BindGroupLayout],
    constants: &[(&str, f64)],
) -> wgpu::ComputePipeline {
    let source = SOURCES.iter().find(|s| s.name == name).expect("known pass");
    let desc = wgpu::ShaderModuleDescriptor {
        label: Some(name),
        source: wgpu::ShaderSource::Wgsl(
            crate::shader::compose_for(source, ParamsBinding::of(device)).into(),
        ),
    };
    let module = if switches.shader_checks {
        device.create_shader_module(desc)
    } else {
        // SAFETY: the pass shaders keep the two promises that wgpu's own checks would
        // otherwise enforce (see `TRUSTED_CHECKS`).
        unsafe { device.create_shader_module_trusted(desc, TRUSTED_CHECKS) }
    };
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(name),
        bind_group_layouts: &layouts.iter().map(|l| Some(*l)).collect::<Vec<_>>(),
        immediate_size: 0,
    });
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(name),
        layout: Some(&layout),
        module: &module,
        entry_point: Some(entry),
        compilation_options: wgpu::PipelineCompilationOptions {
            constants,
            ..Default::default()
        },
        cache: None,
    })
}

/// Byte stride of the VPL ranges in the gather-range buffer (the dynamic-offset alignment).
pub const GATHER_RANGE_STRIDE: u64 = 256;

crate::bindings! {
    /// Bind group 2 of the gathering passes (gather.wgsl): one VPL range of the frame's
    /// range buffer, chosen by dynamic offset.
    pub struct GatherRangeBindings {
        gather_range: Params,
    }
}

/// The layout of bind group 2 of gathering passes: one VPL range, by dynamic offset.
pub fn gather_range_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    use bindings::Bindings;
    let range = GatherRangeBindings::BINDINGS[0];
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("gather range"),
        entries: &[wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: range.access.buffer_type(ParamsBinding::of(device)),
                has_dynamic_offset: true,
                min_binding_size: wgpu::BufferSize::new(16),
            },
            count: None,
        }],
    })
}

/// Some entries of a frame's gather-range buffer (bind group 2 of the gathering passes):
/// `count` dispatches, from entry `first` on.
#[derive(Clone, Copy)]
pub struct GatherRanges<'a> {
    pub bind_group: &'a wgpu::BindGroup,
    pub first: u32,
    pub count: u32,
}

/// A dispatch: a pipeline and its workgroup counts.
pub type Step<'a> = (&'a wgpu::ComputePipeline, [u32; 3]);

/// Workgroups covering a width x height image with TILE x TILE groups.
pub fn image_groups(width: u32, height: u32) -> [u32; 3] {
    [width.div_ceil(TILE), height.div_ceil(TILE), 1]
}

/// Every bind group a shader declares besides the scene's, with its typed bindings: what
/// `tests/bindings.rs` checks against each shader's WGSL.
pub fn declared_groups() -> Vec<bindings::GroupDecl> {
    use bindings::{Bindings, GroupDecl};
    let group = |shader, group, bindings| GroupDecl {
        shader,
        group,
        bindings,
    };
    vec![
        group("vpl", 1, vpl::VplBindings::BINDINGS),
        group("direct", 1, direct::DirectBindings::BINDINGS),
        group("direct", 2, GatherRangeBindings::BINDINGS),
        group("indirect", 1, indirect::IndirectBindings::BINDINGS),
        group("indirect", 2, GatherRangeBindings::BINDINGS),
        group("indirect", 3, indirect::MirrorListBindings::BINDINGS),
        group("filter", 1, filter::FilterBindings::BINDINGS),
        group("compose", 1, compose::ComposeBindings::BINDINGS),
        group("display", 1, display::DisplayBindings::BINDINGS),
        group("rays", 1, crate::raybench::RayBindings::BINDINGS),
        group("rays_refill", 1, crate::raybench::RefillBindings::BINDINGS),
    ]
}
