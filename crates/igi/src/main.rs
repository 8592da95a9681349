//! `igi`: Instant Global Illumination on the GPU (Marques and Santos), from the command line.
//! `igi render` renders a scene file or a built-in scene to PNG/EXR; `igi info` lists the
//! GPU adapters.

use anyhow::{bail, Context, Result};
use clap::{Args, Parser, Subcommand, ValueEnum};
use igi_core::bvh::Bvh;
use igi_core::scene::{builtin, load_scene, Scene};
use igi_core::settings::{GeometryBound, OutputBuffer, RenderSettings};
use igi_gpu::{AdapterChoice, GpuContext, Renderer};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

#[derive(Parser)]
#[command(
    name = "igi",
    version,
    about = "Instant Global Illumination on the GPU: VPLs from point lights, gathered through shadow rays"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene to an sRGB PNG (and optionally linear OpenEXR).
    Render(RenderArgs),
    /// List the GPU adapters wgpu sees and the one igi would pick.
    Info,
}

#[derive(Clone, Copy, ValueEnum)]
enum BoundArg {
    /// G times smoothstep(0.8 m, 1.2 m, d), as in the paper.
    Smoothstep,
    /// cos cos / max(d^2, m^2), the classic clamp.
    Clamp,
}

#[derive(Clone, Copy, ValueEnum)]
enum BufferArg {
    /// The composed frame.
    Final,
    /// Direct + specular alone.
    Direct,
    /// Indirect diffuse alone, (rho / pi) E.
    Indirect,
    /// The incident indirect term E, without albedo.
    Irradiance,
}

/// Where the scene comes from: a file or a built-in.
#[derive(Args)]
struct SceneArgs {
    /// The scene file (TOML, see docs/SCENE_FORMAT.md).
    #[arg(required_unless_present = "builtin", conflicts_with = "builtin")]
    scene: Option<PathBuf>,
    /// A scene defined in igi itself instead of a file: cornell-box.
    #[arg(long, value_name = "NAME")]
    builtin: Option<String>,
}

#[derive(Args)]
struct FrameArgs {
    /// Image width (default: the scene's film).
    #[arg(long)]
    width: Option<u32>,
    /// Image height (default: the scene's film).
    #[arg(long)]
    height: Option<u32>,
    /// Number of VPLs (the paper uses 30, 90, 180); the actual count is reported.
    #[arg(long, default_value_t = 180)]
    vpls: u32,
    /// Maximum diffuse bounces of a light path (VPLs per path).
    #[arg(long, default_value_t = 8)]
    bounces: u32,
    /// Bounding distance m of the geometry term (default: 5% of the scene's diagonal).
    #[arg(long, value_name = "M")]
    min_dist: Option<f32>,
    /// How G is bounded near VPLs.
    #[arg(long, value_enum, default_value = "smoothstep")]
    bound: BoundArg,
    /// Depth limit of mirror reflections.
    #[arg(long, default_value_t = 6)]
    mirror_depth: u32,
    /// Seed of the VPL set (a window of the Halton sequence).
    #[arg(long, default_value_t = 0)]
    seed: u32,
    /// Adapter to use: an index or part of a name from `igi info` (default: the best).
    #[arg(long)]
    adapter: Option<String>,
}

#[derive(Args)]
struct RenderArgs {
    #[command(flatten)]
    scene: SceneArgs,
    #[command(flatten)]
    frame: FrameArgs,
    /// Output PNG (sRGB, 8 bit).
    #[arg(short, long, value_name = "PNG")]
    output: Option<PathBuf>,
    /// Also write linear radiance as float32 RGB OpenEXR.
    #[arg(long, value_name = "EXR")]
    exr: Option<PathBuf>,
    /// Multiplier applied before tone mapping the PNG (the EXR stays unscaled).
    #[arg(long, default_value_t = 1.0)]
    exposure: f32,
    /// Which buffer to write.
    #[arg(long, value_enum, default_value = "final")]
    buffer: BufferArg,
    /// Print the GPU time of each stage (timestamp queries).
    #[arg(long)]
    timings: bool,
}

fn load(args: &SceneArgs) -> Result<Scene> {
    match (&args.scene, &args.builtin) {
        (_, Some(name)) => builtin::builtin_scene(name).with_context(|| {
            format!(
                "no built-in scene '{name}' (there is: {})",
                builtin::BUILTIN_NAMES.join(", ")
            )
        }),
        (Some(path), None) => Ok(load_scene(path)?),
        (None, None) => bail!("give a scene file or --builtin NAME"),
    }
}

