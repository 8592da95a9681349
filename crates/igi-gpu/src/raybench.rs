//! The ray-tracing layer measured alone (`igi bench rays`): a ray file traced with the
//! any-hit or closest-hit query of `traverse.wgsl`, timed with timestamp queries, so that
//! another ray tracer (OptiX through Mitsuba, `shared/tools/optix_peer.py`) can trace the
//! very same rays and be compared ray for ray. Any hit has two schedules
//! ([`RaySchedule`]): one ray per thread for coherent batches, persistent subgroups that
//! refill their idle lanes (Aila and Laine 2009, `rays_refill.wgsl`) for incoherent ones.

use crate::context::{GpuContext, GpuError};
use crate::layout::FrameParams;
use crate::passes::bindings::{bind, compute_layout};
use crate::passes::pipeline;
use crate::profiler::{Profiler, WarmUp};
use crate::scene_buffers::{storage_buffer, SceneBuffers};
use crate::shader::ParamsBinding;
use crate::switches::Switches;
use glam::Vec3;
use igi_core::bvh::Bvh;
use igi_core::rays::RayRecord;
use igi_core::scene::Scene;
use igi_core::trace_scale::TraceScale;

/// Untimed runs before the timed ones, the least: they go on for at least
/// [`WARMUP_SECONDS`](crate::profiler::WARMUP_SECONDS).
pub const WARMUP_RUNS: u32 = 3;

/// Threads per workgroup of the ray kernels (`RAY_GROUP` in rays.wgsl).
const RAY_GROUP: u32 = 64;

/// Workgroups of a refill dispatch, whatever the batch: more than the largest GPUs hold at
/// once (an H100 holds about 3,200 of these), since workgroups that start after the batch
/// is handed out leave at once; fewer than the GPU holds left it part idle on an H100
/// (docs/lab/PERFORMANCE.md has the comparison).
const REFILL_GROUPS: u32 = 8192;

/// How the any-hit kernel hands rays to threads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RaySchedule {
    /// One ray per thread, in batch order (`any_hit` of rays.wgsl): best where
    /// neighbouring rays walk alike, as the renderer's VPL-major shadow rays do.
    PerThread,
    /// Persistent subgroups whose idle lanes take the next rays (`rays_refill.wgsl`):
    /// best for incoherent batches, whose warps otherwise wait for their longest walk.
    /// Offered where [`refill_offered`] says.
    Refill,
}

/// Whether the refill schedule runs on this device: a GPU with subgroup operations (the
/// ballot that says when to refill). Not on software adapters: on lavapipe (Mesa 22.3.6)
/// the refill loop returns a few rays in ten thousand untraced (tests/ray_schedules.rs
/// showed it, with every run's results cleared first), even with no subgroup operation
/// in the choice of rays, while on NVIDIA's driver every ray of the bench's ray sets was
/// answered as one ray per thread answers it.
pub fn refill_offered(ctx: &GpuContext) -> bool {
    ctx.subgroups && !ctx.is_software()
}

impl RaySchedule {
    /// The schedule for a batch whose [`coherent_fraction`] is `alike`:
    /// [`RaySchedule::Refill`] unless most neighbouring rays in it are alike or the device
    /// does not offer it ([`refill_offered`]).
    pub fn auto(ctx: &GpuContext, alike: f64) -> RaySchedule {
        if refill_offered(ctx) && alike < 0.5 {
            RaySchedule::Refill
        } else {
            RaySchedule::PerThread
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            RaySchedule::PerThread => "one ray per thread",
            RaySchedule::Refill => "refilled subgroups",
        }
    }
}

