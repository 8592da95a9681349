//! `igi bench rays`: the ray-tracing layer alone, in rays/s, on generated rays, a real
//! frame's shadow rays or a ray file.

use crate::frame_options::BvhChoice;
use anyhow::{bail, Result};
use clap::{Args, ValueEnum};
use igi_core::bvh::Bvh;
use igi_core::settings::RenderSettings;
use igi_gpu::Renderer;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum RayKindArg {
    Shadow,
    Closest,
    Both,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum RaySetArg {
    /// Segments between (shadow) and rays from (closest) area-uniform random surface points.
    Random,
    /// The VPL shadow rays of a canonical frame (shadow only).
    Frame,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ScheduleArg {
    /// Refilled subgroups unless most neighbouring rays are alike or the adapter does not
    /// run them (software adapters, GPUs without subgroup operations); else one ray per
    /// thread.
    Auto,
    /// One ray per thread, in file order: best for coherent batches.
    PerThread,
    /// Persistent subgroups that refill idle lanes: best for incoherent batches (needs a
    /// GPU with subgroup operations).
    Refill,
}

#[derive(Args)]
pub struct RaysArgs {
    /// The scene file (TOML), or builtin:NAME.
    pub scene: String,
    /// Number of rays.
    #[arg(long, default_value_t = 1 << 24)]
    pub count: usize,
    /// Which query to time.
    #[arg(long, value_enum, default_value = "both")]
    pub kind: RayKindArg,
    /// Which rays.
    #[arg(long, value_enum, default_value = "random")]
    pub set: RaySetArg,
    /// Save the generated rays (with a single --kind).
    #[arg(long, value_name = "FILE", conflicts_with = "load")]
    pub save: Option<PathBuf>,
    /// Trace rays from a file instead of generating them (the file fixes the rays, so the
    /// options that generate them are refused with it).
    // Clap counts only options given on the command line as conflicts, not defaults.
    #[arg(
        long,
        value_name = "FILE",
        conflicts_with_all = ["count", "set", "vpls", "width", "height", "seed"]
    )]
    pub load: Option<PathBuf>,
    /// Timed runs after a warm-up (at least 3 untimed runs and 0.5 s of them, so that the
    /// GPU's clocks are up); the median is reported.
    #[arg(long, default_value_t = 10)]
    pub runs: u32,
    /// How the any-hit query hands rays to GPU threads (closest hits: one per thread).
    #[arg(long, value_enum, default_value = "auto")]
    pub schedule: ScheduleArg,
    /// VPLs of the frame set.
    #[arg(long, default_value_t = 180)]
    pub vpls: u32,
    /// Image size of the frame set (default: the scene's film).
    #[arg(long)]
    pub width: Option<u32>,
    #[arg(long)]
    pub height: Option<u32>,
    #[arg(long, default_value_t = 0)]
    pub seed: u32,
    #[command(flatten)]
    pub bvh: BvhChoice,
    /// Adapter: an index or part of a name from `igi info`.
    #[arg(long)]
    pub adapter: Option<String>,
}

