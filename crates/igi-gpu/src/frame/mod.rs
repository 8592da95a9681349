//! The frame (paper section 4). [`Renderer`] owns the scene on the GPU, the passes and
//! the frame's buffers; `listing.rs` lists a frame's passes in order (VPL shooting,
//! direct and specular, the indirect gathers, the filters, compose), `recorder.rs` groups them
//! into stages (those that depend on none of each other side by side) and encodes them,
//! each stage timed by GPU timestamps, and `resources.rs` declares every buffer once.
//! Nothing is read back inside a frame.

mod listing;
mod params;
mod passes;
pub(crate) mod recorder;
pub mod resources;
mod shadow_rays;
mod walks;

pub(crate) use listing::FrameShape;
pub use listing::{filter_chain, low_resolution};
pub use passes::Passes;

use crate::context::{GpuContext, GpuError};
use crate::layout::{FrameParams, Vpl};
use crate::passes::compose::ComposePass;
use crate::passes::direct::{DirectPass, CHAIN_WORKGROUPS};
use crate::passes::display::DisplayInputs;
use crate::passes::filter::FilterPass;
use crate::passes::indirect::{IndirectPass, LIST_WORKGROUPS};
use crate::passes::vpl::VplPass;
use crate::passes::{SurfaceMaps, GATHER_RANGE_STRIDE};
use crate::profiler::{Profiler, StageTime};
use crate::scene_buffers::SceneBuffers;
use crate::shader::ParamsBinding;
use crate::switches::Switches;
use igi_core::bvh::Bvh;
use igi_core::image::Image;
use igi_core::sampling::{halton_base, DigitPermutations};
use igi_core::scene::{Camera, PointLight, Scene};
use igi_core::settings::{RenderSettings, SettingsError, MAX_MIRROR_DEPTH};
use igi_core::trace_scale::TraceScale;
use resources::{Buf, FrameBuffers};

/// Most stages a frame can have: every pass in a stage of its own (`IGI_SIDE_BY_SIDE=0`)
/// with mirrors and compaction: VPL shooting, VPL list, direct, mirror chains, mirror
/// indirect, indirect, filter, mirror discontinuity, compose. Each stage has its
/// timestamp pair.
pub const MAX_STAGES: u32 = 9;

/// Light paths of the pilot run that estimates VPLs per path.
pub const PILOT_PATHS: u32 = 4096;

/// What one frame produced.
#[derive(Clone, Debug)]
pub struct FrameOutput {
    /// Linear radiance of the chosen output buffer.
    pub image: Image,
    /// VPLs actually stored this frame.
    pub vpl_count: u32,
    /// Light paths shot to get them.
    pub path_count: u32,
    /// GPU time per stage (empty without timestamp queries).
    pub stages: Vec<StageTime>,
    /// GPU time from the first stage's start to the last one's end.
    pub frame_ms: Option<f64>,
}

/// Accumulated frames submitted ahead of the one the GPU runs
/// ([`Renderer::render_with_progress`]): enough that the GPU always has the next. On
/// lavapipe, whose work runs on the CPU's cores, one ahead left the cores idle between
/// frames; four ahead measured as fast as submitting every frame at once.
pub const FRAMES_IN_FLIGHT: usize = 4;

