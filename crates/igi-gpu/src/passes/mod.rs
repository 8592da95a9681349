//! The passes of the frame (paper section 4), one module per stage with its WGSL in
//! `shaders/` beside the shared modules. A pass owns its pipeline and the layout of its
//! bind group 1; bind group 0 is always the scene.

pub mod compose;
pub mod direct;
pub mod display;
pub mod filter;
pub mod indirect;
pub mod vpl;

use crate::profiler::Profiler;
use crate::scene_buffers::{buffer_entry, UNIFORM};
use crate::shader::ParamsBinding;

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
        name: &str,
        entry: &str,
        layouts: &[&wgpu::BindGroupLayout],
        constants: &[(&str, f64)],
    ) -> GatherPipelines {
        let build = |iv: f64| {
            let mut all = vec![("IMPERFECT_VISIBILITY", iv)];
            all.extend_from_slice(constants);
            pipeline_with_constants(device, name, entry, layouts, &all)
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

/// VPL lanes per pixel the indirect pass is built for: `main` (one) and `main_coherent`
/// (more: a warp holds one lane of 32 pixels of one interleaving subset).
pub const LANE_CHOICES: [u32; 4] = [1, 4, 8, 16];

/// Lanes per pixel of the indirect pass at the mirrored hits (the mirror indirect stage,
/// over the list of those pixels): few pixels see a mirror (18000 of 480000 in the
/// conference room), so their VPL loops are split over 4 threads; one lane on a software
/// adapter. 8 beat 32 and 1 on the H200 at 800 x 600 and 1920 x 1080, canonical and
/// interleaved (docs/PERFORMANCE.md, attempts 17 and 26), and 16 was slower in
/// interleaved frames (attempt 51). Since the gathers run side by side, 4 beat 8 by 1.2%
/// in the accelerated frames at both sizes, with canonical the same; 2 and 16 did not
/// (attempt 87). `IGI_MIRROR_LANES` (1, 2, 4, 8, 16 or 32) overrides it, for
/// measurements.
pub fn mirror_lanes(software: bool) -> u32 {
    if let Some(l) = std::env::var("IGI_MIRROR_LANES")
        .ok()
        .and_then(|v| v.parse::<u32>().ok())
    {
        if [1, 2, 4, 8, 16, 32].contains(&l) {
            return l;
        }
    }
    if software {
        1
    } else {
        4
    }
}

/// Below this many pixels of the indirect term each pixel's VPLs are split over 8 lanes
/// (`main_coherent`, a warp holding one lane of 32 pixels of one interleaving subset),
/// from it on over 4. Measured on the H200, conference room, 180 VPLs (docs/PERFORMANCE.md,
/// attempt 37; indirect stage in ms for 1 / 2 / 4 / 8 lanes):
///
/// | indirect term | pixels | 1 | 2 | 4 | 8 |
/// |---|---|---|---|---|---|
/// | iv+ds+il 800 x 600 | 30,000 | 1.19 | 0.47 | 0.296 | **0.262** |
/// | iv+ds 800 x 600 | 30,000 | 7.58 | 3.69 | 2.06 | **1.45** |
/// | iv+ds+il 1920 x 1080 | 129,600 | 1.57 | 0.83 | **0.651** | 0.689 |
/// | iv+ds 1920 x 1080 | 129,600 | 8.91 | 4.95 | 3.55 | **3.28** |
/// | canonical 800 x 600 | 480,000 | 18.46 | 13.59 | **12.59** | 13.23 |
/// | canonical 1920 x 1080 | 2,073,600 | 48.23 | 49.60 | **46.27** | 49.22 |
///
/// (iv at full resolution behaves like canonical.) The threshold sits between the two
/// sizes measured where 4 and 8 lanes trade places, so that the worse choice there costs
/// least (0.04 ms at iv+ds+il 1080p). One lane per pixel (`main`, 8 x 8 pixels a
/// workgroup, not grouped by subset) loses everywhere on a GPU, and 2 lanes never win,
/// so the pass is not built for them. Small images that are not interleaved take 16
/// lanes (see [`LANES_16_MAX_PIXELS`]). `IGI_VPL_LANES` (1, 4, 8 or 16) overrides the
/// choice, for measurements.
pub const LANES_BELOW_PIXELS: u32 = 200_000;

/// Up to this many pixels of an indirect term that is not interleaved (every pixel
/// gathers every VPL), each pixel's VPLs are split over 16 lanes. Indirect stage in ms on
/// the H200, conference room, imperfect visibility and downsampling by 4, for 8 / 16
/// lanes (docs/PERFORMANCE.md attempt 51):
///
/// | indirect term | pixels | 30 VPLs | 90 VPLs | 180 VPLs |
/// |---|---|---|---|---|
/// | 800 x 600 | 30,000 | 0.294 / **0.245** | 0.628 / **0.562** | 1.305 / **1.143** |
/// | 1280 x 720 | 57,600 | **0.382** / 0.389 | 0.922 / **0.886** | 1.910 / **1.692** |
/// | 1920 x 1080 | 129,600 | | | **3.04** / 3.33 |
///
/// Interleaved terms gather a ninth as many VPLs per pixel (3 x 3 subsets) and lose with
/// 16 lanes: 0.267 / 0.322 ms at 800 x 600, 0.616 / 0.887 at 1920 x 1080.
pub const LANES_16_MAX_PIXELS: u32 = 65_536;

/// The lanes a gathering pass uses over `pixels` pixels, `interleaved` or not; always one
/// on a software adapter, which has few threads to fill and whose workgroup barriers are
/// slow.
pub fn lanes_for(pixels: u32, interleaved: bool, software: bool) -> u32 {
    if let Some(l) = std::env::var("IGI_VPL_LANES")
        .ok()
        .and_then(|v| v.parse::<u32>().ok())
    {
        if LANE_CHOICES.contains(&l) {
            return l;
        }
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
        name: &str,
        layouts: &[&wgpu::BindGroupLayout],
    ) -> LanePipelines {
        LanePipelines {
            by_lanes: LANE_CHOICES
                .iter()
                .map(|&lanes| {
                    if lanes == 1 {
                        GatherPipelines::new(device, name, "main", layouts, &[])
                    } else {
                        let constants = [("COHERENT_LANES", lanes as f64)];
                        GatherPipelines::new(device, name, "main_coherent", layouts, &constants)
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

/// The layout of a pass's bind group 1: binding i has type `types[i]`.
pub(crate) fn pass_layout(
    device: &wgpu::Device,
    label: &str,
    types: &[wgpu::BufferBindingType],
) -> wgpu::BindGroupLayout {
    // Parameter blocks (UNIFORM) as this device binds them.
    let params = ParamsBinding::of(device).buffer_type();
    let entries: Vec<_> = types
        .iter()
        .enumerate()
        .map(|(i, &ty)| {
            let ty = if ty == UNIFORM { params } else { ty };
            buffer_entry(i as u32, ty)
        })
        .collect();
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &entries,
    })
}

/// What wgpu checks at run time in the pass shaders: everything it checks by default
/// except index bounds and loop bounding, which cost every BVH walk 7-9% on the H200
/// (frame rays 3.50 -> 3.81 G rays/s, iv+ds+il 1.27 -> 1.19 ms at 800 x 600;
/// docs/PERFORMANCE.md attempt 34). `IGI_SHADER_CHECKS=1` restores wgpu's defaults, to
/// look for a bug or to measure.
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
    name: &str,
    entry: &str,
    layouts: &[&wgpu::BindGroupLayout],
) -> wgpu::ComputePipeline {
    pipeline_with_constants(device, name, entry, layouts, &[])
}

/// [`pipeline`] with values for the shader's pipeline-overridable constants.
pub(crate) fn pipeline_with_constants(
    device: &wgpu::Device,
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
    let module = if std::env::var_os("IGI_SHADER_CHECKS").is_some_and(|v| v == "1") {
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

/// A bind group whose binding i is the whole of `buffers[i]`.
pub(crate) fn bind(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    buffers: &[&wgpu::Buffer],
) -> wgpu::BindGroup {
    let entries: Vec<_> = buffers
        .iter()
        .enumerate()
        .map(|(i, b)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource: b.as_entire_binding(),
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &entries,
    })
}

/// Byte stride of the VPL ranges in the gather-range buffer (the dynamic-offset alignment).
pub const GATHER_RANGE_STRIDE: u64 = 256;

/// The layout of bind group 2 of gathering passes: one VPL range, by dynamic offset.
pub fn gather_range_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("gather range"),
        entries: &[wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: ParamsBinding::of(device).buffer_type(),
                has_dynamic_offset: true,
                min_binding_size: wgpu::BufferSize::new(16),
            },
            count: None,
        }],
    })
}

/// Some entries of a frame's gather-range buffer (bind group 2 of the gathering passes):
/// `count` dispatches, from entry `first` on.
pub struct GatherRanges<'a> {
    pub bind_group: &'a wgpu::BindGroup,
    pub first: u32,
    pub count: u32,
}