pub fn run(args: &RaysArgs) -> Result<()> {
    use igi_core::rays::{random_rays, random_segments, read_rays, write_rays};
    use igi_gpu::raybench::{coherent_fraction, refill_offered, RayBench, RayQuery, RaySchedule};
    if args.count == 0 {
        bail!("--count must be at least 1");
    }
    // Before any allocation: a huge count would abort on it instead.
    igi_core::rays::check_ray_count(args.count)
        .map_err(|why| anyhow::anyhow!("--count {}: {why}", args.count))?;
    if args.runs == 0 {
        bail!("--runs must be at least 1");
    }
    if args.vpls == 0 {
        bail!("--vpls must be at least 1");
    }
    if args.save.is_some() && args.kind == RayKindArg::Both {
        bail!("--save writes one ray set: give --kind shadow or --kind closest");
    }
    if args.set == RaySetArg::Frame && args.kind != RayKindArg::Shadow && args.load.is_none() {
        bail!("the frame set holds shadow rays: use --kind shadow");
    }
    if args.schedule == ScheduleArg::Refill && args.kind == RayKindArg::Closest {
        bail!("--schedule refill applies to shadow rays (any hit): give --kind shadow or both");
    }
    let save = args.save.as_deref().map(|path| igi::outputs::Output {
        option: "--save",
        path,
        format: igi::outputs::Format::Rays,
        other: "",
    });
    // Before the scene is loaded and the rays are made, which can take long: a name that
    // cannot be written is an error now, and one of the scene's files once it is known.
    igi::outputs::check(save.as_slice(), &[])?;
    // The GPU is set up while the scene loads, as for `igi render`; with the frame's
    // passes only where a frame makes the rays.
    let frame_rays = args.set == RaySetArg::Frame && args.load.is_none();
    let gpu = if frame_rays {
        igi::gpu_set_up::GpuSetUp::start(args.adapter.clone())?
    } else {
        igi::gpu_set_up::GpuSetUp::start_context(args.adapter.clone())?
    };
    let loaded = igi::bench::run::load(&args.scene).and_then(|scene| {
        igi::outputs::check(save.as_slice(), &scene.files)?;
        Ok(scene)
    });
    let scene = match loaded {
        Ok(scene) => scene,
        Err(e) => {
            gpu.abandon();
            return Err(e);
        }
    };
    // Before the build, which takes every core: an adapter that cannot run the benchmark
    // is said before it.
    let (ctx, mut passes) = if frame_rays {
        let (ctx, passes) = gpu.join()?;
        (ctx, Some(passes))
    } else {
        (gpu.join_context()?, None)
    };
    if !ctx.timestamps {
        bail!(
            "adapter '{}' has no timestamp queries: igi bench rays needs them",
            ctx.info.name
        );
    }
    if args.schedule == ScheduleArg::Refill && !refill_offered(&ctx) {
        bail!(
            "adapter '{}' does not run --schedule refill (it needs a GPU with subgroup operations): use --schedule per-thread",
            ctx.info.name
        );
    }
    let t = Instant::now();
    let builder = args.bvh.builder.into();
    let bvh = Bvh::build_with(&scene.triangles, builder);
    let bvh_ms = t.elapsed().as_secs_f64() * 1e3;
    igi::note!(
        "scene {}: {} triangles, {}; adapter: {}",
        scene.source,
        scene.triangles.len(),
        igi::bvh_built(&bvh, builder, bvh_ms),
        ctx.describe()
    );
    let queries: Vec<RayQuery> = match args.kind {
        RayKindArg::Shadow => vec![RayQuery::AnyHit],
        RayKindArg::Closest => vec![RayQuery::ClosestHit],
        RayKindArg::Both => vec![RayQuery::AnyHit, RayQuery::ClosestHit],
    };
    let bench = RayBench::new(&ctx, &scene, &bvh)?;
    for query in queries {
        let rays = match (&args.load, args.set, query) {
            (Some(path), _, _) => read_rays(path)?,
            (None, RaySetArg::Random, RayQuery::AnyHit) => {
                random_segments(&scene, args.count, args.seed)
            }
            (None, RaySetArg::Random, RayQuery::ClosestHit) => {
                random_rays(&scene, args.count, args.seed)
            }
            (None, RaySetArg::Frame, _) => {
                let settings = RenderSettings {
                    width: args.width.unwrap_or(scene.film.width),
                    height: args.height.unwrap_or(scene.film.height),
                    vpls: args.vpls,
                    seed: args.seed,
                    ..RenderSettings::for_scene(&scene)
                };
                settings.validate()?;
                let mut renderer = match passes.take() {
                    Some(passes) => Renderer::with_passes(&ctx, passes, &scene, &bvh)?,
                    None => Renderer::new(&ctx, &scene, &bvh)?,
                };
                renderer.frame_shadow_rays(&ctx, &settings, args.count)?
            }
        };
        if let Some(path) = &args.save {
            write_rays(path, &rays)?;
            igi::note!("wrote {} rays to {}", rays.len(), path.display());
        }
        // Closest hits run one ray per thread whatever the schedule.
        let mut schedule = RaySchedule::PerThread;
        if query == RayQuery::AnyHit {
            let (lo, hi) = bvh.bounds();
            let alike = coherent_fraction(&rays, lo, hi);
            schedule = match args.schedule {
                ScheduleArg::Auto => RaySchedule::auto(&ctx, alike),
                ScheduleArg::PerThread => RaySchedule::PerThread,
                ScheduleArg::Refill => RaySchedule::Refill,
            };
            let alike = 100.0 * alike;
            let why = match args.schedule {
                ScheduleArg::Auto if !refill_offered(&ctx) => {
                    "auto: this adapter does not run the refill schedule".to_string()
                }
                ScheduleArg::Auto => format!("auto: {alike:.1}% of neighbouring rays alike"),
                _ => format!("asked; {alike:.1}% of neighbouring rays alike"),
            };
            igi::note!("any-hit schedule: {} ({why})", schedule.name());
        }
        let timing = bench.trace(&ctx, &rays, query, schedule, args.runs)?;
        let mut runs = timing.runs_ms.clone();
        runs.sort_by(f64::total_cmp);
        let median = runs[runs.len() / 2];
        let name = match query {
            RayQuery::AnyHit => format!("shadow (any hit) by {}", schedule.name()),
            RayQuery::ClosestHit => "closest hit".to_string(),
        };
        // A hash of every answer, so that two traversals (or builds) of the same ray file
        // can be checked to answer the same, not only to be as fast.
        let answers = igi_core::fingerprint::fnv1a(
            timing
                .results
                .iter()
                .copied()
                .chain(timing.distances.iter().map(|d| d.to_bits()))
                .map(u64::from),
        );
        igi::say!(
            "{name}: {} rays, {} {} ({:.1}%, answers hash {answers:016x}), median {median:.3} ms over {} runs (min {:.3}, max {:.3}): {:.3} G rays/s",
            rays.len(),
            timing.hits,
            if query == RayQuery::AnyHit { "occluded" } else { "hit" },
            100.0 * timing.hits as f64 / rays.len() as f64,
            runs.len(),
            runs[0],
            runs[runs.len() - 1],
            rays.len() as f64 / median * 1e-6
        );
    }
    Ok(())
}