pub struct Renderer {
    scene: SceneBuffers,
    switches: Switches,
    /// What its passes were built to draw ([`Passes::for_maps`]).
    maps: SurfaceMaps,
    vpl: VplPass,
    direct: DirectPass,
    indirect: IndirectPass,
    filter: FilterPass,
    compose: ComposePass,
    profiler: Profiler,
    /// Every buffer of the frame (see `resources.rs`).
    buffers: FrameBuffers,
    /// The most workgroups of the mirror gather and of the direct pass's later walks,
    /// which stride over lists whose lengths only the GPU knows
    /// ([`crate::passes::indirect::LIST_WORKGROUPS`],
    /// [`crate::passes::direct::CHAIN_WORKGROUPS`]).
    list_grids: (u32, u32),
    /// The scrambled Halton sequence's digit permutations, for the seed they were made for.
    halton_perms: (u32, wgpu::Buffer),
    /// Bind group 2 of the gathering passes: the VPL ranges of one frame.
    range_layout: wgpu::BindGroupLayout,
    range_buffer: Option<(wgpu::Buffer, wgpu::BindGroup, u32)>,
    vpls_per_dispatch: u32,
    /// In the scene's coordinates (what the caller sets); the frame's parameters have it
    /// in trace coordinates.
    camera: Camera,
    /// Scene coordinates to the coordinates the GPU traces in (see
    /// [`igi_core::trace_scale`]); the figures below are in trace coordinates.
    scale: TraceScale,
    /// See [`light_powers`].
    light_power_sum: f32,
    total_power: [f32; 3],
    diagonal: f32,
    /// The scene's [`igi_core::bvh::offset_floor`] (params.ray_offset_floor).
    ray_offset_floor: f32,
    /// Paths per frame for (seed, vpls, bounces, mirror depth), from the pilot run.
    path_cache: Option<((u32, u32, u32, u32), u32)>,
    /// Whether any material has a mirror part (else the mirror stage is skipped).
    has_mirrors: bool,
    /// Whether the adapter is a software one (see `passes::lanes_for`).
    software: bool,
    /// Whether the next frame counts its rays (see [`Renderer::count_rays`]).
    counting: bool,
    /// The parameters of the last submitted frame.
    last_params: Option<FrameParams>,
    /// Where `check_walks` gathers the counts of walks cut short (software adapters).
    cut_walks: Option<wgpu::Buffer>,
}

fn permutation_buffer(ctx: &GpuContext, seed: u32) -> wgpu::Buffer {
    wgpu::util::DeviceExt::create_buffer_init(
        &ctx.device,
        &wgpu::util::BufferInitDescriptor {
            label: Some("halton permutations"),
            contents: bytemuck::cast_slice(&DigitPermutations::new(seed).table),
            usage: wgpu::BufferUsages::STORAGE,
        },
    )
}

impl Renderer {
    /// Digit permutations for `seed` on the GPU (made again only when the seed changes).
    fn ensure_permutations(&mut self, ctx: &GpuContext, seed: u32) {
        if self.halton_perms.0 != seed {
            self.halton_perms = (seed, permutation_buffer(ctx, seed));
        }
    }

    /// Upload the scene and its BVH, and build the passes.
    pub fn new(ctx: &GpuContext, scene: &Scene, bvh: &Bvh) -> Result<Renderer, GpuError> {
        let maps = SurfaceMaps::of(scene);
        Renderer::with_passes(
            ctx,
            Passes::for_maps(ctx, Switches::from_env(), maps),
            scene,
            bvh,
        )
    }