/// A dispatch: a pipeline and its workgroup counts.
pub type Step<'a> = (&'a wgpu::ComputePipeline, [u32; 3]);

/// What one compute pass runs for one pass of the frame: each step's pipeline over its
/// workgroups, with the scene's and the pass's bind groups; with `ranges`, every step runs
/// once per VPL range (bind group 2).
pub(crate) struct Dispatches<'a> {
    pub steps: &'a [Step<'a>],
    pub scene: &'a wgpu::BindGroup,
    pub pass: &'a wgpu::BindGroup,
    pub ranges: Option<&'a GatherRanges<'a>>,
    /// Bind group 3, for the pipelines that have one.
    pub group3: Option<&'a wgpu::BindGroup>,
}

/// The dispatches of several passes in one compute pass (one timestamp pair), run side by
/// side: wgpu records each compute pass into a command buffer of its own, and the GPU
/// does not run work of two command buffers at once (measured on the H200,
/// docs/PERFORMANCE.md attempt 21), while two dispatches of one pass that share no
/// written buffer get no barrier between them (wgpu puts one before a dispatch only when
/// one of its buffers changes state).
pub(crate) fn dispatch_together(
    encoder: &mut wgpu::CommandEncoder,
    profiler: &Profiler,
    stage: u32,
    label: &str,
    parts: &[Dispatches],
) {
    let mut cpass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
        label: Some(label),
        timestamp_writes: profiler.pass_writes(stage),
    });
    record(&mut cpass, parts);
}

