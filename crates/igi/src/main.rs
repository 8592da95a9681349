//! `igi`: Instant Global Illumination on the GPU (Marques and Santos), from the command line.
//! `igi render` renders a scene file or a built-in scene to PNG/EXR; `igi view` opens the
//! interactive viewer; `igi bench` measures; `igi info` lists the GPU adapters.

use anyhow::{bail, Context, Result};
use clap::{Args, CommandFactory, FromArgMatches, Parser, Subcommand, ValueEnum};
use igi_core::bvh::{Bvh, BvhBuilder};
use igi_core::scene::{builtin, load_scene, Scene};
use igi_core::settings::{
    Accelerations, FilterMode, GeometryBound, InterleavePattern, OutputBuffer, RenderSettings,
    MAX_MIRROR_DEPTH,
};
use igi_gpu::{AdapterChoice, Renderer};
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
    /// Open a window: fly through the scene, change any option and watch the GPU times;
    /// a still view converges (frames with fresh VPL sets are averaged).
    View(ViewArgs),
    /// List the GPU adapters wgpu sees and the one igi would pick.
    Info,
    /// Measure like the paper: GPU time per stage, fps, rays and image error for every
    /// scene x set-up x VPL count; writes results.json/.csv/.md, charts and images.
    Bench(BenchCommand),
    /// Compare a linear image with a reference (OpenEXR): relative MSE and channel means.
    Compare {
        /// The image to measure.
        image: PathBuf,
        /// The reference it is measured against.
        reference: PathBuf,
    },
}

#[derive(Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
struct BenchCommand {
    #[command(subcommand)]
    sub: Option<BenchSub>,
    #[command(flatten)]
    args: BenchArgs,
}

#[derive(Subcommand)]
enum BenchSub {
    /// The ray-tracing layer alone: rays/s of the any-hit and closest-hit queries on a ray
    /// set (random segments and rays, or the VPL shadow rays of a real frame), in the ray
    /// file format of docs/BENCHMARKS.md so another tracer can trace the very same rays.
    Rays(RaysArgs),
    /// The BVH build alone, on the CPU: median wall time of several builds in this
    /// process, its phases, the tree's size and SAH cost.
    Build(BuildArgs),
}