    /// Upload the scene and its BVH for passes made before (see [`Passes`]).
    pub fn with_passes(
        ctx: &GpuContext,
        passes: Passes,
        scene: &Scene,
        bvh: &Bvh,
    ) -> Result<Renderer, GpuError> {
        let device = &ctx.device;
        // Passes built without the code of what this scene's materials use are built
        // again with it.
        let needed = SurfaceMaps::of(scene);
        let passes = if passes.maps.covers(needed) {
            passes
        } else {
            Passes::for_maps(ctx, passes.switches, needed)
        };
        let Passes {
            switches,
            scene_layout,
            range_layout,
            vpl,
            direct,
            indirect,
            filter,
            compose,
            maps,
        } = passes;
        // One pass over the triangles for the scene's size and its trace scale.
        let (lo, hi) = scene.bounds();
        let scale = TraceScale::for_bounds(lo, hi);
        let scaled_bvh;
        let traced_bvh = if scale.is_one() {
            bvh
        } else {
            log::info!(
                "{}: traced at {} times its size (igi_core::trace_scale)",
                scene.source,
                scale.factor
            );
            scaled_bvh = bvh.scaled(scale.factor);
            &scaled_bvh
        };
        let scene_buffers = SceneBuffers::upload_with(ctx, scene_layout, scene, traced_bvh, scale)?;
        warn_large_min_dist(scene, igi_core::scene::diagonal_of(lo, hi));
        let (lo, hi) = (scale.point(lo), scale.point(hi));
        let (light_power_sum, total_power) = light_powers(&scene.lights, scale);
        check_light_power(light_power_sum, scale)?;
        let params_usage = ParamsBinding::of(device).usage() | wgpu::BufferUsages::COPY_DST;
        let renderer = Renderer {
            switches,
            maps,
            vpl,
            direct,
            indirect,
            range_layout,
            range_buffer: None,
            vpls_per_dispatch: ctx.vpls_per_dispatch(),
            filter,
            compose,
            scene: scene_buffers,
            profiler: Profiler::new(ctx, MAX_STAGES),
            buffers: FrameBuffers::new(device, params_usage),
            list_grids: (LIST_WORKGROUPS, CHAIN_WORKGROUPS),
            halton_perms: (0, permutation_buffer(ctx, 0)),
            camera: scene.camera,
            scale,
            light_power_sum,
            total_power,
            diagonal: igi_core::scene::diagonal_of(lo, hi),
            ray_offset_floor: igi_core::bvh::offset_floor(lo, hi),
            path_cache: None,
            counting: false,
            last_params: None,
            cut_walks: None,
            software: ctx.is_software(),
            has_mirrors: scene.materials.iter().any(|m| m.mirror.max_element() > 0.0),
        };
        ctx.check()?;
        Ok(renderer)
    }

    /// The renderer's passes back, for the next scene's renderer ([`Renderer::with_passes`]):
    /// a command that renders several scenes makes the pipelines once.
    pub fn into_passes(self) -> Passes {
        Passes {
            switches: self.switches,
            maps: self.maps,
            scene_layout: self.scene.layout,
            range_layout: self.range_layout,
            vpl: self.vpl,
            direct: self.direct,
            indirect: self.indirect,
            filter: self.filter,
            compose: self.compose,
        }
    }

    /// The most workgroups of the mirror gather and of the direct pass's later walks
    /// from the next frame on (at least one per bucket): fewer than the lists need make
    /// each workgroup take several parts of its list, which is what a larger image does
    /// with the defaults; for tests of that path and for measurements.
    pub fn set_list_grids(&mut self, mirror_gather: u32, chain_walks: u32) {
        self.list_grids = (mirror_gather, chain_walks);
    }

    /// Look through `camera` from the next frame on.
    pub fn set_camera(&mut self, camera: Camera) {
        self.camera = camera;
    }

    /// The camera of the next frame.
    pub fn camera(&self) -> Camera {
        self.camera
    }

    /// Replace the point lights (same number as the scene's: the viewer moves and dims
    /// them) from the next frame on. VPLs are shot again every frame, so indirect light
    /// follows at once; the path count is measured again for the new lights.
    pub fn set_lights(&mut self, ctx: &GpuContext, lights: &[PointLight]) -> Result<(), GpuError> {
        if lights.len() as u32 != self.scene.light_count {
            return Err(GpuError::Limit(format!(
                "{} lights given, the scene on the GPU has {}",
                lights.len(),
                self.scene.light_count
            )));
        }
        let (sum, total) = light_powers(lights, self.scale);
        check_light_power(sum, self.scale)?;
        let gpu = crate::scene_buffers::gpu_lights(lights, self.scale);
        ctx.queue
            .write_buffer(&self.scene.lights, 0, bytemuck::cast_slice(&gpu));
        (self.light_power_sum, self.total_power) = (sum, total);
        self.path_cache = None;
        Ok(())
    }