/// Of (up to 65,536 evenly spread) pairs of neighbouring rays in a batch, the fraction
/// that are alike: origins within 1% of the scene box's diagonal of each other and
/// directions within about 8 degrees (cosine > 0.99). The renderer's frame set (a warp's
/// worth of neighbouring pixels to one VPL) is mostly alike; random segments are not.
pub fn coherent_fraction(rays: &[RayRecord], scene_lo: Vec3, scene_hi: Vec3) -> f64 {
    let pairs = rays.len().saturating_sub(1);
    if pairs == 0 {
        return 1.0;
    }
    let near = 0.01 * (scene_hi - scene_lo).length();
    let step = pairs.div_ceil(65_536);
    let (mut alike, mut seen) = (0u64, 0u64);
    for i in (0..pairs).step_by(step) {
        let (a, b) = (&rays[i], &rays[i + 1]);
        let (da, db) = (Vec3::from(a.dir), Vec3::from(b.dir));
        let close = Vec3::from(a.origin).distance(Vec3::from(b.origin)) <= near;
        let cos = da.dot(db) / (da.length() * db.length());
        seen += 1;
        alike += u64::from(close && cos > 0.99);
    }
    alike as f64 / seen as f64
}

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

crate::bindings! {
    /// Bind group 1 of rays.wgsl.
    pub struct RayBindings {
        /// Unused by the kernels, but the shared modules declare it.
        params: Params,
        rays: Read,
        results: Write,
    }
}

crate::bindings! {
    /// Bind group 1 of the refill schedule (rays.wgsl's, then rays_refill.wgsl's counter).
    pub struct RefillBindings {
        params: Params,
        rays: Read,
        results: Write,
        /// The next ray to hand out.
        ray_counter: Write,
    }
}

pub struct RayBench {
    scene: SceneBuffers,
    layout: wgpu::BindGroupLayout,
    any_hit: wgpu::ComputePipeline,
    closest_hit: wgpu::ComputePipeline,
    /// The refill schedule's bindings (those of `any_hit` and the ray counter) and
    /// pipeline; None where it is not offered ([`refill_offered`]).
    refill: Option<(wgpu::BindGroupLayout, wgpu::ComputePipeline)>,
    /// Most workgroups of a refill dispatch ([`REFILL_GROUPS`]).
    refill_groups: u32,
    params: wgpu::Buffer,
    tri_order: Vec<u32>,
}

/// Error unless `scene` is traced in its own coordinates ([`TraceScale`] 1): ray files
/// hold rays in the scene's coordinates, and the ray bench measures the traversal as the
/// frame runs it, unscaled.
pub fn own_coordinates(scene: &Scene) -> Result<(), GpuError> {
    let (lo, hi) = scene.bounds();
    let scale = TraceScale::for_bounds(lo, hi);
    if scale.is_one() {
        return Ok(());
    }
    let (a, b) = igi_core::trace_scale::TRACED_RANGE;
    Err(GpuError::Limit(format!(
        "{}: the ray bench traces scenes in their own coordinates, whose largest magnitude must lie in [{a}, {b}); this one's is {:.3e} (igi render and igi view trace it scaled by {})",
        scene.source,
        lo.abs().max(hi.abs()).max_element(),
        scale.factor
    )))
}

impl RayBench {
    pub fn new(ctx: &GpuContext, scene: &Scene, bvh: &Bvh) -> Result<RayBench, GpuError> {
        own_coordinates(scene)?;
        let scene_buffers = SceneBuffers::upload(ctx, scene, bvh)?;
        let switches = Switches::from_env();
        let layout = compute_layout::<RayBindings>(&ctx.device, "rays");
        let layouts = [&scene_buffers.layout, &layout];
        let params = wgpu::util::DeviceExt::create_buffer_init(
            &ctx.device,
            &wgpu::util::BufferInitDescriptor {
                label: Some("rays params"),
                contents: bytemuck::bytes_of(&FrameParams::default()),
                usage: ParamsBinding::of(&ctx.device).usage(),
            },
        );
        let refill = refill_offered(ctx).then(|| {
            let layout = compute_layout::<RefillBindings>(&ctx.device, "rays refill");
            let refill = pipeline(
                &ctx.device,
                &switches,
                "rays_refill",
                "any_hit_refill",
                &[&scene_buffers.layout, &layout],
            );
            (layout, refill)
        });
        Ok(RayBench {
            refill,
            refill_groups: REFILL_GROUPS,
            any_hit: pipeline(&ctx.device, &switches, "rays", "any_hit", &layouts),
            closest_hit: pipeline(&ctx.device, &switches, "rays", "closest_hit", &layouts),
            scene: scene_buffers,
            layout,
            params,
            tri_order: bvh.tri_order.clone(),
        })
    }