fn settings(scene: &Scene, f: &FrameArgs) -> Result<RenderSettings> {
    if f.vpls == 0 {
        bail!("--vpls must be at least 1");
    }
    if f.bounces == 0 {
        bail!("--bounces must be at least 1");
    }
    if let Some(m) = f.min_dist {
        if !(m.is_finite() && m > 0.0) {
            bail!("--min-dist must be a positive number, got {m}");
        }
    }
    Ok(RenderSettings {
        width: f.width.unwrap_or(scene.film.width),
        height: f.height.unwrap_or(scene.film.height),
        vpls: f.vpls,
        bounces: f.bounces,
        min_dist: f.min_dist,
        geometry_bound: match f.bound {
            BoundArg::Smoothstep => GeometryBound::Smoothstep,
            BoundArg::Clamp => GeometryBound::Clamp,
        },
        mirror_depth: f.mirror_depth,
        seed: f.seed,
        ..RenderSettings::default()
    })
}

fn render(args: &RenderArgs) -> Result<()> {
    if args.output.is_none() && args.exr.is_none() {
        bail!("nothing to write: give -o OUT.png and/or --exr OUT.exr");
    }
    if !(args.exposure.is_finite() && args.exposure > 0.0) {
        bail!(
            "--exposure must be a positive number, got {}",
            args.exposure
        );
    }
    let t = Instant::now();
    let scene = load(&args.scene)?;
    let load_ms = t.elapsed().as_secs_f64() * 1e3;
    let mut settings = settings(&scene, &args.frame)?;
    settings.exposure = args.exposure;
    settings.output = match args.buffer {
        BufferArg::Final => OutputBuffer::Final,
        BufferArg::Direct => OutputBuffer::Direct,
        BufferArg::Indirect => OutputBuffer::Indirect,
        BufferArg::Irradiance => OutputBuffer::Irradiance,
    };
    let t = Instant::now();
    let bvh = Bvh::build(&scene.triangles);
    let bvh_ms = t.elapsed().as_secs_f64() * 1e3;
    eprintln!(
        "scene {}: {} triangles, {} lights (loaded in {load_ms:.0} ms, BVH built in {bvh_ms:.1} ms)",
        scene.source,
        scene.triangles.len(),
        scene.lights.len()
    );
    let ctx = GpuContext::new(&AdapterChoice::from_option(args.frame.adapter.as_deref()))?;
    eprintln!("adapter: {}", ctx.describe());
    let mut renderer = Renderer::new(&ctx, &scene, &bvh)?;
    let frame = renderer.render(&ctx, &settings)?;
    eprintln!(
        "{}x{}: {} VPLs from {} light paths ({} asked), min_dist {:.4}",
        settings.width,
        settings.height,
        frame.vpl_count,
        frame.path_count,
        settings.vpls,
        settings.min_dist_for(&scene)
    );
    if args.timings {
        if frame.stages.is_empty() {
            eprintln!("timings: this adapter has no timestamp queries");
        } else {
            for s in &frame.stages {
                eprintln!("  {:<20} {:>9.3} ms", s.name, s.ms);
            }
            if let Some(ms) = frame.frame_ms {
                eprintln!("  {:<20} {:>9.3} ms", "frame", ms);
            }
        }
    }
    if let Some(path) = &args.exr {
        frame.image.write_exr(path)?;
        eprintln!("wrote {}", path.display());
    }
    if let Some(path) = &args.output {
        frame.image.write_png(path, args.exposure)?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}

fn info() -> Result<()> {
    let (adapters, best) = igi_gpu::context::list_adapters();
    if adapters.is_empty() {
        bail!(igi_gpu::GpuError::NoAdapter);
    }
    for a in &adapters {
        let mark = if Some(a.index) == best { "*" } else { " " };
        println!(
            "{mark} {}: {} ({}, {}, driver: {}, timestamps: {})",
            a.index,
            a.name,
            a.backend,
            a.device_type,
            if a.driver.is_empty() { "?" } else { &a.driver },
            if a.timestamps { "yes" } else { "no" }
        );
    }
    if let Some(i) = best {
        println!("igi would use adapter {i} (marked *); choose another with --adapter INDEX|NAME");
    }
    Ok(())
}

fn main() -> ExitCode {
    env_logger::Builder::from_env(
        env_logger::Env::default()
            .default_filter_or("warn,wgpu_core=error,wgpu_hal=off,naga=error"),
    )
    .format_timestamp(None)
    .init();
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Render(args) => render(args),
        Command::Info => info(),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let msg = format!("{e:#}");
            eprintln!(
                "error: {}",
                msg.split_whitespace().collect::<Vec<_>>().join(" ")
            );
            ExitCode::FAILURE
        }
    }
}
