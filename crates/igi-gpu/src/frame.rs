//! The frame (paper section 4): [`Renderer::encode_frame`] lists its passes in order —
//! VPL shooting beside direct + specular, the VPL list, [the mirror chains' walks and the
//! mirror indirect gather beside] the indirect diffuse gather, [its filter, beside the
//! mirror discontinuity buffer], compose — each stage timed by GPU timestamps (passes
//! side by side share their stage's). The renderer owns the scene on the GPU, the passes
//! and the frame's buffers; nothing is read back inside a frame.

use crate::context::{GpuContext, GpuError, SMALLER_FRAME};
use crate::layout::{FrameParams, Vpl};
use crate::passes::compose::ComposePass;
use crate::passes::direct::{DirectBindings, DirectPass, CHAIN_WORKGROUPS};
use crate::passes::display::DisplayInputs;
use crate::passes::filter::{Filter, FilterPass};
use crate::passes::indirect::{IndirectPass, LIST_WORKGROUPS};
use crate::passes::vpl::VplPass;
use crate::passes::{
    gather_range_layout, lanes_for, mirror_lanes, Dispatches, GatherRanges, Recorder,
    GATHER_RANGE_STRIDE,
};
use crate::profiler::{Profiler, StageTime};
use crate::scene_buffers::SceneBuffers;
use crate::shader::ParamsBinding;
use igi_core::bvh::Bvh;
use igi_core::image::Image;
use igi_core::sampling::{halton_base, pilot_base, DigitPermutations};
use igi_core::scene::{Camera, PointLight, Scene};
use igi_core::settings::{
    Accelerations, FilterMode, GeometryBound, InterleavePattern, OutputBuffer, RenderSettings,
    MAX_MIRROR_DEPTH,
};

/// Most stages a frame can have (VPL shooting + direct, VPL list, mirror chains, mirror
/// indirect, indirect, filter, mirror discontinuity, compose, with `IGI_SIDE_BY_SIDE=0`),
/// each with its timestamp pair.
pub const MAX_STAGES: u32 = 8;

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

/// How many buffers the frame's image buffers (`ImageBuffers`) hold, each 16 bytes per pixel.
pub const IMAGE_BUFFERS: u32 = 15;

/// Buffers sized by the image.
struct ImageBuffers {
    width: u32,
    height: u32,
    direct: wgpu::Buffer,
    position: wgpu::Buffer,
    normal: wgpu::Buffer,
    geometric: wgpu::Buffer,
    albedo: wgpu::Buffer,
    /// The first diffuse hit of each pixel's mirror chain (direct.wgsl): position,
    /// shading normal (w: the chain's length), geometric normal, weight (w = 1 where
    /// there is one).
    mirror: [wgpu::Buffer; 4],
    /// E at the mirrored hits (full resolution), as the mirror indirect stage leaves it,
    /// and after
    /// the discontinuity buffer over the mirrored hits (interleaved frames).
    mirror_irradiance: wgpu::Buffer,
    mirror_filtered: wgpu::Buffer,
    /// The pixels with a mirrored hit (direct.wgsl's mirror_list: a counter per
    /// interleaving subset, then a bucket of pixels per subset).
    mirror_list: wgpu::Buffer,
    /// The pixels whose mirror chain the direct pass's later walks follow (direct.wgsl's
    /// chain_list: a counter, then the pixels).
    chain_list: wgpu::Buffer,
    /// E at the indirect resolution, as the indirect pass leaves it.
    irradiance: wgpu::Buffer,
    /// After the discontinuity buffer (indirect resolution).
    filtered_low: wgpu::Buffer,
    /// After the fused filter (full resolution).
    filtered: wgpu::Buffer,
    color: wgpu::Buffer,
}

/// Buffers sized by the number of VPL slots (paths x bounces).
struct VplBuffers {
    slots: u64,
    slot_buffer: wgpu::Buffer,
    vpls: wgpu::Buffer,
}

/// The passes of a frame with their pipelines, made from the device alone: no scene
/// goes into them, so a command can make them while it loads the scene. They are most
/// of a renderer's set-up: on the H200 about 95 ms with the driver's shader cache warm
/// and 2.8 s cold, on lavapipe about 0.6 s.
pub struct Passes {
    scene_layout: wgpu::BindGroupLayout,
    range_layout: wgpu::BindGroupLayout,
    vpl: VplPass,
    direct: DirectPass,
    indirect: IndirectPass,
    filter: FilterPass,
    compose: ComposePass,
}

impl Passes {
    pub fn new(ctx: &GpuContext) -> Passes {
        let device = &ctx.device;
        let layout = SceneBuffers::layout(device);
        let range_layout = gather_range_layout(device);
        Passes {
            vpl: VplPass::new(device, &layout),
            direct: DirectPass::new(device, &layout, &range_layout),
            indirect: IndirectPass::new(
                device,
                &layout,
                &range_layout,
                mirror_lanes(ctx.is_software()),
            ),
            filter: FilterPass::new(device, &layout),
            compose: ComposePass::new(device, &layout),
            scene_layout: layout,
            range_layout,
        }
    }
}

/// Accumulated frames submitted ahead of the one the GPU runs
/// ([`Renderer::render_with_progress`]): enough that the GPU always has the next. On
/// lavapipe, whose work runs on the CPU's cores, one ahead took 6.8 s for 300 frames of
/// 32 x 24 where all at once took 4.9 s; four ahead measured alike with all at once (5.2-
/// 5.8 s against 5.4-6.3 s, three alternations).
pub const FRAMES_IN_FLIGHT: usize = 4;

