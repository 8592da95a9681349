//! The options that `igi render` and `igi view` share (where the scene comes from, the
//! frame's parameters, the paper's accelerations) and `--bvh`, which every command that
//! builds a BVH takes; and the [`RenderSettings`] they make.

use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use igi_core::bvh::BvhBuilder;
use igi_core::scene::{builtin, load_scene, Scene};
use igi_core::settings::{
    check_interleave, Accelerations, FilterMode, GeometryBound, InterleavePattern, OutputBuffer,
    RenderSettings, SettingsError, MAX_SUBSETS,
};
use std::path::PathBuf;

/// The `--bvh` option of every command that builds a BVH.
#[derive(Args)]
pub struct BvhChoice {
    /// BVH builder: split (early split clipping of long thin triangles: a faster walk)
    /// or binned (whole triangles: a faster build).
    #[arg(long = "bvh", value_enum, default_value = "split")]
    pub builder: BvhArg,
}

#[derive(Clone, Copy, ValueEnum)]
pub enum BvhArg {
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
pub enum BoundArg {
    /// G times smoothstep(0.8 m, 1.2 m, d), as in the paper.
    Smoothstep,
    /// cos cos / max(d^2, m^2), the classic clamp.
    Clamp,
}

#[derive(Clone, Copy, ValueEnum)]
pub enum BufferArg {
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
pub struct SceneArgs {
    /// The scene file (TOML, see docs/SCENE_FORMAT.md).
    #[arg(required_unless_present = "builtin", conflicts_with = "builtin")]
    pub scene: Option<PathBuf>,
    /// A scene defined in igi itself instead of a file: cornell-box.
    #[arg(long, value_name = "NAME")]
    pub builtin: Option<String>,
}

#[derive(Args)]
pub struct FrameArgs {
    /// Image width (default: the scene's film).
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height (default: the scene's film).
    #[arg(long)]
    pub height: Option<u32>,
    /// Number of VPLs (the paper uses 30, 90, 180); the actual count is reported.
    #[arg(long, default_value_t = 180)]
    pub vpls: u32,
    /// Maximum diffuse bounces of a light path (VPLs per path).
    #[arg(long, default_value_t = 8)]
    pub bounces: u32,
    /// Bounding distance m of the geometry term (default: 5% of the scene's diagonal).
    #[arg(long, value_name = "M")]
    pub min_dist: Option<f32>,
    /// How G is bounded near VPLs.
    #[arg(long, value_enum, default_value = "smoothstep")]
    pub bound: BoundArg,
    /// Depth limit of mirror reflections (at most 1024).
    #[arg(long, default_value_t = 6)]
    pub mirror_depth: u32,
    /// Seed of the VPL set (a window of the Halton sequence).
    #[arg(long, default_value_t = 0)]
    pub seed: u32,
    #[command(flatten)]
    pub bvh: BvhChoice,
    /// Adapter to use: an index or part of a name from `igi info` (default: the best).
    #[arg(long)]
    pub adapter: Option<String>,
    #[command(flatten)]
    pub accel: AccelArgs,
}

/// The paper's accelerations (sections 4.1-4.3) and their filters.
#[derive(Args, Clone)]
pub struct AccelArgs {
    /// A set-up by name, as in the paper's table: canonical, or iv, ds, il (and irregular,
    /// which needs il, and fused, which needs ds or il) joined by '+', e.g. iv+ds+il. The
    /// options below adjust it.
    #[arg(long, value_name = "NAME")]
    pub setup: Option<String>,
    /// VPL shadow rays test triangle bounding boxes instead of triangles.
    #[arg(long)]
    pub imperfect_visibility: bool,
    /// Indirect light at 1/S of the resolution per axis, then joint bilateral upsampling.
    #[arg(long, value_name = "S")]
    pub downsample: Option<u32>,
    /// Interleaved sampling over NxM VPL subsets (N x M at most 64), then the discontinuity
    /// buffer (e.g. 3x3).
    #[arg(long, value_name = "NxM", value_parser = parse_interleave)]
    pub interleave: Option<(u32, u32)>,
    /// How subsets are laid out in a tile (irregular needs interleaving).
    #[arg(long, value_enum)]
    pub pattern: Option<PatternArg>,
    /// Discontinuity buffer and upsampling as two passes, or fused in one (fused needs
    /// downsampling or interleaving).
    #[arg(long, value_enum)]
    pub filter: Option<FilterArg>,
    /// Spatial sigma of the upsampler, in low-resolution pixels.
    #[arg(long, value_name = "PIXELS")]
    pub upsample_sigma: Option<f32>,
    /// Exponent k of the upsampler's normal weight (N_p . N_q)^k (the paper: 1).
    #[arg(long, value_name = "K")]
    pub normal_power: Option<f32>,
    /// Leave depth out of the upsampler's range weight (the paper's normal-only weight).
    #[arg(long)]
    pub no_upsample_depth: bool,
    /// Relative depth difference that counts as a discontinuity.
    #[arg(long, value_name = "FRACTION")]
    pub depth_threshold: Option<f32>,
    /// Smallest normal dot product of continuous neighbours.
    #[arg(long, value_name = "COS")]
    pub normal_threshold: Option<f32>,
    /// Average K frames, each with a fresh VPL set (a still camera converges).
    #[arg(long, value_name = "K", default_value_t = 1)]
    pub accumulate: u32,
}

#[derive(Clone, Copy, ValueEnum)]
pub enum PatternArg {
    Regular,
    Irregular,
}

#[derive(Clone, Copy, ValueEnum)]
pub enum FilterArg {
    TwoPass,
    Fused,
}

/// `--interleave NxM`: the syntax, then the limits of [`check_interleave`] (as clap's
/// error for the option).
pub fn parse_interleave(s: &str) -> Result<(u32, u32), String> {
    let (n, m) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("'{s}' is not NxM (e.g. 3x3)"))?;
    let parse = |v: &str| {
        let v = v.trim();
        v.parse::<u32>().map_err(|e| match e.kind() {
            std::num::IntErrorKind::PosOverflow => {
                format!("{v} is too large: N x M must be at most {MAX_SUBSETS} subsets")
            }
            _ => format!("'{s}' is not NxM (e.g. 3x3)"),
        })
    };
    let (n, m) = (parse(n)?, parse(m)?);
    check_interleave(n, m).map_err(|e| e.to_string())?;
    Ok((n, m))
}

impl AccelArgs {
    /// The set-up of `--setup` (canonical without it) with the options' changes; their
    /// values are checked with the rest of the settings, by [`settings`].
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
        if let Some(v) = self.upsample_sigma {
            a.upsample_sigma = v;
        }
        if let Some(v) = self.normal_power {
            a.upsample_normal_power = v;
        }
        if self.no_upsample_depth {
            a.upsample_depth = false;
        }
        if let Some(v) = self.depth_threshold {
            a.depth_threshold = v;
        }
        if let Some(v) = self.normal_threshold {
            a.normal_threshold = v;
        }
        Ok(a)
    }