#[derive(Args)]
struct BuildArgs {
    /// Scene files (TOML), or builtin:NAME.
    #[arg(required = true)]
    scenes: Vec<String>,
    /// Builds of each scene in this process; the median is reported. Later builds reuse
    /// memory that the first had to map: `--runs 1` in a new process is what `igi render`
    /// pays.
    #[arg(long, default_value_t = 5)]
    runs: u32,
    #[command(flatten)]
    bvh: BvhChoice,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum RayKindArg {
    Shadow,
    Closest,
    Both,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum RaySetArg {
    /// Segments between (shadow) and rays from (closest) area-uniform random surface points.
    Random,
    /// The VPL shadow rays of a canonical frame (shadow only).
    Frame,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum ScheduleArg {
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
struct RaysArgs {
    /// The scene file (TOML), or builtin:NAME.
    scene: String,
    /// Number of rays.
    #[arg(long, default_value_t = 1 << 24)]
    count: usize,
    /// Which query to time.
    #[arg(long, value_enum, default_value = "both")]
    kind: RayKindArg,
    /// Which rays.
    #[arg(long, value_enum, default_value = "random")]
    set: RaySetArg,
    /// Save the generated rays (with a single --kind).
    #[arg(long, value_name = "FILE", conflicts_with = "load")]
    save: Option<PathBuf>,
    /// Trace rays from a file instead of generating them (the file fixes the rays, so the
    /// options that generate them are refused with it).
    // Clap counts only options given on the command line as conflicts, not defaults.
    #[arg(
        long,
        value_name = "FILE",
        conflicts_with_all = ["count", "set", "vpls", "width", "height", "seed"]
    )]
    load: Option<PathBuf>,
    /// Timed runs after a warm-up (at least 3 untimed runs and 0.5 s of them, so that the
    /// GPU's clocks are up); the median is reported.
    #[arg(long, default_value_t = 10)]
    runs: u32,
    /// How the any-hit query hands rays to GPU threads (closest hits: one per thread).
    #[arg(long, value_enum, default_value = "auto")]
    schedule: ScheduleArg,
    /// VPLs of the frame set.
    #[arg(long, default_value_t = 180)]
    vpls: u32,
    /// Image size of the frame set (default: the scene's film).
    #[arg(long)]
    width: Option<u32>,
    #[arg(long)]
    height: Option<u32>,
    #[arg(long, default_value_t = 0)]
    seed: u32,
    #[command(flatten)]
    bvh: BvhChoice,
    /// Adapter: an index or part of a name from `igi info`.
    #[arg(long)]
    adapter: Option<String>,
}

#[derive(Args)]
struct BenchArgs {
    /// Scene files (TOML), or builtin:NAME.
    #[arg(required = true)]
    scenes: Vec<String>,
    /// VPL counts, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "30,90,180")]
    vpls: Vec<u32>,
    /// Set-ups, comma-separated: canonical, or iv, ds, il, irregular, fused joined by '+'.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "canonical,iv,iv+ds,iv+ds+il"
    )]
    setups: Vec<String>,
    /// Timed frames per combination.
    #[arg(long, default_value_t = 10)]
    frames: u32,
    /// Untimed frames before them.
    #[arg(long, default_value_t = 3)]
    warmup: u32,
    /// Reference image (EXR) for one scene; otherwise one is looked for beside each scene
    /// (../../references/NAME-full.exr, or NAME-reference.exr).
    #[arg(long, value_name = "EXR")]
    reference: Option<PathBuf>,
    /// Output directory.
    #[arg(long, default_value = "bench-out")]
    out: PathBuf,
    /// Image width (default: each scene's film).
    #[arg(long)]
    width: Option<u32>,
    /// Image height (default: each scene's film).
    #[arg(long)]
    height: Option<u32>,
    #[arg(long, default_value_t = 0)]
    seed: u32,
    #[command(flatten)]
    bvh: BvhChoice,
    /// Adapter: an index or part of a name from `igi info`.
    #[arg(long)]
    adapter: Option<String>,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
}

/// The `--bvh` option of every command that builds a BVH.
#[derive(Args)]
struct BvhChoice {
    /// BVH builder: split (early split clipping of long thin triangles: a faster walk)
    /// or binned (whole triangles: a faster build).
    #[arg(long = "bvh", value_enum, default_value = "split")]
    builder: BvhArg,
}

#[derive(Clone, Copy, ValueEnum)]
enum BvhArg {
    /// Binned SAH with early split clipping of long thin triangles.
    Split,
    /// Binned SAH over whole triangles.
    Binned,
}

impl From<BvhArg> for BvhBuilder {
    fn from(a: BvhArg) -> BvhBuilder {
        match a {
            BvhArg::Binned => BvhBuilder::Binned,
            BvhArg::Split => BvhBuilder::Split,
        }
    }
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
    /// G-buffer shading normals as 0.5 + 0.5 n.
    Normals,
    /// G-buffer distance from the camera over the scene's diagonal.
    Depth,
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
    /// Depth limit of mirror reflections (at most 1024).
    #[arg(long, default_value_t = 6)]
    mirror_depth: u32,
    /// Seed of the VPL set (a window of the Halton sequence).
    #[arg(long, default_value_t = 0)]
    seed: u32,
    #[command(flatten)]
    bvh: BvhChoice,
    /// Adapter to use: an index or part of a name from `igi info` (default: the best).
    #[arg(long)]
    adapter: Option<String>,
    #[command(flatten)]
    accel: AccelArgs,
}

