//! `igi bench`: the paper's measurements (section 5, Figs. 4 and 5) on any GPU: every
//! scene x set-up x VPL count rendered warm-up + N times, each stage timed with GPU
//! timestamp queries, with ray counts, memory, and the image error against a reference.

use super::model::*;
use crate::gpu_set_up::GpuSetUp;
use anyhow::{bail, Context, Result};
use igi_core::bvh::Bvh;
use igi_core::image::{rel_mse, Image};
use igi_core::metrics::flip;
use igi_core::scene::{builtin, load_scene, Scene};
use igi_core::settings::{Accelerations, RenderSettings};
use igi_gpu::profiler::WarmUp;
use igi_gpu::Renderer;
use indicatif::{ProgressBar, ProgressStyle};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// What to measure.
#[derive(Clone, Debug)]
pub struct BenchOptions {
    /// Scene files, or `builtin:NAME`.
    pub scenes: Vec<String>,
    pub vpls: Vec<u32>,
    pub setups: Vec<String>,
    pub frames: u32,
    pub warmup: u32,
    /// A reference for every scene (only with one scene); otherwise found beside it.
    pub reference: Option<PathBuf>,
    pub out: PathBuf,
    pub width: Option<u32>,
    pub height: Option<u32>,
    pub seed: u32,
    /// BVH builder of every scene.
    pub bvh: igi_core::bvh::BvhBuilder,
    pub adapter: Option<String>,
    pub quiet: bool,
    pub command: String,
}

/// The reference image of a scene file, where the shared scenes keep theirs:
/// `<dir>/../../references/<name>-full.exr`, with `<name>` the file's stem, or its
/// folder's name for a file called `scene.toml`; or `<dir>/<name>-reference.exr`.
pub fn find_reference(scene_path: &Path) -> Option<PathBuf> {
    let dir = scene_path.parent()?;
    let stem = scene_path.file_stem()?.to_string_lossy().to_string();
    let name = if stem == "scene" {
        dir.canonicalize()
            .ok()?
            .file_name()?
            .to_string_lossy()
            .to_string()
    } else {
        stem
    };
    [
        dir.join("../../references")
            .join(format!("{name}-full.exr")),
        dir.join(format!("{name}-reference.exr")),
    ]
    .into_iter()
    .find(|p| p.is_file())
}

/// Short name of a scene argument: the builtin's name, the file stem, or the folder's
/// name for `scene.toml`.
pub fn scene_name(arg: &str) -> String {
    if let Some(name) = arg.strip_prefix("builtin:") {
        return name.to_string();
    }
    let p = Path::new(arg);
    let stem = p
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_default();
    if stem == "scene" {
        if let Some(dir) = p
            .canonicalize()
            .ok()
            .and_then(|c| c.parent().map(Path::to_path_buf))
        {
            if let Some(n) = dir.file_name() {
                return n.to_string_lossy().to_string();
            }
        }
    }
    stem
}

/// Load a scene argument: `builtin:NAME` or a scene file.
pub fn load(arg: &str) -> Result<Scene> {
    match arg.strip_prefix("builtin:") {
        Some(name) => builtin::builtin_scene(name).with_context(|| {
            format!(
                "no built-in scene '{name}' (there is: {})",
                builtin::BUILTIN_NAMES.join(", ")
            )
        }),
        None => Ok(load_scene(Path::new(arg))?),
    }
}

fn stats(values: &mut [f64]) -> TimeStats {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    let median = if n == 0 {
        0.0
    } else if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    };
    TimeStats {
        median_ms: median,
        min_ms: values.first().copied().unwrap_or(0.0),
        max_ms: values.last().copied().unwrap_or(0.0),
    }
}

/// UTC now as RFC 3339 (civil-from-days, Howard Hinnant's algorithm).
pub fn utc_now() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs() as i64)
        .unwrap_or(0);
    let (days, rem) = (secs.div_euclid(86400), secs.rem_euclid(86400));
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        rem % 3600 / 60,
        rem % 60
    )
}