fn record(cpass: &mut wgpu::ComputePass, parts: &[Dispatches]) {
    for part in parts {
        cpass.set_bind_group(0, part.scene, &[]);
        cpass.set_bind_group(1, part.pass, &[]);
        if let Some(g) = part.group3 {
            cpass.set_bind_group(3, g, &[]);
        }
        for (pipeline, groups) in part.steps {
            cpass.set_pipeline(pipeline);
            let run = |cpass: &mut wgpu::ComputePass| {
                cpass.dispatch_workgroups(groups[0], groups[1], groups[2])
            };
            match part.ranges {
                None => run(cpass),
                Some(r) => {
                    for i in r.first..r.first + r.count {
                        let offset = (i as u64 * GATHER_RANGE_STRIDE) as u32;
                        cpass.set_bind_group(2, r.bind_group, &[offset]);
                        run(cpass);
                    }
                }
            }
        }
    }
}

/// Where a frame's stages are recorded: all in one compute pass, with the stages'
/// timestamps written inside it (one between two stages: `Profiler::set_chained`), where
/// the device can (or where nothing is timed), else one compute pass per stage, with a
/// timestamp pair each. wgpu turns every compute pass into command buffers
/// of its own, and on the H200 each boundary cost a few microseconds of idle GPU
/// (docs/PERFORMANCE.md, attempt 25); inside one pass wgpu still puts a barrier before
/// every dispatch that needs one. `IGI_STAGE_PASSES=1` forces a pass per stage, for
/// measurements.
pub(crate) struct Recorder<'a> {
    encoder: &'a mut wgpu::CommandEncoder,
    profiler: &'a Profiler,
    /// The frame's one compute pass, when stages share one.
    pass: Option<wgpu::ComputePass<'static>>,
}