/// The paper's accelerations (sections 4.1-4.3) and their filters.
#[derive(Args, Clone)]
struct AccelArgs {
    /// A set-up by name, as in the paper's table: canonical, or iv, ds, il (and irregular,
    /// which needs il, and fused, which needs ds or il) joined by '+', e.g. iv+ds+il. The
    /// options below adjust it.
    #[arg(long, value_name = "NAME")]
    setup: Option<String>,
    /// VPL shadow rays test triangle bounding boxes instead of triangles.
    #[arg(long)]
    imperfect_visibility: bool,
    /// Indirect light at 1/S of the resolution per axis, then joint bilateral upsampling.
    #[arg(long, value_name = "S")]
    downsample: Option<u32>,
    /// Interleaved sampling over NxM VPL subsets (N x M at most 64), then the discontinuity
    /// buffer (e.g. 3x3).
    #[arg(long, value_name = "NxM", value_parser = parse_interleave)]
    interleave: Option<(u32, u32)>,
    /// How subsets are laid out in a tile (irregular needs interleaving).
    #[arg(long, value_enum)]
    pattern: Option<PatternArg>,
    /// Discontinuity buffer and upsampling as two passes, or fused in one (fused needs
    /// downsampling or interleaving).
    #[arg(long, value_enum)]
    filter: Option<FilterArg>,
    /// Spatial sigma of the upsampler, in low-resolution pixels.
    #[arg(long, value_name = "PIXELS")]
    upsample_sigma: Option<f32>,
    /// Exponent k of the upsampler's normal weight (N_p . N_q)^k (the paper: 1).
    #[arg(long, value_name = "K")]
    normal_power: Option<f32>,
    /// Leave depth out of the upsampler's range weight (the paper's normal-only weight).
    #[arg(long)]
    no_upsample_depth: bool,
    /// Relative depth difference that counts as a discontinuity.
    #[arg(long, value_name = "FRACTION")]
    depth_threshold: Option<f32>,
    /// Smallest normal dot product of continuous neighbours.
    #[arg(long, value_name = "COS")]
    normal_threshold: Option<f32>,
    /// Average K frames, each with a fresh VPL set (a still camera converges).
    #[arg(long, value_name = "K", default_value_t = 1)]
    accumulate: u32,
}

#[derive(Clone, Copy, ValueEnum)]
enum PatternArg {
    Regular,
    Irregular,
}

#[derive(Clone, Copy, ValueEnum)]
enum FilterArg {
    TwoPass,
    Fused,
}

fn parse_interleave(s: &str) -> Result<(u32, u32), String> {
    let (n, m) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("'{s}' is not NxM (e.g. 3x3)"))?;
    let parse = |v: &str| {
        let v = v.trim();
        v.parse::<u32>().map_err(|e| match e.kind() {
            std::num::IntErrorKind::PosOverflow => {
                format!("{v} is too large: N x M must be at most 64 subsets")
            }
            _ => format!("'{s}' is not NxM (e.g. 3x3)"),
        })
    };
    let (n, m) = (parse(n)?, parse(m)?);
    if n == 0 || m == 0 {
        return Err(format!("{n}x{m}: each side must be at least 1"));
    }
    // In u64: a product of two u32 sides can wrap around to a small number.
    let subsets = u64::from(n) * u64::from(m);
    if subsets > 64 {
        return Err(format!(
            "{n}x{m} is {subsets} subsets: N x M must be at most 64"
        ));
    }
    Ok((n, m))
}

