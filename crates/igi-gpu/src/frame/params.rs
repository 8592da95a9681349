//! The frame's parameter block (`FrameParams`, `layout.rs`) from the settings, the camera
//! and the scene's lights, and the number of light paths a frame shoots (the pilot run).

use super::recorder;
use super::resources::Buf;
use super::{low_resolution, Renderer, PILOT_PATHS};
use crate::context::{GpuContext, GpuError};
use crate::layout::FrameParams;
use crate::passes::vpl::VplPass;
use crate::profiler::Profiler;
use igi_core::sampling::pilot_base;
use igi_core::settings::{GeometryBound, InterleavePattern, OutputBuffer, RenderSettings};

impl Renderer {
    /// The parameters of a frame of `paths` light paths from Halton index `base`, the
    /// `accumulate_index`-th of an accumulation.
    pub(super) fn frame_params(
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
        let min_dist = self.min_dist(settings);
        FrameParams {
            cam_eye: self.scale.point(cam.eye).to_array(),
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

    /// The bounding distance of G in trace coordinates: the settings' (in the scene's),
    /// or the default fraction of the scene's diagonal.
    pub(super) fn min_dist(&self, settings: &RenderSettings) -> f32 {
        settings.min_dist.map_or(
            igi_core::settings::DEFAULT_MIN_DIST_FRACTION * self.diagonal,
            |m| self.scale.length(m),
        )
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
        self.buffers
            .ensure_vpl_slots(ctx, PILOT_PATHS as u64 * bounces as u64)?;
        let params = self.frame_params(settings, PILOT_PATHS, pilot_base(settings.seed), 0);
        let pilot_vpls = self.count_vpls(ctx, &params)?;
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
    pub(super) fn count_vpls(
        &mut self,
        ctx: &GpuContext,
        params: &FrameParams,
    ) -> Result<u32, GpuError> {
        let params = FrameParams {
            count_rays: 0,
            ..*params
        };
        let b = &self.buffers;
        ctx.queue
            .write_buffer(b.get(Buf::Params), 0, bytemuck::bytes_of(&params));
        let bindings = VplPass::bindings(b, &self.halton_perms.1);
        let pass = self
            .vpl
            .record_alone(&ctx.device, &bindings, params.path_count);
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        recorder::record(
            &mut encoder,
            &Profiler::disabled(),
            &self.scene,
            &[pass],
            &self.switches,
            false,
        );
        ctx.queue.submit([encoder.finish()]);
        let header: Vec<u32> = ctx.read_buffer(b.get(Buf::VplHeader))?;
        Ok(header[0])
    }
}