    /// What the viewer's display pass reads: the colour buffer of the last frame and its
    /// VPLs (`None` before the first frame).
    pub fn display_inputs(&self) -> Option<DisplayInputs<'_>> {
        let b = &self.buffers;
        let ((width, height), slots) = (b.image_size()?, b.vpl_slots()?);
        Some(DisplayInputs {
            params: b.get(Buf::Params),
            color: b.get(Buf::Color),
            vpls: b.get(Buf::Vpls),
            vpl_header: b.get(Buf::VplHeader),
            width,
            height,
            vpl_slots: slots.min(u32::MAX as u64) as u32,
        })
    }

    /// The image size of the last frame, or an error before the first.
    fn rendered_size(&self) -> Result<(u32, u32), GpuError> {
        self.buffers
            .image_size()
            .ok_or_else(|| GpuError::Device("no frame rendered yet".into()))
    }

    /// The colour buffer of the last submitted frame (waits for it).
    pub fn read_image(&self, ctx: &GpuContext) -> Result<Image, GpuError> {
        let (width, height) = self.rendered_size()?;
        let rgba: Vec<[f32; 4]> = ctx.read_buffer(self.buffers.get(Buf::Color))?;
        let pixels = width as usize * height as usize;
        Ok(Image::from_rgba(width, height, &rgba[..pixels]))
    }

    /// One of the last frame's per-pixel buffers by its label (waits for it), as many
    /// RGBA values as the image has pixels (buffers at the indirect term's resolution use
    /// the first [`low_resolution`] of them): any label of `resources::DECLARATIONS`
    /// sized by the image ("gbuffer position", "irradiance", "color", ...). For the tests
    /// of the passes' CPU twins.
    pub fn read_frame_buffer(
        &self,
        ctx: &GpuContext,
        label: &str,
    ) -> Result<Vec<[f32; 4]>, GpuError> {
        let (width, height) = self.rendered_size()?;
        let per_pixel = resources::DECLARATIONS
            .iter()
            .any(|d| d.label == label && d.size == resources::Size::Pixels);
        let buffer = self
            .buffers
            .by_label(label)
            .filter(|_| per_pixel)
            .ok_or_else(|| GpuError::Device(format!("no frame buffer called {label:?}")))?;
        let mut values: Vec<[f32; 4]> = ctx.read_buffer(buffer)?;
        values.truncate(width as usize * height as usize);
        Ok(values)
    }

    /// The parameter block of the last submitted frame (its passes over the mirrored hits
    /// read [`FrameParams::at_full_resolution`] of it); `None` before the first frame.
    pub fn last_params(&self) -> Option<FrameParams> {
        self.last_params
    }

    /// VPLs stored by the last submitted frame (waits for it).
    pub fn vpl_count(&self, ctx: &GpuContext) -> Result<u32, GpuError> {
        let header: Vec<u32> = ctx.read_buffer(self.buffers.get(Buf::VplHeader))?;
        Ok(header[0])
    }

    /// The lengths of the direct pass's lists in the last frame (waits for it): the
    /// counts of the mirrored-pixel buckets, then the count of listed chains.
    pub fn list_counters(&self, ctx: &GpuContext) -> Result<Vec<u32>, GpuError> {
        self.rendered_size()?;
        let mirror: Vec<u32> = ctx.read_buffer(self.buffers.get(Buf::MirrorList))?;
        let chain: Vec<u32> = ctx.read_buffer(self.buffers.get(Buf::ChainList))?;
        let mut counters = mirror[..MAX_SUBSETS as usize].to_vec();
        counters.push(chain[0]);
        Ok(counters)
    }

    /// The weight record of the last frame's mirrored hits (waits for it): per pixel the
    /// weight of the first diffuse hit of its mirror chain, w = 1 where there is one.
    pub fn mirror_weights(&self, ctx: &GpuContext) -> Result<Vec<[f32; 4]>, GpuError> {
        self.read_frame_buffer(ctx, resources::declaration(Buf::MirrorWeight).label)
    }

    /// Bytes held on the GPU by the scene.
    pub fn scene_bytes(&self) -> u64 {
        self.scene.bytes
    }

    /// Bytes held on the GPU by the frame's buffers (every buffer of
    /// `resources::DECLARATIONS` made so far).
    pub fn frame_bytes(&self) -> u64 {
        self.buffers.bytes()
    }

    fn check_size(ctx: &GpuContext, settings: &RenderSettings) -> Result<(), GpuError> {
        // igi-core's checks of the size (at least 1, at most MAX_IMAGE_SIDE a side),
        // then this adapter's limit.
        settings
            .validate_size()
            .map_err(|e| GpuError::Limit(e.to_string()))?;
        let (w, h) = (settings.width, settings.height);
        let bytes = w as u64 * h as u64 * 16;
        if bytes > ctx.max_storage_binding() {
            return Err(GpuError::Limit(format!(
                "image size {w}x{h} needs {} MiB per frame buffer, more than this adapter's max_storage_buffer_binding_size of {} MiB",
                bytes >> 20,
                ctx.max_storage_binding() >> 20
            )));
        }
        Ok(())
    }

    /// Dispatches of each gather in the last frame: one per range of the VPL list (see
    /// `submit_frame`).
    pub fn gather_ranges(&self) -> u32 {
        self.range_buffer.as_ref().map_or(0, |r| r.2)
    }

    /// Write the VPL ranges for a frame of `slots` VPL slots (an upper bound of the VPL
    /// count, which only the GPU knows) and return how many there are. Entry 0 is the
    /// direct pass's first walk (no VPLs, `first_walk` = 1), entries 1..=count the ranges.
    fn ensure_ranges(&mut self, ctx: &GpuContext, slots: u64) -> u32 {
        let per = self.vpls_per_dispatch as u64;
        let count = slots.div_ceil(per).max(1) as u32;
        if self
            .range_buffer
            .as_ref()
            .is_none_or(|(_, _, n)| *n != count)
        {
            let stride = GATHER_RANGE_STRIDE as usize;
            let mut bytes = vec![0u8; (count as usize + 1) * stride];
            bytes[..12].copy_from_slice(bytemuck::cast_slice(&[0u32, 0, 1]));
            for i in 0..count as usize {
                let begin = (i as u64 * per).min(u32::MAX as u64) as u32;
                let end = ((i as u64 + 1) * per).min(u32::MAX as u64) as u32;
                let at = (i + 1) * stride;
                bytes[at..at + 12].copy_from_slice(bytemuck::cast_slice(&[begin, end, 0]));
            }
            let buffer = wgpu::util::DeviceExt::create_buffer_init(
                &ctx.device,
                &wgpu::util::BufferInitDescriptor {
                    label: Some("gather ranges"),
                    contents: &bytes,
                    usage: ParamsBinding::of(&ctx.device).usage(),
                },
            );
            let bind_group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("gather ranges"),
                layout: &self.range_layout,
                entries: &[wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: &buffer,
                        offset: 0,
                        size: wgpu::BufferSize::new(16),
                    }),
                }],
            });
            self.range_buffer = Some((buffer, bind_group, count));
        }
        count
    }

    /// Render a frame (or `settings.accumulate` frames averaged, each with a fresh VPL set)
    /// and read its image back; timings are those of the last frame.
    pub fn render(
        &mut self,
        ctx: &GpuContext,
        settings: &RenderSettings,
    ) -> Result<FrameOutput, GpuError> {
        self.render_with_progress(ctx, settings, |_| {})
    }

    /// [`Renderer::render`], calling `progress(k)` once k of the accumulated frames have
    /// run on the GPU, for k = 1 to their number, in order. At most [`FRAMES_IN_FLIGHT`]
    /// frames are submitted ahead: they were all submitted at once before, so a long
    /// accumulation said nothing until its end (3,000 frames on lavapipe: 55 s).
    pub fn render_with_progress(
        &mut self,
        ctx: &GpuContext,
        settings: &RenderSettings,
        mut progress: impl FnMut(u32),
    ) -> Result<FrameOutput, GpuError> {
        Self::check_size(ctx, settings)?;
        let mut names = vec![];
        let mut paths = 0;
        // Each wait, for the oldest submission, is one more frame run.
        let mut done = 0;
        let mut wait = |submission| {
            ctx.wait_for(submission).map(|()| {
                done += 1;
                progress(done);
            })
        };
        let mut in_flight = std::collections::VecDeque::new();
        for k in 0..settings.accumulate.max(1) {
            if in_flight.len() == FRAMES_IN_FLIGHT {
                if let Some(oldest) = in_flight.pop_front() {
                    wait(oldest)?;
                }
            }
            let frame = RenderSettings {
                frame: settings.frame + k,
                ..settings.clone()
            };
            let submission;
            (names, paths, submission) = self.submit_frame_indexed(ctx, &frame, k)?;
            in_flight.push_back(submission);
        }
        for submission in in_flight {
            wait(submission)?;
        }
        self.check_walks(ctx)?;
        let image = self.read_image(ctx)?;
        let vpl_count = self.vpl_count(ctx)?;
        let timing = self.profiler.read(ctx, &names)?;
        ctx.check()?;
        let (stages, frame_ms) = match timing {
            Some((s, span)) => (s, Some(span)),
            None => (vec![], None),
        };
        Ok(FrameOutput {
            image,
            vpl_count,
            path_count: paths,
            stages,
            frame_ms,
        })
    }

    /// GPU times of the last submitted frame's stages `names` (as [`Renderer::submit_frame`]
    /// returned them) and its span; `None` without timestamp queries. Waits for the frame.
    pub fn read_timings(
        &self,
        ctx: &GpuContext,
        names: &[&'static str],
    ) -> Result<Option<(Vec<StageTime>, f64)>, GpuError> {
        self.profiler.read(ctx, names)
    }

    /// Rays traced in one frame of `settings`, by kind: [primary, mirror, light shadow,
    /// VPL shadow, particle]. Renders an extra frame with counting on (one atomic add per
    /// invocation and kind); the timed frames never count.
    pub fn count_rays(
        &mut self,
        ctx: &GpuContext,
        settings: &RenderSettings,
    ) -> Result<[u64; 5], GpuError> {
        ctx.queue
            .write_buffer(&self.scene.ray_counters, 0, &[0u8; 32]);
        self.counting = true;
        let submitted = self.submit_frame(ctx, settings, 0);
        self.counting = false;
        submitted?;
        let counts: Vec<u32> = ctx.read_buffer(&self.scene.ray_counters)?;
        ctx.check()?;
        Ok([0, 1, 2, 3, 4].map(|i| counts[i] as u64))
    }

    /// Encode and submit one frame; `accumulate_index` frames are already averaged into
    /// the colour buffer. Returns the stages it ran, in order, and the light paths shot.
    pub fn submit_frame(
        &mut self,
        ctx: &GpuContext,
        settings: &RenderSettings,
        accumulate_index: u32,
    ) -> Result<(Vec<&'static str>, u32), GpuError> {
        self.submit_frame_indexed(ctx, settings, accumulate_index)
            .map(|(names, paths, _)| (names, paths))
    }

    /// [`Renderer::submit_frame`], with the queue's index of the frame's submission.
    fn submit_frame_indexed(
        &mut self,
        ctx: &GpuContext,
        settings: &RenderSettings,
        accumulate_index: u32,
    ) -> Result<(Vec<&'static str>, u32, wgpu::SubmissionIndex), GpuError> {
        let paths = self.prepare(ctx, settings)?;
        let bounces = settings.bounces.max(1);
        let mut params = self.frame_params(
            settings,
            paths,
            halton_base(settings.seed, settings.frame, paths),
            accumulate_index,
        );
        // The gathers take the VPL list in ranges: one on GPUs, of vpls_per_dispatch on
        // software adapters, where each range is a dispatch of every gather, which costs
        // there even when the range is past the last VPL. So there the frame's VPLs are
        // counted first, by its own VPL pass run alone (the same paths leave the same
        // VPLs when the frame runs it again), and the ranges cover them, not every slot
        // the paths could fill: where most paths leave the scene at once the two differ a
        // hundredfold (a scene of one mirror triangle left 9 VPLs in 1,872 slots).
        let vpls = if self.vpls_per_dispatch == u32::MAX {
            paths as u64 * bounces as u64
        } else {
            self.count_vpls(ctx, &params)? as u64
        };
        self.ensure_ranges(ctx, vpls);
        params.count_rays = self.counting as u32;
        self.last_params = Some(params);
        let b = &self.buffers;
        ctx.queue
            .write_buffer(b.get(Buf::Params), 0, bytemuck::bytes_of(&params));
        if self.has_mirrors {
            let mirror = params.at_full_resolution();
            ctx.queue
                .write_buffer(b.get(Buf::MirrorParams), 0, bytemuck::bytes_of(&mirror));
        }
        if self.has_mirrors {
            self.start_lists(ctx);
        }
        let mut encoder = ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("frame"),
            });
        let passes = self.frame_passes(&ctx.device, settings, paths);
        let names = recorder::record(
            &mut encoder,
            &self.profiler,
            &self.scene,
            &passes,
            &self.switches,
            self.counting,
        );
        drop(passes);
        self.profiler.resolve(&mut encoder, names.len() as u32);
        let submission = ctx.queue.submit([encoder.finish()]);
        Ok((names, paths, submission))
    }

    /// What every frame of `settings` needs before it is recorded: the settings checked,
    /// the light paths counted, the permutations of its seed and the frame's buffers
    /// made. Returns the number of paths.
    fn prepare(&mut self, ctx: &GpuContext, settings: &RenderSettings) -> Result<u32, GpuError> {
        Self::check_size(ctx, settings)?;
        check_settings(settings)?;
        let paths = self.path_count(ctx, settings)?;
        self.ensure_permutations(ctx, settings.seed);
        let slots = paths as u64 * settings.bounces.max(1) as u64;
        self.buffers.ensure_vpl_slots(ctx, slots)?;
        self.buffers
            .ensure_image(ctx, settings.width, settings.height)?;
        Ok(paths)
    }

    /// The stages of a frame of `settings`, in order, each with the passes it runs side
    /// by side (renders nothing; the frame's buffers are made if needed).
    pub fn frame_stages(
        &mut self,
        ctx: &GpuContext,
        settings: &RenderSettings,
    ) -> Result<Vec<(&'static str, Vec<&'static str>)>, GpuError> {
        let paths = self.prepare(ctx, settings)?;
        self.ensure_ranges(ctx, paths as u64 * settings.bounces.max(1) as u64);
        let passes = self.frame_passes(&ctx.device, settings, paths);
        Ok(recorder::stage_names(&passes, &self.switches))
    }

    /// Empties the direct pass's lists for the frame about to be submitted (its direct
    /// pass appends to them). Written with the frame's parameters, before its commands
    /// run; the gathers of the frame before have run by then (queue order).
    fn start_lists(&self, ctx: &GpuContext) {
        let b = &self.buffers;
        ctx.queue
            .write_buffer(b.get(Buf::MirrorList), 0, &[0; 4 * MAX_SUBSETS as usize]);
        ctx.queue.write_buffer(b.get(Buf::ChainList), 0, &[0; 4]);
    }

    /// The VPLs of the last frame (for tests and for drawing them).
    pub fn read_vpls(&self, ctx: &GpuContext) -> Result<Vec<Vpl>, GpuError> {
        let header: Vec<u32> = ctx.read_buffer(self.buffers.get(Buf::VplHeader))?;
        if self.buffers.vpl_slots().is_none() {
            return Ok(vec![]);
        }
        let mut vpls: Vec<Vpl> = ctx.read_buffer(self.buffers.get(Buf::Vpls))?;
        vpls.truncate(header[0] as usize);
        Ok(vpls)
    }
}

