//! The ray-tracing layer measured alone (`igi bench rays`): a ray file traced with the
//! any-hit or closest-hit query of `traverse.wgsl`, timed with timestamp queries, so that
//! another ray tracer (OptiX through Mitsuba, `shared/tools/optix_peer.py`) can trace the
//! very same rays and be compared ray for ray.

use crate::context::{GpuContext, GpuError};
use crate::layout::FrameParams;
use crate::passes::{bind, pass_layout, pipeline};
use crate::profiler::Profiler;
use crate::scene_buffers::{storage_buffer, SceneBuffers, READ, UNIFORM, WRITE};
use igi_core::bvh::Bvh;
use igi_core::rays::RayRecord;
use igi_core::scene::Scene;

/// Untimed runs before the timed ones.
pub const WARMUP_RUNS: u32 = 3;

/// Threads per workgroup of the ray kernels (`RAY_GROUP` in rays.wgsl).
const RAY_GROUP: u32 = 64;

/// The query to run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RayQuery {
    /// Occluded or not (shadow rays).
    AnyHit,
    /// Nearest triangle and distance.
    ClosestHit,
}

/// What tracing a ray set gave.
#[derive(Clone, Debug)]
pub struct RayTiming {
    /// GPU time of each timed run (all rays), in milliseconds.
    pub runs_ms: Vec<f64>,
    /// Any-hit: rays found occluded; closest-hit: rays that hit something.
    pub hits: u64,
    /// Per ray: any-hit 0/1; closest-hit the scene's triangle index or u32::MAX.
    pub results: Vec<u32>,
    /// Closest-hit distances (empty for any-hit).
    pub distances: Vec<f32>,
}

pub struct RayBench {
    scene: SceneBuffers,
    layout: wgpu::BindGroupLayout,
    any_hit: wgpu::ComputePipeline,
    closest_hit: wgpu::ComputePipeline,
    params: wgpu::Buffer,
    tri_order: Vec<u32>,
}

impl RayBench {
    pub fn new(ctx: &GpuContext, scene: &Scene, bvh: &Bvh) -> Result<RayBench, GpuError> {
        let scene_buffers = SceneBuffers::upload(ctx, scene, bvh)?;
        // params (unused, but frame.wgsl declares it), rays, results
        let layout = pass_layout(&ctx.device, "rays", &[UNIFORM, READ, WRITE]);
        let layouts = [&scene_buffers.layout, &layout];
        let params = wgpu::util::DeviceExt::create_buffer_init(
            &ctx.device,
            &wgpu::util::BufferInitDescriptor {
                label: Some("rays params"),
                contents: bytemuck::bytes_of(&FrameParams::default()),
                usage: wgpu::BufferUsages::UNIFORM,
            },
        );
        Ok(RayBench {
            any_hit: pipeline(&ctx.device, "rays", "any_hit", &layouts),
            closest_hit: pipeline(&ctx.device, "rays", "closest_hit", &layouts),
            scene: scene_buffers,
            layout,
            params,
            tri_order: bvh.tri_order.clone(),
        })
    }

    /// Trace `rays` [`WARMUP_RUNS`] times untimed (the GPU's clocks rise meanwhile), then
    /// `runs` times timed; results of the last run.
    pub fn trace(
        &self,
        ctx: &GpuContext,
        rays: &[RayRecord],
        query: RayQuery,
        runs: u32,
    ) -> Result<RayTiming, GpuError> {
        // Batches that fit one storage binding (128 MiB on lavapipe).
        let per_batch = (ctx.max_storage_binding() / 32).min(1 << 24) as usize;
        let words = if query == RayQuery::AnyHit { 1 } else { 2 };
        let batches: Vec<(wgpu::Buffer, wgpu::Buffer, u32)> = rays
            .chunks(per_batch.max(1))
            .map(|chunk| {
                let input = storage_buffer(ctx, "rays", bytemuck::cast_slice(chunk))?;
                let output =
                    storage_buffer(ctx, "ray results", &vec![0u8; chunk.len() * 4 * words])?;
                Ok((input, output, chunk.len() as u32))
            })
            .collect::<Result<_, GpuError>>()?;
        let binds: Vec<wgpu::BindGroup> = batches
            .iter()
            .map(|(i, o, _)| bind(&ctx.device, "rays", &self.layout, &[&self.params, i, o]))
            .collect();
        let pipeline = match query {
            RayQuery::AnyHit => &self.any_hit,
            RayQuery::ClosestHit => &self.closest_hit,
        };
        let profiler = Profiler::new(ctx, 1);
        let mut runs_ms = vec![];
        for run in 0..WARMUP_RUNS + runs {
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("rays"),
                    timestamp_writes: profiler.pass_writes(0),
                });
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, &self.scene.bind_group, &[]);
                for (bg, (_, _, n)) in binds.iter().zip(&batches) {
                    pass.set_bind_group(1, bg, &[]);
                    let groups = n.div_ceil(RAY_GROUP);
                    let x = groups.min(65535);
                    pass.dispatch_workgroups(x, groups.div_ceil(x), 1);
                }
            }
            profiler.resolve(&mut encoder, 1);
            ctx.queue.submit([encoder.finish()]);
            if let Some((_, ms)) = profiler.read(ctx, &["rays"])? {
                if run >= WARMUP_RUNS {
                    runs_ms.push(ms);
                }
            }
        }
        let mut results = vec![];
        let mut distances = vec![];
        for (_, output, _) in &batches {
            let words_back: Vec<u32> = ctx.read_buffer(output)?;
            match query {
                RayQuery::AnyHit => results.extend_from_slice(&words_back),
                RayQuery::ClosestHit => {
                    for pair in words_back.chunks_exact(2) {
                        let tri = pair[0];
                        results.push(if tri == u32::MAX {
                            u32::MAX
                        } else {
                            self.tri_order[tri as usize]
                        });
                        distances.push(f32::from_bits(pair[1]));
                    }
                }
            }
        }
        results.truncate(rays.len());
        distances.truncate(rays.len());
        ctx.check()?;
        let hits = match query {
            RayQuery::AnyHit => results.iter().filter(|&&r| r != 0).count(),
            RayQuery::ClosestHit => results.iter().filter(|&&r| r != u32::MAX).count(),
        } as u64;
        Ok(RayTiming {
            runs_ms,
            hits,
            results,
            distances,
        })
    }
}