/// The EXR and PNG file names of one combination's image.
fn image_names(scene: &str, setup: &str, vpls: u32) -> (String, String) {
    let stem = format!(
        "{}-{}-{vpls}",
        super::report::file_stem(scene),
        setup.replace('+', "_")
    );
    (format!("{stem}.exr"), format!("{stem}.png"))
}

/// Errors where `opts.out` could not be made, or where a file the run writes into it
/// (images, report, charts) is taken by something that is not a regular file.
fn check_out(opts: &BenchOptions, setups: &[(String, Accelerations)]) -> Result<()> {
    let out = &opts.out;
    if !out.exists() {
        // create_dir_all fails later where the nearest existing ancestor is a file.
        if let Some(a) = out.ancestors().skip(1).find(|a| a.exists()) {
            if !a.is_dir() {
                bail!(
                    "--out '{}': cannot create it: '{}' is not a directory",
                    out.display(),
                    a.display()
                );
            }
        }
        return Ok(());
    }
    if !out.is_dir() {
        bail!("--out '{}' exists and is not a directory", out.display());
    }
    let mut names: Vec<String> = super::report::REPORT_FILES
        .iter()
        .map(|n| n.to_string())
        .collect();
    for name in scene_names(&opts.scenes) {
        names.extend(super::report::chart_files(&name));
        for (setup, _) in setups {
            for &vpls in &opts.vpls {
                let (exr, png) = image_names(&name, setup, vpls);
                names.extend([exr, png]);
            }
        }
    }
    for name in names {
        igi_core::image::output_target(&out.join(name))?;
    }
    Ok(())
}

/// A scene as `igi bench` measures it: its argument, the scene, and the reference image
/// with its path, where there is one.
type Input<'a> = (&'a String, Scene, Option<PathBuf>, Option<Image>);

/// Every scene and reference read before anything is rendered or created: a bad scene or
/// reference leaves no empty --out folder.
fn read_inputs(opts: &BenchOptions) -> Result<Vec<Input<'_>>> {
    let mut inputs = vec![];
    for arg in &opts.scenes {
        let scene = load(arg)?;
        let reference_path = match &opts.reference {
            Some(p) => Some(p.clone()),
            None if !arg.starts_with("builtin:") => find_reference(Path::new(arg)),
            None => None,
        };
        let reference = match &reference_path {
            Some(p) => Some(Image::read_exr(p)?),
            None => None,
        };
        inputs.push((arg, scene, reference_path, reference));
    }
    Ok(inputs)
}

/// The names of the scenes in a report and its files ([`scene_name`]), one per scene: a
/// name whose file stem ([`super::report::file_stem`]) an earlier scene has taken gets
/// "-2", "-3", ... (two scenes of one name, such as `builtin:cornell-box` and
/// `cornell-box/scene.toml`, wrote one set of images and charts, the second over the
/// first).
pub fn scene_names(args: &[String]) -> Vec<String> {
    let stem = super::report::file_stem;
    let mut names: Vec<String> = vec![];
    for arg in args {
        let base = scene_name(arg);
        let mut name = base.clone();
        let mut k = 1;
        // Against every name so far, the renamed ones included ("a-2" may be a name too).
        while names.iter().any(|n| stem(n) == stem(&name)) {
            k += 1;
            name = format!("{base}-{k}");
        }
        names.push(name);
    }
    names
}