impl AccelArgs {
    fn accelerations(&self) -> Result<Accelerations> {
        let mut a = match &self.setup {
            Some(name) => {
                Accelerations::from_setup(name).map_err(|e| anyhow::anyhow!("--setup: {e}"))?
            }
            None => Accelerations::default(),
        };
        if self.imperfect_visibility {
            a.imperfect_visibility = true;
        }
        if let Some(s) = self.downsample {
            if s == 0 || s > 64 {
                bail!("--downsample must be between 1 and 64, got {s}");
            }
            a.downsample = s;
        }
        if let Some(il) = self.interleave {
            a.interleave = il;
        }
        if let Some(p) = self.pattern {
            a.pattern = match p {
                PatternArg::Regular => InterleavePattern::Regular,
                PatternArg::Irregular => InterleavePattern::Irregular,
            };
        }
        if let Some(f) = self.filter {
            a.filter = match f {
                FilterArg::TwoPass => FilterMode::TwoPass,
                FilterArg::Fused => FilterMode::Fused,
            };
        }
        let positive = |name: &str, v: Option<f32>| -> Result<Option<f32>> {
            match v {
                Some(x) if !(x.is_finite() && x > 0.0) => {
                    bail!("--{name} must be a positive number, got {x}")
                }
                v => Ok(v),
            }
        };
        if let Some(v) = positive("upsample-sigma", self.upsample_sigma)? {
            a.upsample_sigma = v;
        }
        if let Some(v) = self.normal_power {
            if !(v.is_finite() && v >= 0.0) {
                bail!("--normal-power must be a number >= 0, got {v}");
            }
            a.upsample_normal_power = v;
        }
        if self.no_upsample_depth {
            a.upsample_depth = false;
        }
        if let Some(v) = positive("depth-threshold", self.depth_threshold)? {
            a.depth_threshold = v;
        }
        if let Some(v) = self.normal_threshold {
            if !(-1.0..=1.0).contains(&v) {
                bail!("--normal-threshold must be between -1 and 1, got {v}");
            }
            a.normal_threshold = v;
        }
        // A set-up name was checked whole by from_setup, so an idle modifier here came
        // from --pattern or --filter, or the options switched its acceleration off.
        let named = |option: &str, given: bool| match (&self.setup, given) {
            (Some(setup), false) => format!("{option} (from --setup {setup})"),
            _ => option.to_string(),
        };
        match a.idle_modifier() {
            Some("irregular") => bail!(
                "{} lays out interleaved VPL subsets: it needs --interleave NxM (or il in --setup)",
                named("--pattern irregular", self.pattern.is_some())
            ),
            Some(_) => bail!(
                "{} runs the filters of downsampling and interleaving in one pass: it needs --downsample S or --interleave NxM (or ds or il in --setup)",
                named("--filter fused", self.filter.is_some())
            ),
            None => Ok(a),
        }
    }
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

#[derive(Args)]
struct ViewArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Image size and the options of the frame; with --width/--height the image keeps that
    /// size (letterboxed in the window), otherwise it follows the window.
    #[command(flatten)]
    frame: FrameArgs,
    /// Multiplier applied before tone mapping (the panel changes it).
    #[arg(long, default_value_t = 1.0)]
    exposure: f32,
    /// Which buffer to show first.
    #[arg(long, value_enum, default_value = "final")]
    buffer: BufferArg,
    /// Start from this camera: a TOML file with a [camera] table, or the TOML itself
    /// (as the C key prints it), instead of the scene's.
    #[arg(long, value_name = "FILE|TOML")]
    camera: Option<String>,
    /// Render N frames, then exit (with --screenshot: save it first).
    #[arg(long, value_name = "N")]
    frames: Option<u32>,
    /// Where screenshots go: PNG at the panel's exposure, and the linear frame as EXR
    /// beside it (default: igi-screenshot-N.png in the working directory).
    #[arg(long, value_name = "PNG")]
    screenshot: Option<PathBuf>,
    /// Still frames averaged at most.
    #[arg(long, default_value_t = 256)]
    max_accumulate: u32,
    /// Render at 1/S of the window's resolution (faster on slow adapters).
    #[arg(long, value_name = "S", default_value_t = 1)]
    scale: u32,
    /// Draw the VPLs as dots.
    #[arg(long)]
    vpl_dots: bool,
    /// Initial window size in pixels, WxH.
    #[arg(long, value_name = "WxH", default_value = "1280x720", value_parser = parse_size)]
    window: (u32, u32),
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let bad = || format!("'{s}' is not WxH (e.g. 1280x720)");
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let (w, h) = (
        w.trim().parse::<u32>().map_err(|_| bad())?,
        h.trim().parse::<u32>().map_err(|_| bad())?,
    );
    if w == 0 || h == 0 || w > 16384 || h > 16384 {
        return Err(format!("window {w}x{h}: sides between 1 and 16384"));
    }
    Ok((w, h))
}

