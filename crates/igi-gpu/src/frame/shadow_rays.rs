//! The VPL shadow rays of a real frame, for the ray bench (`igi bench rays --set frame`).

use super::resources::Buf;
use super::Renderer;
use crate::context::{GpuContext, GpuError};
use crate::layout::Vpl;
use igi_core::settings::{Accelerations, GeometryBound, RenderSettings};

impl Renderer {
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
        if !self.scale.is_one() {
            return Err(GpuError::Limit(
                "the frame's shadow rays are for the ray bench, which traces scenes in their own coordinates: this scene is traced scaled (igi_core::trace_scale)".into(),
            ));
        }
        let canonical = RenderSettings {
            accelerations: Accelerations::default(),
            accumulate: 1,
            ..settings.clone()
        };
        self.render(ctx, &canonical)?;
        let b = &self.buffers;
        let positions: Vec<[f32; 4]> = ctx.read_buffer(b.get(Buf::GbufPosition))?;
        let normals: Vec<[f32; 4]> = ctx.read_buffer(b.get(Buf::GbufNormal))?;
        let geometric: Vec<[f32; 4]> = ctx.read_buffer(b.get(Buf::GbufGeometric))?;
        let vpls = self.read_vpls(ctx)?;
        let m = self.min_dist(settings);
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
}