/// Warns when the default bounding distance of G (a fraction of the diagonal) is longer
/// than every distance between the camera and what it looks at (its target, the lights):
/// then far-away geometry (one triangle at 1e20 among a room's) has stretched the bounds,
/// and G cuts off all the indirect light that matters. Only a warning: the default is
/// still what the documentation says, and `--min-dist` overrides it.
fn warn_large_min_dist(scene: &Scene, diagonal: f32) {
    let m = igi_core::settings::DEFAULT_MIN_DIST_FRACTION * diagonal;
    let eye = scene.camera.eye;
    let reach = scene
        .lights
        .iter()
        .map(|l| l.position.distance(eye))
        .fold(scene.camera.target.distance(eye), f32::max);
    if m > reach {
        log::warn!(
            "{}: the default min_dist {m:.4e} ({}% of the scene's diagonal {diagonal:.4e}) exceeds the camera's distance to its target and lights ({reach:.4e}): geometry far away stretches the bounds, and the bound of G removes the indirect light; set --min-dist",
            scene.source,
            igi_core::settings::DEFAULT_MIN_DIST_FRACTION * 100.0
        );
    }
}

/// What light choice and the VPLs' flux need of the lights: the sum over lights of each
/// one's power summed over channels (in this order, as the CPU twin `igi_core::vpl`
/// sums it), and the total power per channel; in trace coordinates.
fn light_powers(lights: &[PointLight], scale: TraceScale) -> (f32, [f32; 3]) {
    let power = |l: &PointLight| scale.intensity(l.power());
    let sum = lights.iter().map(|l| power(l).element_sum()).sum();
    let total = lights.iter().map(power).sum::<glam::Vec3>();
    (sum, total.to_array())
}