fn output_buffer(b: BufferArg) -> OutputBuffer {
    match b {
        BufferArg::Final => OutputBuffer::Final,
        BufferArg::Direct => OutputBuffer::Direct,
        BufferArg::Indirect => OutputBuffer::Indirect,
        BufferArg::Irradiance => OutputBuffer::Irradiance,
        BufferArg::Normals => OutputBuffer::Normals,
        BufferArg::Depth => OutputBuffer::Depth,
    }
}

fn view(args: &ViewArgs) -> Result<()> {
    if !(args.exposure.is_finite() && args.exposure > 0.0) {
        bail!(
            "--exposure must be a positive number, got {}",
            args.exposure
        );
    }
    if args.frames == Some(0) {
        bail!("--frames must be at least 1");
    }
    if args.scale == 0 || args.scale > 64 {
        bail!("--scale must be between 1 and 64, got {}", args.scale);
    }
    if args.max_accumulate == 0 {
        bail!("--max-accumulate must be at least 1");
    }
    if let Some(dir) = args.screenshot.as_ref().and_then(|p| p.parent()) {
        if !dir.as_os_str().is_empty() && !dir.is_dir() {
            bail!("--screenshot: directory {} does not exist", dir.display());
        }
    }
    if let Some(path) = &args.screenshot {
        // The PNG's name: the EXR goes beside it, with the extension .exr.
        let png = igi::outputs::Output {
            option: "--screenshot",
            path,
            format: igi::outputs::Format::Png,
            other: "the EXR is written beside the PNG",
        };
        igi::outputs::check(&[png], &[])?;
    }
    let camera = match &args.camera {
        None => None,
        Some(text) => {
            let path = std::path::Path::new(text);
            let (text, name) = if !text.contains('=') {
                // Text without '=' is taken for a file name, so a missing file may as
                // well be mistyped TOML: the message says what either form looks like.
                let bytes = igi_core::scene::loader::read_regular_file(path).map_err(|e| {
                    if e.kind() == std::io::ErrorKind::NotFound {
                        anyhow::anyhow!(
                            "--camera '{}': no such file (give a TOML file with a [camera] table, or that TOML itself: eye = [...] ...)",
                            path.display()
                        )
                    } else {
                        anyhow::Error::new(e).context(format!("--camera '{}'", path.display()))
                    }
                })?;
                let text = String::from_utf8(bytes).map_err(|_| {
                    anyhow::anyhow!("--camera '{}': not UTF-8 text", path.display())
                })?;
                (text, path.display().to_string())
            } else {
                (text.clone(), "--camera".to_string())
            };
            Some(igi_core::scene::parse_camera_toml(&text, &name)?)
        }
    };
    check_frame_args(&args.frame)?;
    let scene = load(&args.scene)?;
    let mut settings = settings(&scene, &args.frame)?;
    settings.exposure = args.exposure;
    settings.output = output_buffer(args.buffer);
    let fixed_size = match (args.frame.width, args.frame.height) {
        (None, None) => None,
        (w, h) => Some((
            w.unwrap_or(scene.film.width),
            h.unwrap_or(scene.film.height),
        )),
    };
    if let Some((w, h)) = fixed_size {
        if w == 0 || h == 0 {
            bail!("image size {w}x{h}: both must be at least 1");
        }
    }
    igi::view::run(igi::view::ViewOptions {
        settings,
        fixed_size,
        adapter: AdapterChoice::from_option(args.frame.adapter.as_deref()),
        camera,
        frames: args.frames,
        screenshot: args.screenshot.clone(),
        max_accumulate: args.max_accumulate.max(args.frame.accel.accumulate),
        render_scale: args.scale,
        show_vpls: args.vpl_dots,
        bvh: args.frame.bvh.builder.into(),
        window: args.window,
        scene,
    })
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

/// The frame options' own errors, which need no scene: checked before the scene is
/// loaded (which can take seconds), and again by [`settings`].
fn check_frame_args(f: &FrameArgs) -> Result<()> {
    if f.vpls == 0 {
        bail!("--vpls must be at least 1");
    }
    if f.bounces == 0 {
        bail!("--bounces must be at least 1");
    }
    if f.accel.accumulate == 0 {
        bail!("--accumulate must be at least 1");
    }
    if f.mirror_depth > MAX_MIRROR_DEPTH {
        bail!(
            "--mirror-depth must be at most {MAX_MIRROR_DEPTH}, got {}",
            f.mirror_depth
        );
    }
    if let Some(m) = f.min_dist {
        if !(m.is_finite() && m > 0.0) {
            bail!("--min-dist must be a positive number, got {m}");
        }
    }
    f.accel.accelerations()?;
    Ok(())
}

fn settings(scene: &Scene, f: &FrameArgs) -> Result<RenderSettings> {
    check_frame_args(f)?;
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
        accelerations: f.accel.accelerations()?,
        accumulate: f.accel.accumulate,
        ..RenderSettings::default()
    })
}