impl<'a> Recorder<'a> {
    pub(crate) fn new(
        encoder: &'a mut wgpu::CommandEncoder,
        profiler: &'a Profiler,
        label: &str,
    ) -> Recorder<'a> {
        let one_pass = profiler.writes_inside_passes()
            && std::env::var("IGI_STAGE_PASSES").as_deref() != Ok("1");
        profiler.set_chained(one_pass);
        let pass = one_pass.then(|| {
            encoder
                .begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some(label),
                    timestamp_writes: None,
                })
                .forget_lifetime()
        });
        Recorder {
            encoder,
            profiler,
            pass,
        }
    }

    /// Stage `stage`: the dispatches of `parts`, between its two timestamps.
    pub(crate) fn stage(&mut self, stage: u32, label: &str, parts: &[Dispatches]) {
        match &mut self.pass {
            Some(cpass) => {
                // Stages follow each other: one's end is the next one's start.
                if stage == 0 {
                    self.profiler.write_inside(cpass, 0);
                }
                cpass.push_debug_group(label);
                record(cpass, parts);
                cpass.pop_debug_group();
                self.profiler.write_inside(cpass, 2 * stage + 1);
            }
            None => dispatch_together(self.encoder, self.profiler, stage, label, parts),
        }
    }

    /// The dispatches of several passes that depend on none of each other, side by side
    /// in one stage called `name` (each part in a stage of its own, under its own name,
    /// with `IGI_SIDE_BY_SIDE=0`, for measurements). `stage` numbers the stages.
    ///
    /// wgpu puts a barrier before a dispatch when one of its buffers changes state, and
    /// also when it binds read-write a buffer that an earlier dispatch of the frame bound
    /// read-write (whether or not either writes it). A barrier waits for every dispatch
    /// before it, so one before the second part would run the parts one after the other
    /// (measured on the H200: docs/PERFORMANCE.md attempt 65). So the parts after the
    /// first must bind only buffers that are either read-only in the state the frame
    /// left them in, or put in that state here (`ready`: transitions
    /// before the stage, where a barrier is due anyway), or bound read-write for the first
    /// time in the frame: their outputs, and spare ray counters
    /// (`SceneBuffers::beside_bind_groups`).
    pub(crate) fn side_by_side(
        &mut self,
        stage: &mut dyn FnMut(&'static str) -> u32,
        name: &'static str,
        ready: &[wgpu::BufferTransition<&wgpu::Buffer>],
        parts: Vec<(&'static str, Dispatches)>,
    ) {
        let together = std::env::var("IGI_SIDE_BY_SIDE").as_deref() != Ok("0");
        if together && parts.len() > 1 {
            if let Some(cpass) = &mut self.pass {
                cpass.transition_resources(
                    ready.iter().map(|t| wgpu::BufferTransition {
                        buffer: t.buffer,
                        state: t.state,
                    }),
                    std::iter::empty(),
                );
            }
            let (_, parts): (Vec<_>, Vec<_>) = parts.into_iter().unzip();
            let i = stage(name);
            self.stage(i, name, &parts);
        } else {
            for (name, part) in parts {
                let i = stage(name);
                self.stage(i, name, &[part]);
            }
        }
    }

    /// Stage `stage` with one pass's dispatches (see [`Dispatches`]).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn dispatch(
        &mut self,
        stage: u32,
        label: &str,
        steps: &[Step],
        scene: &wgpu::BindGroup,
        pass: &wgpu::BindGroup,
        ranges: Option<&GatherRanges>,
    ) {
        self.stage(
            stage,
            label,
            &[Dispatches {
                steps,
                scene,
                pass,
                ranges,
                group3: None,
            }],
        );
    }
}

/// Workgroups covering a width x height image with TILE x TILE groups.
pub fn image_groups(width: u32, height: u32) -> [u32; 3] {
    [width.div_ceil(TILE), height.div_ceil(TILE), 1]
}