/// Run the whole benchmark and write its images into `opts.out` (the report is written
/// by the caller with `report::write_all`).
pub fn run(opts: &BenchOptions) -> Result<BenchResults> {
    if opts.scenes.is_empty() {
        bail!("give at least one scene");
    }
    if opts.reference.is_some() && opts.scenes.len() > 1 {
        bail!("--reference applies to one scene; with several, references are found beside each scene");
    }
    if opts.frames == 0 {
        bail!("--frames must be at least 1");
    }
    if opts.vpls.is_empty() || opts.vpls.contains(&0) {
        bail!("--vpls needs one or more counts of at least 1");
    }
    let setups: Vec<(String, Accelerations)> = opts
        .setups
        .iter()
        .map(|s| {
            Accelerations::from_setup(s)
                .map(|a| (s.clone(), a))
                .map_err(|e| anyhow::anyhow!("--setups: {e}"))
        })
        .collect::<Result<_>>()?;
    // The outputs are checked before the scenes are read (which can take seconds): a
    // report name taken by a directory leaves no images without their report. The folder
    // itself is made right before the first image is written.
    check_out(opts, &setups)?;
    // The GPU is set up while the inputs are read (GpuSetUp), and its passes are made
    // once for every scene.
    let gpu = GpuSetUp::start(opts.adapter.clone())?;
    let inputs = match read_inputs(opts) {
        Ok(inputs) => inputs,
        Err(e) => {
            gpu.abandon();
            return Err(e);
        }
    };
    let (ctx, passes) = gpu.join()?;
    if !ctx.timestamps {
        bail!(
            "adapter '{}' has no timestamp queries: igi bench needs them",
            ctx.info.name
        );
    }
    let combos = (opts.scenes.len() * setups.len() * opts.vpls.len()) as u64;
    let bar = if opts.quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(combos)
    };
    bar.set_style(
        ProgressStyle::with_template("{bar:30} {pos}/{len} {elapsed_precise} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let mut runs = vec![];
    let mut free_passes = Some(passes);
    let scene_names = scene_names(&opts.scenes);
    for (arg, name) in opts.scenes.iter().zip(&scene_names) {
        if *name != scene_name(arg) {
            crate::note!("note: scene {arg} is named {name} in the report: its name is taken by an earlier scene");
        }
    }
    for ((arg, scene, reference_path, reference), name) in inputs.into_iter().zip(scene_names) {
        let t = Instant::now();
        let bvh = Bvh::build_with(&scene.triangles, opts.bvh);
        let bvh_build_ms = t.elapsed().as_secs_f64() * 1e3;
        let passes = free_passes
            .take()
            .expect("the last scene's renderer gave its passes back");
        let mut renderer = Renderer::with_passes(&ctx, passes, &scene, &bvh)?;
        for (setup, accelerations) in &setups {
            for &vpls in &opts.vpls {
                bar.set_message(format!("{name} {setup} {vpls} VPLs"));
                let settings = RenderSettings {
                    width: opts.width.unwrap_or(scene.film.width),
                    height: opts.height.unwrap_or(scene.film.height),
                    vpls,
                    seed: opts.seed,
                    accelerations: accelerations.clone(),
                    ..RenderSettings::for_scene(&scene)
                };
                settings.validate()?;
                // Warm-up (`WarmUp`): the frames asked for, and at least 0.5 s of frames, so
                // that the GPU's clocks are up again after the CPU work between
                // combinations (writing images, FLIP).
                let mut warm_up = WarmUp::new(opts.warmup);
                while warm_up.more() {
                    renderer.submit_frame(&ctx, &settings, 0)?;
                    ctx.finish()?;
                }
                let mut frame_ms = vec![];
                let mut stage_ms: BTreeMap<usize, (&'static str, Vec<f64>)> = BTreeMap::new();
                for _ in 0..opts.frames {
                    let (names, _) = renderer.submit_frame(&ctx, &settings, 0)?;
                    let (stages, span) = renderer
                        .read_timings(&ctx, &names)?
                        .context("timestamps vanished")?;
                    frame_ms.push(span);
                    for (i, s) in stages.into_iter().enumerate() {
                        stage_ms.entry(i).or_insert((s.name, vec![])).1.push(s.ms);
                    }
                }
                let frame = stats(&mut frame_ms);
                let stages: Vec<StageStats> = stage_ms
                    .into_values()
                    .map(|(name, mut v)| {
                        let time = stats(&mut v);
                        StageStats {
                            name: name.to_string(),
                            share: if frame.median_ms > 0.0 {
                                time.median_ms / frame.median_ms
                            } else {
                                0.0
                            },
                            time,
                        }
                    })
                    .collect();
                let output = renderer.render(&ctx, &settings)?;
                let counts = renderer.count_rays(&ctx, &settings)?;
                let rays = RayCounts {
                    primary: counts[0],
                    mirror: counts[1],
                    light_shadow: counts[2],
                    vpl_shadow: counts[3],
                    particle: counts[4],
                };
                let (exr, png) = image_names(&name, setup, vpls);
                std::fs::create_dir_all(&opts.out)
                    .with_context(|| format!("cannot create '{}'", opts.out.display()))?;
                output.image.write_exr(&opts.out.join(&exr))?;
                output.image.write_png(&opts.out.join(&png), 1.0)?;
                let error = match (&reference, &reference_path) {
                    (Some(r), Some(p))
                        if r.width == output.image.width && r.height == output.image.height =>
                    {
                        Some(ImageErrors {
                            reference: p.display().to_string(),
                            rel_mse: rel_mse(&output.image, r)?,
                            flip: flip(&output.image, r, 1.0)?.mean,
                        })
                    }
                    (Some(r), Some(p)) => {
                        bar.suspend(|| {
                            crate::note!(
                                "note: reference {} is {}x{}, the image {}x{}: no error measured",
                                p.display(),
                                r.width,
                                r.height,
                                output.image.width,
                                output.image.height
                            )
                        });
                        None
                    }
                    _ => None,
                };
                let median_s = frame.median_ms * 1e-3;
                runs.push(BenchRun {
                    scene: name.clone(),
                    scene_path: arg.clone(),
                    triangles: scene.triangles.len() as u64,
                    bvh_build_ms,
                    bvh: opts.bvh.name().to_string(),
                    width: settings.width,
                    height: settings.height,
                    setup: setup.clone(),
                    vpls_asked: vpls,
                    vpl_count: output.vpl_count,
                    light_paths: output.path_count,
                    fps: if median_s > 0.0 { 1.0 / median_s } else { 0.0 },
                    rays_per_s: if median_s > 0.0 {
                        rays.total() as f64 / median_s
                    } else {
                        0.0
                    },
                    rays,
                    frame,
                    stages,
                    scene_bytes: renderer.scene_bytes(),
                    frame_bytes: renderer.frame_bytes(),
                    error,
                    image_exr: exr,
                    image_png: png,
                });
                bar.inc(1);
            }
        }
        free_passes = Some(renderer.into_passes());
    }
    bar.finish_and_clear();
    Ok(BenchResults {
        meta: BenchMeta {
            adapter: ctx.info.name.clone(),
            backend: format!("{:?}", ctx.info.backend),
            driver: format!("{} {}", ctx.info.driver, ctx.info.driver_info)
                .trim()
                .to_string(),
            git_commit: env!("IGI_GIT_COMMIT").to_string(),
            date: utc_now(),
            command: opts.command.clone(),
            igi_version: env!("CARGO_PKG_VERSION").to_string(),
            frames: opts.frames,
            warmup: opts.warmup,
        },
        runs,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scenes_of_one_name_get_names_of_their_own() {
        let args = [
            "builtin:cornell-box",
            "a/cornell-box.toml",
            "b/room.toml",
            "room-2.toml",
            "c/room.toml",
            "cornell box.toml",
        ]
        .map(String::from);
        assert_eq!(
            scene_names(&args),
            [
                "cornell-box",
                "cornell-box-2",
                "room",
                "room-2",
                "room-3",
                // Its file stem, cornell_box, is not another's.
                "cornell box",
            ]
        );
        let args = ["a/x y.toml", "b/x_y.toml"].map(String::from);
        assert_eq!(scene_names(&args), ["x y", "x_y-2"]);
    }
}