/// Every output of `igi render` checked before anything is rendered (see igi::outputs):
/// with no scene before it is loaded, then against the files it was read from.
fn check_render_outputs(args: &RenderArgs, scene: Option<&Scene>) -> Result<()> {
    use igi::outputs::{Format, Output};
    let png = args.output.as_deref().map(|path| Output {
        option: "-o",
        path,
        format: Format::Png,
        other: "write EXR with --exr",
    });
    let exr = args.exr.as_deref().map(|path| Output {
        option: "--exr",
        path,
        format: Format::Exr,
        other: "write PNG with -o",
    });
    let outputs: Vec<Output> = png.into_iter().chain(exr).collect();
    igi::outputs::check(&outputs, scene.map_or(&[], |s| &s.files))
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
    check_frame_args(&args.frame)?;
    check_render_outputs(args, None)?;
    let gpu = igi::gpu_set_up::GpuSetUp::start(args.frame.adapter.clone())?;
    let t = Instant::now();
    let loaded = load(&args.scene).and_then(|scene| {
        let load_ms = t.elapsed().as_secs_f64() * 1e3;
        let settings = settings(&scene, &args.frame)?;
        check_render_outputs(args, Some(&scene))?;
        Ok((scene, load_ms, settings))
    });
    let (scene, load_ms, mut settings) = match loaded {
        Ok(loaded) => loaded,
        Err(e) => {
            gpu.abandon();
            return Err(e);
        }
    };
    // Before the build, which takes every core.
    let (ctx, passes) = gpu.join()?;
    settings.exposure = args.exposure;
    settings.output = output_buffer(args.buffer);
    let t = Instant::now();
    let builder = args.frame.bvh.builder.into();
    let bvh = Bvh::build_with(&scene.triangles, builder);
    let bvh_ms = t.elapsed().as_secs_f64() * 1e3;
    eprintln!(
        "scene {}: {} triangles, {} lights (loaded in {load_ms:.0} ms, {})",
        scene.source,
        scene.triangles.len(),
        scene.lights.len(),
        igi::bvh_built(&bvh, builder, bvh_ms)
    );
    eprintln!("adapter: {}", ctx.describe());
    let mut renderer = Renderer::with_passes(&ctx, passes, &scene, &bvh)?;
    let frame = if settings.accumulate > 1 {
        // Frames done and the time left, on a terminal (indicatif draws nothing elsewhere).
        let bar = indicatif::ProgressBar::new(settings.accumulate as u64).with_style(
            indicatif::ProgressStyle::with_template("{bar:30} {pos}/{len} frames, {eta} left")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        let frame = renderer.render_with_progress(&ctx, &settings, |k| bar.set_position(k as u64));
        bar.finish_and_clear();
        frame?
    } else {
        renderer.render(&ctx, &settings)?
    };
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
        if let Some(why) = &a.unusable {
            println!("     unusable: it {why}");
        }
    }
    if let Some(i) = best {
        println!("igi would use adapter {i} (marked *); choose another with --adapter INDEX|NAME");
    }
    Ok(())
}

