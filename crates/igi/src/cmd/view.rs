//! `igi view`: the command's side of the interactive viewer (its options and their
//! checks); the window itself is [`igi::view`].

use crate::frame_options::{load, output_buffer, settings, BufferArg, FrameArgs, SceneArgs};
use anyhow::{bail, Result};
use clap::Args;
use igi_core::scene::Camera;
use igi_core::settings::check_exposure;
use igi_gpu::AdapterChoice;
use std::path::PathBuf;

/// Largest `--scale`: the image at 1/S of the window's resolution.
const MAX_RENDER_SCALE: u32 = 64;

#[derive(Args)]
pub struct ViewArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Image size and the options of the frame; with --width/--height the image keeps that
    /// size (letterboxed in the window), otherwise it follows the window.
    #[command(flatten)]
    pub frame: FrameArgs,
    /// Multiplier applied before tone mapping (the panel changes it).
    #[arg(long, default_value_t = 1.0)]
    pub exposure: f32,
    /// Which buffer to show first.
    #[arg(long, value_enum, default_value = "final")]
    pub buffer: BufferArg,
    /// Start from this camera: a TOML file with a [camera] table, or the TOML itself
    /// (as the C key prints it), instead of the scene's.
    #[arg(long, value_name = "FILE|TOML")]
    pub camera: Option<String>,
    /// Render N frames, then exit (with --screenshot: save it first).
    #[arg(long, value_name = "N")]
    pub frames: Option<u32>,
    /// Where screenshots go: PNG at the panel's exposure, and the linear frame as EXR
    /// beside it (default: igi-screenshot-N.png in the working directory).
    #[arg(long, value_name = "PNG")]
    pub screenshot: Option<PathBuf>,
    /// Still frames averaged at most.
    #[arg(long, default_value_t = 256)]
    pub max_accumulate: u32,
    /// Render at 1/S of the window's resolution (faster on slow adapters).
    #[arg(long, value_name = "S", default_value_t = 1)]
    pub scale: u32,
    /// Draw the VPLs as dots.
    #[arg(long)]
    pub vpl_dots: bool,
    /// Initial window size in pixels, WxH.
    #[arg(long, value_name = "WxH", default_value = "1280x720", value_parser = parse_size)]
    pub window: (u32, u32),
}

pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
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

pub fn run(args: &ViewArgs) -> Result<()> {
    check_exposure(args.exposure)?;
    if args.frames == Some(0) {
        bail!("--frames must be at least 1");
    }
    if args.scale == 0 || args.scale > MAX_RENDER_SCALE {
        bail!(
            "--scale must be between 1 and {MAX_RENDER_SCALE}, got {}",
            args.scale
        );
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
    let camera = args.camera.as_deref().map(camera_option).transpose()?;
    // The options' errors that need no scene, before it is loaded.
    settings(&args.frame, args.exposure, None)?;
    let scene = load(&args.scene)?;
    // With the film's size: an image size of 0 is refused here.
    let film = (scene.film.width, scene.film.height);
    let mut settings = settings(&args.frame, args.exposure, Some(film))?;
    settings.output = output_buffer(args.buffer);
    let fixed_size = match (args.frame.width, args.frame.height) {
        (None, None) => None,
        _ => Some((settings.width, settings.height)),
    };
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

/// The camera of `--camera`: a TOML file with a [camera] table, or that TOML itself.
fn camera_option(text: &str) -> Result<Camera> {
    let path = std::path::Path::new(text);
    let (text, name) = if !text.contains('=') {
        // Text without '=' is taken for a file name, so a missing file may as well be
        // mistyped TOML: the message says what either form looks like.
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
        let text = String::from_utf8(bytes)
            .map_err(|_| anyhow::anyhow!("--camera '{}': not UTF-8 text", path.display()))?;
        (text, path.display().to_string())
    } else {
        (text.to_string(), "--camera".to_string())
    };
    Ok(igi_core::scene::parse_camera_toml(&text, &name)?)
}
