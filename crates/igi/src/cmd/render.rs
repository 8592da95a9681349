//! `igi render`: one image of a scene, to PNG and/or OpenEXR.

use crate::frame_options::{load, output_buffer, settings, BufferArg, FrameArgs, SceneArgs};
use anyhow::{bail, Result};
use clap::Args;
use igi_core::bvh::Bvh;
use igi_core::scene::Scene;
use igi_gpu::Renderer;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Args)]
pub struct RenderArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub frame: FrameArgs,
    /// Output PNG (sRGB, 8 bit).
    #[arg(short, long, value_name = "PNG")]
    pub output: Option<PathBuf>,
    /// Also write linear radiance as float32 RGB OpenEXR.
    #[arg(long, value_name = "EXR")]
    pub exr: Option<PathBuf>,
    /// Multiplier applied before tone mapping the PNG (the EXR stays unscaled).
    #[arg(long, default_value_t = 1.0)]
    pub exposure: f32,
    /// Which buffer to write.
    #[arg(long, value_enum, default_value = "final")]
    pub buffer: BufferArg,
    /// Print the GPU time of each stage (timestamp queries).
    #[arg(long)]
    pub timings: bool,
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

pub fn run(args: &RenderArgs) -> Result<()> {
    if args.output.is_none() && args.exr.is_none() {
        bail!("nothing to write: give -o OUT.png and/or --exr OUT.exr");
    }
    // The options' errors that need no scene, before it is loaded.
    settings(&args.frame, args.exposure, None)?;
    check_render_outputs(args, None)?;
    // Every output gets its temporary file now: a folder that takes no files is an error
    // before the scene is loaded, and the outputs are renamed into place together.
    let paths: Vec<&std::path::Path> = [&args.exr, &args.output]
        .into_iter()
        .flatten()
        .map(|p| p.as_path())
        .collect();
    let mut files = igi_core::image::OutputFiles::reserve(paths.iter().copied())?;
    let gpu = igi::gpu_set_up::GpuSetUp::start(args.frame.adapter.clone())?;
    let t = Instant::now();
    let loaded = load(&args.scene).and_then(|scene| {
        let load_ms = t.elapsed().as_secs_f64() * 1e3;
        let film = (scene.film.width, scene.film.height);
        let settings = settings(&args.frame, args.exposure, Some(film))?;
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
    settings.output = output_buffer(args.buffer);
    let t = Instant::now();
    let builder = args.frame.bvh.builder.into();
    let bvh = Bvh::build_with(&scene.triangles, builder);
    let bvh_ms = t.elapsed().as_secs_f64() * 1e3;
    igi::note!(
        "scene {}: {} triangles, {} lights (loaded in {load_ms:.0} ms, {})",
        scene.source,
        scene.triangles.len(),
        scene.lights.len(),
        igi::bvh_built(&bvh, builder, bvh_ms)
    );
    igi::note!("adapter: {}", ctx.describe());
    let mut renderer = Renderer::with_passes(&ctx, passes, &scene, &bvh)?;
    let frame = if settings.accumulate > 1 {
        // Frames done and the time left, on a terminal (indicatif draws nothing elsewhere).
        let bar = frames_bar(settings.accumulate);
        let frame = renderer.render_with_progress(&ctx, &settings, |k| bar.set_position(k as u64));
        bar.finish_and_clear();
        frame?
    } else {
        renderer.render(&ctx, &settings)?
    };
    igi::note!(
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
            igi::note!("timings: this adapter has no timestamp queries");
        } else {
            for s in &frame.stages {
                igi::note!("  {:<20} {:>9.3} ms", s.name, s.ms);
            }
            if let Some(ms) = frame.frame_ms {
                igi::note!("  {:<20} {:>9.3} ms", "frame", ms);
            }
        }
    }
    if let Some(path) = &args.exr {
        files.write(path, |file| frame.image.write_exr_to(file))?;
    }
    if let Some(path) = &args.output {
        files.write(path, |file| frame.image.write_png_to(file, args.exposure))?;
    }
    files.commit()?;
    for path in paths {
        igi::note!("wrote {}", path.display());
    }
    Ok(())
}

/// A bar of the `frames` of an accumulation: those done and the time left.
fn frames_bar(frames: u32) -> indicatif::ProgressBar {
    indicatif::ProgressBar::new(u64::from(frames)).with_style(
        indicatif::ProgressStyle::with_template("{bar:30} {pos}/{len} frames, {eta} left")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    )
}