    /// `e` with the set-up named where an idle modifier came from it: a set-up name was
    /// checked whole by `from_setup`, so an idle modifier came from --pattern or
    /// --filter, or the options switched its acceleration off.
    fn named(&self, e: SettingsError) -> SettingsError {
        let from_setup = |given: bool| self.setup.clone().filter(|_| !given);
        match e {
            SettingsError::IrregularWithoutInterleave { .. } => {
                SettingsError::IrregularWithoutInterleave {
                    from_setup: from_setup(self.pattern.is_some()),
                }
            }
            SettingsError::FusedWithoutFilter { .. } => SettingsError::FusedWithoutFilter {
                from_setup: from_setup(self.filter.is_some()),
            },
            e => e,
        }
    }
}

/// What `--buffer` names, as the renderer names it.
pub fn output_buffer(b: BufferArg) -> OutputBuffer {
    match b {
        BufferArg::Final => OutputBuffer::Final,
        BufferArg::Direct => OutputBuffer::Direct,
        BufferArg::Indirect => OutputBuffer::Indirect,
        BufferArg::Irradiance => OutputBuffer::Irradiance,
        BufferArg::Normals => OutputBuffer::Normals,
        BufferArg::Depth => OutputBuffer::Depth,
    }
}

/// The scene of a file or of `--builtin`.
pub fn load(args: &SceneArgs) -> Result<Scene> {
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

/// The frame's settings, checked by [`RenderSettings::validate`], for a scene whose film
/// is `film` (the default image size). Without a film (before the scene is loaded, which
/// can take seconds) every option but the image size is checked: the errors that need no
/// scene come first, and the same checks run again once it is loaded.
pub fn settings(f: &FrameArgs, exposure: f32, film: Option<(u32, u32)>) -> Result<RenderSettings> {
    let (width, height) = film.unwrap_or((1, 1));
    let mut settings = RenderSettings {
        width: f.width.unwrap_or(width),
        height: f.height.unwrap_or(height),
        vpls: f.vpls,
        bounces: f.bounces,
        min_dist: f.min_dist,
        geometry_bound: match f.bound {
            BoundArg::Smoothstep => GeometryBound::Smoothstep,
            BoundArg::Clamp => GeometryBound::Clamp,
        },
        mirror_depth: f.mirror_depth,
        seed: f.seed,
        exposure,
        accumulate: f.accel.accumulate,
        ..RenderSettings::default()
    };
    // The frame's own options before the set-up name is read (the default accelerations
    // pass), then the accelerations: the errors come in the order of the options.
    settings.validate_parameters()?;
    settings.accelerations = f.accel.accelerations()?;
    let checked = match film {
        Some(_) => settings.validate(),
        None => settings.validate_parameters(),
    };
    checked.map_err(|e| f.accel.named(e))?;
    Ok(settings)
}