/// Error where the lights' power in trace coordinates is past the f32 range: a scene
/// scaled up by a large factor (a tiny scene) has its intensities scaled by its square.
fn check_light_power(sum: f32, scale: TraceScale) -> Result<(), GpuError> {
    if sum.is_finite() {
        return Ok(());
    }
    Err(GpuError::Limit(format!(
        "the lights' power, traced at {:e} times the scene's size (igi_core::trace_scale), is beyond the range of 32-bit floats: give the scene in larger units, or the lights less intensity",
        scale.factor
    )))
}

/// Reject settings the passes cannot honour, by igi-core's validation (the one the
/// command, the bench and the viewer run): the accelerations' parameters, and a mirror
/// depth past [`MAX_MIRROR_DEPTH`]. Counts of zero (VPLs, bounces, frames) are taken as
/// one here, as the frame always has.
fn check_settings(settings: &RenderSettings) -> Result<(), GpuError> {
    let refuse = |e: SettingsError| GpuError::Limit(e.to_string());
    if settings.mirror_depth > MAX_MIRROR_DEPTH {
        return Err(refuse(SettingsError::MirrorDepth(settings.mirror_depth)));
    }
    settings.accelerations.validate().map_err(refuse)
}

/// Most VPL subsets of interleaved sampling (igi-core's limit, which the WGSL's mirror
/// list and irregular pattern are sized for).
pub const MAX_SUBSETS: u32 = igi_core::settings::MAX_SUBSETS;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interleave_sides_whose_product_wraps_in_32_bits_are_refused() {
        let mut settings = RenderSettings::default();
        settings.accelerations.interleave = (3, 3);
        assert!(check_settings(&settings).is_ok());
        // 65536 x 65536 is 0 in u32.
        for interleave in [(65_536, 65_536), (8, 9), (0, 4), (u32::MAX, 2)] {
            settings.accelerations.interleave = interleave;
            let err = check_settings(&settings).expect_err("refused");
            assert!(
                err.to_string().contains("at most 64"),
                "{interleave:?}: {err}"
            );
        }
    }

    #[test]
    fn mirror_depths_past_the_bound_are_refused() {
        let mut settings = RenderSettings {
            mirror_depth: MAX_MIRROR_DEPTH,
            ..RenderSettings::default()
        };
        assert!(check_settings(&settings).is_ok());
        // u32::MAX wrapped the VPL pass's path length (bounces + mirror depth) to 7.
        for depth in [MAX_MIRROR_DEPTH + 1, u32::MAX] {
            settings.mirror_depth = depth;
            let err = check_settings(&settings).expect_err("refused");
            assert!(err.to_string().contains("at most 1024"), "{depth}: {err}");
        }
    }
}