pub struct Renderer {
    scene: SceneBuffers,
    vpl: VplPass,
    direct: DirectPass,
    indirect: IndirectPass,
    filter: FilterPass,
    compose: ComposePass,
    profiler: Profiler,
    params: wgpu::Buffer,
    /// The frame's parameters as the indirect pass and the discontinuity buffer read them
    /// over the mirrored hits: their image is the full-resolution one (no downsampling).
    mirror_params: wgpu::Buffer,
    vpl_header: wgpu::Buffer,
    /// An empty VPL list and header bound to the direct pass's first walk, which gathers
    /// nothing: binding the real ones (written by VPL shooting) would put a barrier
    /// between the two passes, which are meant to run side by side.
    no_vpls: (wgpu::Buffer, wgpu::Buffer),
    /// What the direct pass's later walks (`chains_main`) bind where its first walk binds
    /// the G-buffer, the mirror record and the mirror list, which only the first walk
    /// writes: scratch buffers that no other pass binds, so that the later walks can run
    /// beside the gathers that read those outputs (wgpu would put a barrier between a
    /// dispatch that binds a buffer read-write and one that reads it).
    chain_scratch: [wgpu::Buffer; 9],
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
    images: Option<ImageBuffers>,
    vpl_buffers: Option<VplBuffers>,
    camera: Camera,
    /// See [`light_powers`].
    light_power_sum: f32,
    total_power: [f32; 3],
    diagonal: f32,
    /// The scene's [`Scene::ray_offset_floor`] (params.ray_offset_floor).
    ray_offset_floor: f32,
    /// Paths per frame for (seed, vpls, bounces, mirror depth), from the pilot run.
    path_cache: Option<((u32, u32, u32, u32), u32)>,
    /// Whether any material has a mirror part (else the mirror stage is skipped).
    has_mirrors: bool,
    /// Whether the adapter is a software one (see `passes::lanes_for`).
    software: bool,
    /// Whether the next frame counts its rays (see [`Renderer::count_rays`]).
    counting: bool,
}