fn bench(args: &BenchArgs) -> Result<()> {
    let opts = igi::bench::run::BenchOptions {
        scenes: args.scenes.clone(),
        vpls: args.vpls.clone(),
        setups: args.setups.clone(),
        frames: args.frames,
        warmup: args.warmup,
        reference: args.reference.clone(),
        out: args.out.clone(),
        width: args.width,
        height: args.height,
        seed: args.seed,
        bvh: args.bvh.builder.into(),
        adapter: args.adapter.clone(),
        quiet: args.quiet,
        command: std::env::args().collect::<Vec<_>>().join(" "),
    };
    let results = igi::bench::run::run(&opts)?;
    for warning in igi::bench::report::write_all(&results, &args.out)? {
        eprintln!("warning: {warning}");
    }
    if !args.quiet {
        println!("{}", igi::bench::report::to_markdown(&results));
    }
    eprintln!("wrote {}", args.out.join("results.json").display());
    Ok(())
}

fn bench_rays(args: &RaysArgs) -> Result<()> {
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
    eprintln!(
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
                let mut renderer = match passes.take() {
                    Some(passes) => Renderer::with_passes(&ctx, passes, &scene, &bvh)?,
                    None => Renderer::new(&ctx, &scene, &bvh)?,
                };
                renderer.frame_shadow_rays(&ctx, &settings, args.count)?
            }
        };
        if let Some(path) = &args.save {
            write_rays(path, &rays)?;
            eprintln!("wrote {} rays to {}", rays.len(), path.display());
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
            eprintln!("any-hit schedule: {} ({why})", schedule.name());
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
        println!(
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

fn compare(image: &std::path::Path, reference: &std::path::Path) -> Result<()> {
    let a = igi_core::image::Image::read_exr(image)?;
    let b = igi_core::image::Image::read_exr(reference)?;
    let e = igi_core::image::rel_mse(&a, &b)?;
    let (ma, mb) = (a.mean(), b.mean());
    // Five decimals as before, and the figure itself where they would round it to 0.
    if e > 0.0 && e < 5e-6 {
        println!("relMSE {e:.5} ({e:.2e})");
    } else {
        println!("relMSE {e:.5}");
    }
    println!(
        "mean {:.4} {:.4} {:.4} (reference {:.4} {:.4} {:.4})",
        ma[0], ma[1], ma[2], mb[0], mb[1], mb[2]
    );
    let d = igi_core::image::pixel_differences(&a, &b)?;
    match d.largest {
        None => println!("pixels differing: none of {} (the same bits)", d.pixels),
        Some((diff, (x, y), r)) => println!(
            "pixels differing: {} of {}; largest difference {diff:.3e} at ({x}, {y}), where the reference is {r:.4e}",
            d.differing, d.pixels
        ),
    }
    Ok(())
}

/// The Rust runtime ignores SIGPIPE, so that a write to a closed pipe (`igi info | head
/// -0`, or a pager quit early) returns an error, which print! turns into a panic. Like
/// other Unix tools, igi stops quietly there instead: the default action of SIGPIPE.
/// Image files are written under a temporary name and renamed into place
/// (igi_core::image), so such a stop leaves no half-written file under an output's name.
#[cfg(unix)]
fn quiet_on_closed_pipes() {
    // SAFETY: called first in main, before any thread exists; SIG_DFL is a valid action.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

/// Mesa's Vulkan drivers (lavapipe among them) connect to a Wayland display when an
/// instance is made, for window surfaces; where `XDG_RUNTIME_DIR` is not set
/// (containers, CI runners, many ssh sessions), libwayland then prints "error:
/// XDG_RUNTIME_DIR is invalid or not set in the environment." once per instance, lines
/// that read like igi failing and that break the one error line of a real failure. For
/// the commands that open no window, a `WAYLAND_DISPLAY` that is an absolute path to no
/// socket makes that connection fail without a word (libwayland needs no runtime
/// directory for an absolute path). Where a Wayland session is set up, nothing changes.
#[cfg(unix)]
fn no_wayland_for_headless_commands() {
    let set = |name: &str| std::env::var_os(name).is_some_and(|v| !v.is_empty());
    let runtime_dir =
        std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| std::path::Path::new(&d).is_absolute());
    if !runtime_dir && !set("WAYLAND_DISPLAY") && !set("WAYLAND_SOCKET") {
        // Called in main before any other thread exists (see main), so no thread can
        // read the environment while it changes.
        std::env::set_var("WAYLAND_DISPLAY", "/nonexistent/igi-opens-no-window");
    }
}

/// `cmd` and its subcommands, each option that takes a value taking a negative number as
/// one (see [`parse_command_line`]). Flags take no value, and clap refuses the setting on
/// them.
fn negative_numbers_as_values(cmd: clap::Command) -> clap::Command {
    cmd.mut_args(|a| {
        let takes_value = a.get_action().takes_values();
        a.allow_negative_numbers(takes_value)
    })
    .mut_subcommands(negative_numbers_as_values)
}

/// The command line, with a negative number taken as the value of the option before it:
/// clap's default reads `--exposure -1` as a stray flag ("unexpected argument '-1'", with
/// a tip to write `-- -1`), and a valid `--normal-threshold -0.5` needed `=`. Every
/// option of every subcommand that takes a value gets the setting here, so that igi's own checks answer
/// ("--exposure must be a positive number, got -1", or clap's "-5 is not in 0..=...").
fn parse_command_line() -> Cli {
    let mut cmd = negative_numbers_as_values(Cli::command());
    let matches = cmd.get_matches_mut();
    Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.format(&mut cmd).exit())
}

fn main() -> ExitCode {
    #[cfg(unix)]
    quiet_on_closed_pipes();
    let cli = parse_command_line();
    #[cfg(unix)]
    if !matches!(cli.command, Command::View(_)) {
        no_wayland_for_headless_commands();
    }
    // The first thread besides main: the environment is settled by now.
    #[cfg(unix)]
    if let Err(e) = igi::outputs::remove_partial_files_on_signals() {
        eprintln!("error: cannot handle signals: {}", error_line(&e));
        return ExitCode::FAILURE;
    }
    env_logger::Builder::from_env(
        env_logger::Env::default()
            .default_filter_or("warn,wgpu_core=error,wgpu_hal=off,naga=error"),
    )
    .format_timestamp(None)
    .init();
    let result = match &cli.command {
        Command::Render(args) => render(args),
        Command::View(args) => view(args),
        Command::Info => info(),
        Command::Bench(cmd) => match &cmd.sub {
            Some(BenchSub::Rays(r)) => bench_rays(r),
            Some(BenchSub::Build(b)) => {
                igi::bench::build::run(&b.scenes, b.runs, b.bvh.builder.into(), b.quiet)
            }
            None => bench(&cmd.args),
        },
        Command::Compare { image, reference } => compare(image, reference),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", error_line(&e));
            ExitCode::FAILURE
        }
    }
}

/// The one line `igi` prints for an error: the error and its causes joined by ": ",
/// without the " (os error 2)" tails of OS errors (their message says it in words, as
/// the scene loader's do) and with any line breaks of a message made spaces.
fn error_line(e: &anyhow::Error) -> String {
    let causes: Vec<String> = e
        .chain()
        .map(|cause| igi_core::scene::without_os_error_code(&cause.to_string()).to_string())
        .collect();
    causes
        .join(": ")
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_command_line_passes_clap_checks() {
        // clap checks every subcommand's arguments when it builds them; a setting that
        // does not fit an argument (as on a flag) panics only once that subcommand is
        // used.
        negative_numbers_as_values(Cli::command()).debug_assert();
    }
}