    /// At most `groups` (>= 1) workgroups per refill dispatch instead of `REFILL_GROUPS`:
    /// with few of them each lane takes many rays, as on a full GPU (the tests use it).
    pub fn set_refill_groups(&mut self, groups: u32) {
        self.refill_groups = groups.max(1);
    }

    /// Trace `rays` untimed ([`WARMUP_RUNS`] times, and for at least
    /// [`WARMUP_SECONDS`](crate::profiler::WARMUP_SECONDS): the GPU's clocks rise
    /// meanwhile), then `runs` times timed; results of the last run (every run's results
    /// are cleared first, so that a ray a run leaves untraced cannot keep an earlier
    /// run's answer). `schedule`
    /// applies to any hit (closest hits always run one ray per thread);
    /// [`RaySchedule::Refill`] only where [`refill_offered`].
    pub fn trace(
        &self,
        ctx: &GpuContext,
        rays: &[RayRecord],
        query: RayQuery,
        schedule: RaySchedule,
        runs: u32,
    ) -> Result<RayTiming, GpuError> {
        let refill = match (query, schedule) {
            (RayQuery::AnyHit, RaySchedule::Refill) => {
                Some(self.refill.as_ref().ok_or_else(|| {
                    GpuError::Device(format!(
                        "adapter '{}' does not run the refill schedule (it needs a GPU with subgroup operations)",
                        ctx.info.name
                    ))
                })?)
            }
            _ => None,
        };
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
        // The refill schedule's ray counters, one per batch, zeroed before each run.
        let counters: Vec<wgpu::Buffer> = match refill {
            Some(_) => batches
                .iter()
                .map(|_| storage_buffer(ctx, "ray counter", &[0u8; 4]))
                .collect::<Result<_, GpuError>>()?,
            None => vec![],
        };
        let binds: Vec<wgpu::BindGroup> = batches
            .iter()
            .enumerate()
            .map(|(k, (i, o, _))| match refill {
                Some((layout, _)) => {
                    let bindings = RefillBindings {
                        params: &self.params,
                        rays: i,
                        results: o,
                        ray_counter: &counters[k],
                    };
                    bind(&ctx.device, "rays refill", layout, &bindings).group
                }
                None => {
                    let bindings = RayBindings {
                        params: &self.params,
                        rays: i,
                        results: o,
                    };
                    bind(&ctx.device, "rays", &self.layout, &bindings).group
                }
            })
            .collect();
        let pipeline = match (query, refill) {
            (RayQuery::AnyHit, Some((_, refill))) => refill,
            (RayQuery::AnyHit, None) => &self.any_hit,
            (RayQuery::ClosestHit, _) => &self.closest_hit,
        };
        let profiler = Profiler::new(ctx, 1);
        let mut runs_ms = vec![];
        let mut warm_up = WarmUp::new(WARMUP_RUNS);
        let mut timed = 0;
        loop {
            // Once the warm-up says no more, it never says more again.
            let warm = !warm_up.more();
            if warm && timed == runs {
                break;
            }
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            for counter in &counters {
                encoder.clear_buffer(counter, 0, None);
            }
            for (_, output, _) in &batches {
                encoder.clear_buffer(output, 0, None);
            }
            {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("rays"),
                    timestamp_writes: profiler.pass_writes(0),
                });
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, &self.scene.bind_group, &[]);
                for (bg, (_, _, n)) in binds.iter().zip(&batches) {
                    pass.set_bind_group(1, bg, &[]);
                    let mut groups = n.div_ceil(RAY_GROUP);
                    if refill.is_some() {
                        groups = groups.min(self.refill_groups);
                    }
                    let x = groups.min(65535);
                    pass.dispatch_workgroups(x, groups.div_ceil(x), 1);
                }
            }
            profiler.resolve(&mut encoder, 1);
            ctx.queue.submit([encoder.finish()]);
            let ms = profiler.read(ctx, &["rays"])?;
            if warm {
                timed += 1;
                runs_ms.extend(ms.map(|(_, ms)| ms));
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