fn storage(device: &wgpu::Device, label: &str, size: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size.max(16),
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_SRC
            | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
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
        Renderer::with_passes(ctx, Passes::new(ctx), scene, bvh)
    }

    /// Upload the scene and its BVH for passes made before (see [`Passes`]).
    pub fn with_passes(
        ctx: &GpuContext,
        passes: Passes,
        scene: &Scene,
        bvh: &Bvh,
    ) -> Result<Renderer, GpuError> {
        let device = &ctx.device;
        let Passes {
            scene_layout,
            range_layout,
            vpl,
            direct,
            indirect,
            filter,
            compose,
        } = passes;
        let scene_buffers = SceneBuffers::upload_with(ctx, scene_layout, scene, bvh)?;
        // One pass over the triangles for both figures of the scene's size.
        let (lo, hi) = scene.bounds();
        warn_large_min_dist(scene, igi_core::scene::diagonal_of(lo, hi));
        let params_usage = ParamsBinding::of(device).usage() | wgpu::BufferUsages::COPY_DST;
        let params_buffer = |label| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: std::mem::size_of::<FrameParams>() as u64,
                usage: params_usage,
                mapped_at_creation: false,
            })
        };
        let renderer = Renderer {
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
            params: params_buffer("frame params"),
            mirror_params: params_buffer("mirror filter params"),
            vpl_header: storage(device, "vpl header", 16),
            no_vpls: (
                storage(device, "no vpls", std::mem::size_of::<Vpl>() as u64),
                storage(device, "no vpl header", 16),
            ),
            chain_scratch: std::array::from_fn(|_| storage(device, "chain walk scratch", 16)),
            list_grids: (LIST_WORKGROUPS, CHAIN_WORKGROUPS),
            halton_perms: (0, permutation_buffer(ctx, 0)),
            images: None,
            vpl_buffers: None,
            camera: scene.camera,
            light_power_sum: light_powers(&scene.lights).0,
            total_power: light_powers(&scene.lights).1,
            diagonal: igi_core::scene::diagonal_of(lo, hi),
            ray_offset_floor: igi_core::bvh::offset_floor(lo, hi),
            path_cache: None,
            counting: false,
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
        let gpu = crate::scene_buffers::gpu_lights(lights);
        ctx.queue
            .write_buffer(&self.scene.lights, 0, bytemuck::cast_slice(&gpu));
        (self.light_power_sum, self.total_power) = light_powers(lights);
        self.path_cache = None;
        Ok(())
    }

    /// What the viewer's display pass reads: the colour buffer of the last frame and its
    /// VPLs (`None` before the first frame).
    pub fn display_inputs(&self) -> Option<DisplayInputs<'_>> {
        let (img, vb) = (self.images.as_ref()?, self.vpl_buffers.as_ref()?);
        Some(DisplayInputs {
            params: &self.params,
            color: &img.color,
            vpls: &vb.vpls,
            vpl_header: &self.vpl_header,
            width: img.width,
            height: img.height,
            vpl_slots: vb.slots.min(u32::MAX as u64) as u32,
        })
    }

    /// The colour buffer of the last submitted frame (waits for it).
    pub fn read_image(&self, ctx: &GpuContext) -> Result<Image, GpuError> {
        let Some(images) = self.images.as_ref() else {
            return Err(GpuError::Device("no frame rendered yet".into()));
        };
        let rgba: Vec<[f32; 4]> = ctx.read_buffer(&images.color)?;
        let pixels = images.width as usize * images.height as usize;
        Ok(Image::from_rgba(
            images.width,
            images.height,
            &rgba[..pixels],
        ))
    }

    /// One of the last frame's per-pixel buffers by its label (waits for it), as many
    /// RGBA values as the image has pixels (buffers at the indirect term's resolution use
    /// the first `low_resolution` of them): "direct", "gbuffer position", "gbuffer
    /// normal", "gbuffer geometric normal", "gbuffer albedo", "mirror position", "mirror
    /// normal", "mirror geometric normal", "mirror weight", "mirror irradiance", "mirror
    /// irradiance after discontinuity", "irradiance", "irradiance after discontinuity",
    /// "irradiance full resolution", "color". For the tests of the passes' CPU twins.
    pub fn read_frame_buffer(
        &self,
        ctx: &GpuContext,
        label: &str,
    ) -> Result<Vec<[f32; 4]>, GpuError> {
        let Some(b) = self.images.as_ref() else {
            return Err(GpuError::Device("no frame rendered yet".into()));
        };
        let buffer = match label {
            "direct" => &b.direct,
            "gbuffer position" => &b.position,
            "gbuffer normal" => &b.normal,
            "gbuffer geometric normal" => &b.geometric,
            "gbuffer albedo" => &b.albedo,
            "mirror position" => &b.mirror[0],
            "mirror normal" => &b.mirror[1],
            "mirror geometric normal" => &b.mirror[2],
            "mirror weight" => &b.mirror[3],
            "mirror irradiance" => &b.mirror_irradiance,
            "mirror irradiance after discontinuity" => &b.mirror_filtered,
            "irradiance" => &b.irradiance,
            "irradiance after discontinuity" => &b.filtered_low,
            "irradiance full resolution" => &b.filtered,
            "color" => &b.color,
            _ => return Err(GpuError::Device(format!("no frame buffer called {label:?}"))),
        };
        let mut values: Vec<[f32; 4]> = ctx.read_buffer(buffer)?;
        values.truncate(b.width as usize * b.height as usize);
        Ok(values)
    }

    /// VPLs stored by the last submitted frame (waits for it).
    pub fn vpl_count(&self, ctx: &GpuContext) -> Result<u32, GpuError> {
        let header: Vec<u32> = ctx.read_buffer(&self.vpl_header)?;
        Ok(header[0])
    }

    /// The lengths of the direct pass's lists in the last frame (waits for it): the
    /// counts of the mirrored-pixel buckets, then the count of listed chains.
    pub fn list_counters(&self, ctx: &GpuContext) -> Result<Vec<u32>, GpuError> {
        let Some(images) = self.images.as_ref() else {
            return Err(GpuError::Device("no frame rendered yet".into()));
        };
        let mirror: Vec<u32> = ctx.read_buffer(&images.mirror_list)?;
        let chain: Vec<u32> = ctx.read_buffer(&images.chain_list)?;
        let mut counters = mirror[..MAX_SUBSETS as usize].to_vec();
        counters.push(chain[0]);
        Ok(counters)
    }

    /// The weight record of the last frame's mirrored hits (waits for it): per pixel the
    /// weight of the first diffuse hit of its mirror chain, w = 1 where there is one.
    pub fn mirror_weights(&self, ctx: &GpuContext) -> Result<Vec<[f32; 4]>, GpuError> {
        let Some(images) = self.images.as_ref() else {
            return Err(GpuError::Device("no frame rendered yet".into()));
        };
        let mut weights: Vec<[f32; 4]> = ctx.read_buffer(&images.mirror[3])?;
        weights.truncate(images.width as usize * images.height as usize);
        Ok(weights)
    }

    /// Bytes held on the GPU by the scene.
    pub fn scene_bytes(&self) -> u64 {
        self.scene.bytes
    }

    /// Bytes held on the GPU by the frame's buffers (image and VPL buffers).
    pub fn frame_bytes(&self) -> u64 {
        let images = self.images.as_ref().map_or(0, |b| {
            [
                &b.direct,
                &b.position,
                &b.normal,
                &b.geometric,
                &b.albedo,
                &b.irradiance,
                &b.mirror[0],
                &b.mirror[1],
                &b.mirror[2],
                &b.mirror[3],
                &b.filtered_low,
                &b.filtered,
                &b.mirror_irradiance,
                &b.mirror_filtered,
                &b.color,
                &b.mirror_list,
                &b.chain_list,
            ]
            .iter()
            .map(|b| b.size())
            .sum()
        });
        let vpls = self
            .vpl_buffers
            .as_ref()
            .map_or(0, |b| b.slot_buffer.size() + b.vpls.size());
        images + vpls + self.params.size() + self.vpl_header.size()
    }

    fn check_size(ctx: &GpuContext, settings: &RenderSettings) -> Result<(), GpuError> {
        let (w, h) = (settings.width, settings.height);
        if w == 0 || h == 0 {
            return Err(GpuError::Limit(format!(
                "image size {w}x{h}: both must be at least 1"
            )));
        }
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

    /// The image buffers for `width` x `height`: made again when the size changes, the
    /// old ones freed first (the new set may need their memory).
    fn ensure_images(&mut self, ctx: &GpuContext, width: u32, height: u32) -> Result<(), GpuError> {
        if let Some(b) = &self.images {
            if b.width == width && b.height == height {
                return Ok(());
            }
        }
        self.images = None;
        let size = width as u64 * height as u64 * 16;
        // A counter per subset, then one bucket per subset (direct.wgsl's mirror_list):
        // n x m buckets of ceil(w / n) ceil(h / m) pixels, at most (w + 63) (h + 63).
        let list_size = (MAX_SUBSETS as u64
            + (width as u64 + MAX_SUBSETS as u64 - 1) * (height as u64 + MAX_SUBSETS as u64 - 1))
            * 4;
        let chain_size = (1 + width as u64 * height as u64) * 4;
        let device = &ctx.device;
        let images = ctx.allocate(
            || format!("the {IMAGE_BUFFERS} frame buffers of a {width}x{height} image"),
            IMAGE_BUFFERS as u64 * size.max(16) + list_size + chain_size,
            SMALLER_FRAME,
            || ImageBuffers {
                width,
                height,
                direct: storage(device, "direct", size),
                position: storage(device, "gbuffer position", size),
                normal: storage(device, "gbuffer normal", size),
                geometric: storage(device, "gbuffer geometric normal", size),
                albedo: storage(device, "gbuffer albedo", size),
                mirror: [
                    storage(device, "mirror position", size),
                    storage(device, "mirror normal", size),
                    storage(device, "mirror geometric normal", size),
                    storage(device, "mirror weight", size),
                ],
                mirror_irradiance: storage(device, "mirror irradiance", size),
                mirror_filtered: storage(device, "mirror irradiance after discontinuity", size),
                irradiance: storage(device, "irradiance", size),
                filtered_low: storage(device, "irradiance after discontinuity", size),
                filtered: storage(device, "irradiance full resolution", size),
                color: storage(device, "color", size),
                mirror_list: storage(device, "mirror list", list_size),
                chain_list: storage(device, "mirror chain list", chain_size),
            },
        )?;
        self.images = Some(images);
        Ok(())
    }

    fn ensure_vpl_slots(&mut self, ctx: &GpuContext, slots: u64) -> Result<(), GpuError> {
        if self.vpl_buffers.as_ref().is_some_and(|b| b.slots >= slots) {
            return Ok(());
        }
        let bytes = slots * std::mem::size_of::<Vpl>() as u64;
        if bytes > ctx.max_storage_binding() {
            return Err(GpuError::Limit(format!(
                "{slots} VPL slots need {} MiB, more than this adapter's max_storage_buffer_binding_size of {} MiB: ask for fewer VPLs or bounces",
                bytes >> 20,
                ctx.max_storage_binding() >> 20
            )));
        }
        self.vpl_buffers = None;
        let buffers = ctx.allocate(
            || format!("the VPL buffers for {slots} VPL slots"),
            2 * bytes.max(16),
            "fewer VPLs or bounces need less",
            || VplBuffers {
                slots,
                slot_buffer: storage(&ctx.device, "vpl slots", bytes),
                vpls: storage(&ctx.device, "vpls", bytes),
            },
        )?;
        self.vpl_buffers = Some(buffers);
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

    fn frame_params(
        &self,
        settings: &RenderSettings,
        paths: u32,
        base: u32,
        accumulate_index: u32,
    ) -> FrameParams {
        let a = &settings.accelerations;
        let low = low_resolution(settings);
        // Frame 0 through pixel centres (the canonical image); later accumulated frames
        // at (2, 3) Halton points within the pixel.
        let jitter = if accumulate_index == 0 {
            (0.0, 0.0)
        } else {
            (
                igi_core::sampling::radical_inverse(2, accumulate_index) - 0.5,
                igi_core::sampling::radical_inverse(3, accumulate_index) - 0.5,
            )
        };
        let cam = &self.camera;
        let (forward, right, up) = cam.basis();
        let min_dist = settings
            .min_dist
            .unwrap_or(igi_core::settings::DEFAULT_MIN_DIST_FRACTION * self.diagonal);
        FrameParams {
            cam_eye: cam.eye.to_array(),
            width: settings.width,
            cam_forward: forward.to_array(),
            height: settings.height,
            cam_right: right.to_array(),
            tan_half_fov_y: (cam.fov_y_deg.to_radians() * 0.5).tan(),
            cam_up: up.to_array(),
            aspect: settings.width as f32 / settings.height as f32,
            total_power: self.total_power,
            light_count: self.scene.light_count,
            path_count: paths,
            bounces: settings.bounces.max(1),
            min_dist,
            geometry_bound: match settings.geometry_bound {
                GeometryBound::Smoothstep => 0,
                GeometryBound::Clamp => 1,
            },
            mirror_depth: settings.mirror_depth,
            halton_base: base,
            output: match settings.output {
                OutputBuffer::Final => 0,
                OutputBuffer::Direct => 1,
                OutputBuffer::Indirect => 2,
                OutputBuffer::Irradiance => 3,
                OutputBuffer::Normals => 4,
                OutputBuffer::Depth => 5,
            },
            light_power_sum: self.light_power_sum,
            low_width: low.0,
            low_height: low.1,
            downsample: a.downsample.max(1),
            interleave_n: a.interleave.0.max(1),
            interleave_m: a.interleave.1.max(1),
            pattern: match a.pattern {
                InterleavePattern::Regular => 0,
                InterleavePattern::Irregular => 1,
            },
            seed: settings.seed,
            accumulate_index,
            upsample_sigma: a.upsample_sigma,
            normal_power: a.upsample_normal_power,
            upsample_depth: a.upsample_depth as u32,
            depth_threshold: a.depth_threshold,
            normal_threshold: a.normal_threshold,
            jitter_x: jitter.0,
            jitter_y: jitter.1,
            count_rays: 0,
            depth_scale: 1.0 / self.diagonal.max(f32::MIN_POSITIVE),
            ray_offset_floor: self.ray_offset_floor,
            _pad: [0; 2],
        }
    }

    /// Light paths per frame so that the expected VPL count is `settings.vpls`: a pilot
    /// run of [`PILOT_PATHS`] paths (a Halton window of its own) measures VPLs per path.
    /// The count is fixed before, and independently of, the paths it is used with, and
    /// each path carries 1/M of the power, so the estimator stays unbiased.
    pub fn path_count(
        &mut self,
        ctx: &GpuContext,
        settings: &RenderSettings,
    ) -> Result<u32, GpuError> {
        let key = (
            settings.seed,
            settings.vpls,
            settings.bounces.max(1),
            settings.mirror_depth,
        );
        if let Some((k, paths)) = self.path_cache {
            if k == key {
                return Ok(paths);
            }
        }
        let bounces = settings.bounces.max(1);
        self.ensure_permutations(ctx, settings.seed);
        self.ensure_vpl_slots(ctx, PILOT_PATHS as u64 * bounces as u64)?;
        let params = self.frame_params(settings, PILOT_PATHS, pilot_base(settings.seed), 0);
        let pilot_vpls = self.count_vpls(ctx, &params, "vpl pilot")?;
        let per_path = pilot_vpls as f64 / PILOT_PATHS as f64;
        let paths = if per_path > 0.0 {
            (settings.vpls as f64 / per_path)
                .round()
                .clamp(1.0, u32::MAX as f64 / 64.0) as u32
        } else {
            // The lights reach no surface: no VPLs whatever the count.
            settings.vpls.max(1)
        };
        self.path_cache = Some((key, paths));
        Ok(paths)
    }

    /// The VPLs that the light paths of `params` leave: the VPL pass run alone, untimed
    /// and uncounted, and its count read back (the VPL buffers must hold the paths'
    /// slots).
    fn count_vpls(
        &mut self,
        ctx: &GpuContext,
        params: &FrameParams,
        label: &'static str,
    ) -> Result<u32, GpuError> {
        let params = FrameParams {
            count_rays: 0,
            ..*params
        };
        ctx.queue
            .write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
        let vb = self.vpl_buffers.as_ref().expect("allocated");
        let bind = self.vpl.bind(
            &ctx.device,
            &self.params,
            &vb.slot_buffer,
            &vb.vpls,
            &self.vpl_header,
            &self.halton_perms.1,
        );
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        let untimed = Profiler::disabled();
        let steps = self.vpl.steps(params.path_count);
        let steps: Vec<_> = std::iter::once(steps.shoot).chain(steps.compact).collect();
        Recorder::new(&mut encoder, &untimed, label).dispatch(
            0,
            label,
            &steps,
            &self.scene.bind_group,
            &bind,
            None,
        );
        ctx.queue.submit([encoder.finish()]);
        let header: Vec<u32> = ctx.read_buffer(&self.vpl_header)?;
        Ok(header[0])
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
        Self::check_size(ctx, settings)?;
        check_settings(settings)?;
        let paths = self.path_count(ctx, settings)?;
        self.ensure_permutations(ctx, settings.seed);
        let bounces = settings.bounces.max(1);
        self.ensure_vpl_slots(ctx, paths as u64 * bounces as u64)?;
        self.ensure_images(ctx, settings.width, settings.height)?;
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
        // hundredfold (one mirror triangle: 9 VPLs in 1,872 slots, whose 234 ranges took
        // 2.5-10 s a frame on llvmpipe).
        let vpls = if self.vpls_per_dispatch == u32::MAX {
            paths as u64 * bounces as u64
        } else {
            self.count_vpls(ctx, &params, "vpl count")? as u64
        };
        self.ensure_ranges(ctx, vpls);
        params.count_rays = self.counting as u32;
        ctx.queue
            .write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
        if self.has_mirrors {
            let mirror = FrameParams {
                low_width: params.width,
                low_height: params.height,
                downsample: 1,
                ..params
            };
            ctx.queue
                .write_buffer(&self.mirror_params, 0, bytemuck::bytes_of(&mirror));
        }
        if self.has_mirrors {
            self.start_lists(ctx);
        }
        let mut encoder = ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("frame"),
            });
        let names = self.encode_frame(&ctx.device, &mut encoder, settings, paths);
        self.profiler.resolve(&mut encoder, names.len() as u32);
        let submission = ctx.queue.submit([encoder.finish()]);
        Ok((names, paths, submission))
    }

    /// Empties the direct pass's lists for the frame about to be submitted (its direct
    /// pass appends to them). Written with the frame's parameters, before its commands
    /// run; the gathers of the frame before have run by then (queue order).
    fn start_lists(&self, ctx: &GpuContext) {
        let img = self.images.as_ref().expect("image buffers allocated");
        ctx.queue
            .write_buffer(&img.mirror_list, 0, &[0; 4 * MAX_SUBSETS as usize]);
        ctx.queue.write_buffer(&img.chain_list, 0, &[0; 4]);
    }

    /// The VPL shadow rays of a real frame of `settings` (canonical: every pixel against
    /// every VPL, exactly the segments the indirect pass traces), about `count` of them:
    /// when the frame has more, an evenly spread subset of its pixels keeps all its rays.
    /// Ordered VPL by VPL, each over the pixels in scanline order, as neighbouring threads
    /// of the indirect pass trace them (all towards one VPL at a time).
    pub fn frame_shadow_rays(
        &mut self,
        ctx: &GpuContext,
        settings: &RenderSettings,
        count: usize,
    ) -> Result<Vec<igi_core::rays::RayRecord>, GpuError> {
        use glam::Vec3;
        use igi_core::bvh::offset_ray_origin;
        let canonical = RenderSettings {
            accelerations: Accelerations::default(),
            accumulate: 1,
            ..settings.clone()
        };
        self.render(ctx, &canonical)?;
        let img = self.images.as_ref().expect("rendered");
        let positions: Vec<[f32; 4]> = ctx.read_buffer(&img.position)?;
        let normals: Vec<[f32; 4]> = ctx.read_buffer(&img.normal)?;
        let geometric: Vec<[f32; 4]> = ctx.read_buffer(&img.geometric)?;
        let vpls = self.read_vpls(ctx)?;
        let m = settings
            .min_dist
            .unwrap_or(igi_core::settings::DEFAULT_MIN_DIST_FRACTION * self.diagonal);
        let pixels: Vec<usize> = (0..(settings.width * settings.height) as usize)
            .filter(|&p| positions[p][3] > 0.0)
            .collect();
        // The segment from pixel p to VPL v, if the indirect pass traces it.
        let segment = |p: usize, v: &Vpl| -> Option<igi_core::rays::RayRecord> {
            let x = Vec3::from_slice(&positions[p][..3]);
            let ns = Vec3::from_slice(&normals[p][..3]);
            let ng = Vec3::from_slice(&geometric[p][..3]);
            let (y, ny) = (Vec3::from(v.position), Vec3::from(v.normal));
            let d = y - x;
            let dist = d.length();
            if ns.dot(d) <= 0.0 || -ny.dot(d) <= 0.0 || ng.dot(d) <= 0.0 {
                return None;
            }
            if settings.geometry_bound == GeometryBound::Smoothstep && dist <= 0.8 * m {
                return None;
            }
            Some(igi_core::rays::RayRecord::segment(
                offset_ray_origin(x, ng, self.ray_offset_floor),
                offset_ray_origin(y, ny, self.ray_offset_floor),
            ))
        };
        let all: usize = pixels
            .iter()
            .map(|&p| vpls.iter().filter(|v| segment(p, v).is_some()).count())
            .sum();
        // Keep an evenly spread fraction of the pixels (error diffusion along scanlines).
        let fraction = (count as f64 / all.max(1) as f64).min(1.0);
        let mut carry = 0.0;
        let kept: Vec<usize> = pixels
            .into_iter()
            .filter(|_| {
                carry += fraction;
                if carry >= 1.0 - 1e-9 {
                    carry -= 1.0;
                    true
                } else {
                    false
                }
            })
            .collect();
        let mut out = Vec::with_capacity(count.min(all));
        for v in &vpls {
            out.extend(kept.iter().filter_map(|&p| segment(p, v)));
        }
        out.truncate(count);
        Ok(out)
    }

    /// The VPLs of the last frame (for tests and for drawing them).
    pub fn read_vpls(&self, ctx: &GpuContext) -> Result<Vec<Vpl>, GpuError> {
        let header: Vec<u32> = ctx.read_buffer(&self.vpl_header)?;
        let Some(vb) = &self.vpl_buffers else {
            return Ok(vec![]);
        };
        let mut vpls: Vec<Vpl> = ctx.read_buffer(&vb.vpls)?;
        vpls.truncate(header[0] as usize);
        Ok(vpls)
    }

    /// The passes of one frame, in order (kajiya style: the frame reads top to bottom).
    /// Returns the names of the stages it encoded, one time each. Meant to be
    /// called by [`Renderer::submit_frame`], which first writes the frame's parameters and
    /// empties the direct pass's lists (`start_lists`): a frame encoded without them would
    /// append to the last frame's lists.
    pub fn encode_frame(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        settings: &RenderSettings,
        paths: u32,
    ) -> Vec<&'static str> {
        let img = self.images.as_ref().expect("image buffers allocated");
        let vb = self.vpl_buffers.as_ref().expect("vpl buffers allocated");
        let scene = &self.scene.bind_group;
        let mut rec = Recorder::new(encoder, &self.profiler, "frame");
        let (_, range_group, range_count) = self.range_buffer.as_ref().expect("ranges written");
        // Entry 0 of the range buffer is the direct pass's first walk, then the VPL ranges.
        let ranges = GatherRanges {
            bind_group: range_group,
            first: 1,
            count: *range_count,
        };
        let a = &settings.accelerations;
        let iv = a.imperfect_visibility;
        let full = (settings.width, settings.height);
        let low = low_resolution(settings);
        let mut stages: Vec<&'static str> = vec![];
        let mut stage = |name: &'static str| {
            stages.push(name);
            stages.len() as u32 - 1
        };

        // VPL shooting and the direct pass's first walk share no buffer that either
        // writes, so no barrier keeps them apart: the light paths (a few workgroups that
        // each walk up to `bounces` closest hits in sequence, latency more than work)
        // run beside the direct pass instead of before it. Shooting goes first, so that
        // its workgroups start before the direct pass's fill the GPU.
        let vpl_bind = self.vpl.bind(
            device,
            &self.params,
            &vb.slot_buffer,
            &vb.vpls,
            &self.vpl_header,
            &self.halton_perms.1,
        );
        let vpl_steps = self.vpl.steps(paths);
        // The direct pass's first walk gathers no VPLs: an empty list (the one shooting
        // writes would keep the two passes apart).
        let direct_first = self.direct.bind(
            device,
            &self.params,
            DirectBindings {
                vpls: &self.no_vpls.0,
                vpl_header: &self.no_vpls.1,
                direct: &img.direct,
                position: &img.position,
                normal: &img.normal,
                geometric: &img.geometric,
                albedo: &img.albedo,
                mirror: [
                    &img.mirror[0],
                    &img.mirror[1],
                    &img.mirror[2],
                    &img.mirror[3],
                ],
                mirror_list: &img.mirror_list,
                chain_list: &img.chain_list,
            },
        );
        // Spare ray counters for the dispatches that run beside an earlier one (see
        // `SceneBuffers::beside_bind_groups`); a frame that counts rays counts them all in
        // one buffer (then with a barrier).
        let beside = |i: usize| {
            if self.counting {
                scene
            } else {
                &self.scene.beside_bind_groups[i]
            }
        };
        let first_walk = GatherRanges {
            bind_group: range_group,
            first: 0,
            count: 1,
        };
        let direct_steps = self.direct.steps(full.0, full.1, iv);
        let i = stage("vpl shooting + direct");
        rec.stage(
            i,
            "vpl shooting + direct",
            &[
                Dispatches {
                    steps: &[vpl_steps.shoot],
                    scene,
                    pass: &vpl_bind,
                    ranges: None,
                    group3: None,
                },
                Dispatches {
                    steps: &direct_steps,
                    scene: beside(0),
                    pass: &direct_first,
                    ranges: Some(&first_walk),
                    group3: None,
                },
            ],
        );

        // With more light paths than one workgroup shoots and compacts, the compaction
        // follows in a stage of its own.
        if let Some(compact) = vpl_steps.compact {
            let i = stage("vpl list");
            rec.dispatch(i, "vpl list", &[compact], scene, &vpl_bind, None);
        }

        // The indirect pass over the mirror record (the mirror gather below), gathering
        // only at the pixels the direct pass listed: its bind groups (its parameters and
        // buffers, the list), in scenes with mirrors.
        let mirror_groups = self.has_mirrors.then(|| {
            let bind = self.indirect.bind(
                device,
                &[
                    &self.mirror_params,
                    &vb.vpls,
                    &self.vpl_header,
                    &img.mirror[0],
                    &img.mirror[1],
                    &img.mirror[2],
                    &img.mirror_irradiance,
                ],
            );
            let list = self.indirect.bind_list(device, &img.mirror_list);
            (bind, list)
        });

        // The gathers, side by side in one stage (see `Recorder::side_by_side`): each
        // ends on a few slow warps, and each one's tail overlaps the others' work. First
        // the VPL light at hits seen in a mirror seen in a mirror: later walks of the
        // direct pass over the chains its first walk listed, which write only its
        // radiance (the first walk's other outputs are bound to scratch buffers, so that
        // they share nothing the other gathers read). Then the gather at the mirrored
        // hits (over the list the direct pass made) and the one at the pixels of the
        // indirect term. Scenes without mirrors have only the last.
        let chains_bind = (self.has_mirrors && settings.mirror_depth >= 2).then(|| {
            let [s0, s1, s2, s3, s4, s5, s6, s7, s8] = &self.chain_scratch;
            self.direct.bind(
                device,
                &self.params,
                DirectBindings {
                    vpls: &vb.vpls,
                    vpl_header: &self.vpl_header,
                    direct: &img.direct,
                    position: s0,
                    normal: s1,
                    geometric: s2,
                    albedo: s3,
                    mirror: [s4, s5, s6, s7],
                    mirror_list: s8,
                    chain_list: &img.chain_list,
                },
            )
        });
        let chains_steps = self
            .direct
            .chains_steps(full.0, full.1, iv, self.list_grids.1);
        let list_steps =
            self.indirect
                .list_steps(full.0, full.1, a.interleave, iv, self.list_grids.0);
        let indirect_bind = self.indirect.bind(
            device,
            &[
                &self.params,
                &vb.vpls,
                &self.vpl_header,
                &img.position,
                &img.normal,
                &img.geometric,
                &img.irradiance,
            ],
        );
        let indirect_steps = self.indirect.steps(
            low.0,
            low.1,
            iv,
            lanes_for(
                low.0 * low.1,
                a.interleave.0 * a.interleave.1 > 1,
                self.software,
            ),
            a.interleave,
        );
        let mut gathers = vec![];
        if let Some(bind) = &chains_bind {
            gathers.push((
                "mirror chains",
                Dispatches {
                    steps: &chains_steps,
                    scene,
                    pass: bind,
                    ranges: Some(&ranges),
                    group3: None,
                },
            ));
        }
        if let Some((mirror_bind, list_bind)) = &mirror_groups {
            gathers.push((
                "mirror indirect",
                Dispatches {
                    steps: &list_steps,
                    scene: beside(1),
                    pass: mirror_bind,
                    ranges: Some(&ranges),
                    group3: Some(list_bind),
                },
            ));
        }
        gathers.push((
            "indirect",
            Dispatches {
                steps: &indirect_steps,
                scene: beside(2),
                pass: &indirect_bind,
                ranges: Some(&ranges),
                group3: None,
            },
        ));
        let name = match gathers.len() {
            3 => "mirror chains + mirror indirect + indirect",
            2 => "mirror indirect + indirect",
            _ => "indirect",
        };
        // What the gathers after the first read: the G-buffer, the mirror record and its
        // list.
        let read = |buffer| wgpu::BufferTransition {
            buffer,
            state: wgpu::BufferUses::STORAGE_READ_ONLY,
        };
        rec.side_by_side(
            &mut stage,
            name,
            &[
                read(&img.position),
                read(&img.normal),
                read(&img.geometric),
                read(&img.mirror[0]),
                read(&img.mirror[1]),
                read(&img.mirror[2]),
                read(&img.mirror_list),
            ],
            gathers,
        );

        // The filter of the indirect term, and beside it the discontinuity buffer over the
        // mirrored hits (interleaved frames with mirrors): in this order the stage took
        // 0.019 ms against 0.021 at 800 x 600, 0.038 against 0.045 at 1920 x 1080 on the
        // H200 (docs/PERFORMANCE.md attempt 70).
        let (filter, upsample) = filter_chain(a);
        // The filter's output, bind group and dispatch.
        let filter_pass = filter.map(|filter| {
            let out = match filter {
                Filter::Discontinuity => &img.filtered_low,
                Filter::Fused => &img.filtered,
            };
            let bind = self.filter.bind(
                device,
                &[
                    &self.params,
                    &img.position,
                    &img.normal,
                    &img.irradiance,
                    out,
                ],
            );
            (filter, out, bind, self.filter.steps(filter, full, low))
        });
        let mut filter_parts = vec![];
        if let Some((filter, _, bind, steps)) = &filter_pass {
            filter_parts.push((
                filter.stage_name(),
                Dispatches {
                    steps,
                    scene,
                    pass: bind,
                    ranges: None,
                    group3: None,
                },
            ));
        }
        let mirror_filter = self.has_mirrors && a.interleave.0 * a.interleave.1 > 1;
        let mirror_e = if mirror_filter {
            &img.mirror_filtered
        } else {
            &img.mirror_irradiance
        };
        let mirror_filter_bind = mirror_filter.then(|| {
            self.filter.bind(
                device,
                &[
                    &self.mirror_params,
                    &img.mirror[0],
                    &img.mirror[1],
                    &img.mirror_irradiance,
                    &img.mirror_filtered,
                ],
            )
        });
        let mirror_filter_steps = self.filter.steps(Filter::Discontinuity, full, full);
        if let Some(bind) = &mirror_filter_bind {
            filter_parts.push((
                "mirror discontinuity",
                Dispatches {
                    steps: &mirror_filter_steps,
                    scene: beside(3),
                    pass: bind,
                    ranges: None,
                    group3: None,
                },
            ));
        }
        let name = match (filter_parts.len(), filter) {
            (2, Some(Filter::Discontinuity)) => "discontinuity + mirror discontinuity",
            (2, Some(Filter::Fused)) => "fused filter + mirror discontinuity",
            _ => filter_parts.first().map_or("", |(name, _)| *name),
        };
        rec.side_by_side(
            &mut stage,
            name,
            &[read(&img.irradiance), read(&img.mirror_irradiance)],
            filter_parts,
        );
        let e = filter_pass
            .as_ref()
            .map_or(&img.irradiance, |(_, out, _, _)| *out);

        let compose_bind = self.compose.bind(
            device,
            &[
                &self.params,
                &img.position,
                &img.normal,
                e,
                &img.color,
                &img.direct,
                &img.albedo,
                &img.mirror[3],
                mirror_e,
            ],
        );
        // With downsampling (two-pass filters), compose upsamples E as it writes each pixel:
        // a pass of its own took 0.036 ms of the H200 at 800 x 600 and 0.11 at 1920 x 1080
        // (docs/PERFORMANCE.md attempt 52).
        let name = if upsample {
            "upsample + compose"
        } else {
            "compose"
        };
        let i = stage(name);
        rec.dispatch(
            i,
            name,
            &self.compose.steps(full.0, full.1, upsample),
            scene,
            &compose_bind,
            None,
        );
        stages
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
/// sums it), and the total power per channel.
fn light_powers(lights: &[PointLight]) -> (f32, [f32; 3]) {
    let sum = lights.iter().map(|l| l.power().element_sum()).sum();
    let total = lights.iter().map(|l| l.power()).sum::<glam::Vec3>();
    (sum, total.to_array())
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

/// Reject settings the passes cannot honour: acceleration parameters, and a mirror depth
/// past [`MAX_MIRROR_DEPTH`].
fn check_settings(settings: &RenderSettings) -> Result<(), GpuError> {
    if settings.mirror_depth > MAX_MIRROR_DEPTH {
        return Err(GpuError::Limit(format!(
            "mirror depth {}: at most {MAX_MIRROR_DEPTH} reflections",
            settings.mirror_depth
        )));
    }
    let a = &settings.accelerations;
    let (n, m) = a.interleave;
    // In 64 bits: n x m of two large u32 sides wraps around in 32.
    if n == 0 || m == 0 || u64::from(n) * u64::from(m) > u64::from(MAX_SUBSETS) {
        return Err(GpuError::Limit(format!(
            "interleave {n}x{m}: each side must be at least 1 and n x m at most {MAX_SUBSETS}"
        )));
    }
    if a.downsample == 0 || a.downsample > 64 {
        return Err(GpuError::Limit(format!(
            "downsample {}: must be between 1 and 64",
            a.downsample
        )));
    }
    if !(a.upsample_sigma > 0.0 && a.depth_threshold > 0.0 && a.upsample_normal_power >= 0.0) {
        return Err(GpuError::Limit(
            "filter parameters: sigma and depth threshold must be positive, the normal power not negative".into(),
        ));
    }
    Ok(())
}

/// Most VPL subsets of interleaved sampling (the irregular pattern's permutation array).
pub const MAX_SUBSETS: u32 = 64;

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
