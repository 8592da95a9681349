//! Reports of `igi bench`: `results.json` (the [`BenchResults`] itself), `results.csv`
//! (one row per run), `results.md` (the paper's table per scene: fps and frame time per
//! set-up and VPL count, the stages' shares, the image error) and charts per scene
//! (stacked stage times as in the paper's figures, error against frame time), as SVG and,
//! when a TrueType font is found, PNG.
//!
//! Every file is written to a temporary name and renamed into place, so an interrupted
//! run leaves no half-written file.

mod charts;
mod tables;

pub use charts::write_charts;
pub use tables::{to_csv, to_markdown};

use super::model::{BenchResults, BenchRun};
use anyhow::{Context, Result};
use igi_core::image::write_atomically;
use std::path::Path;

/// Write `results.json`, `results.csv`, `results.md` and the charts into `dir` (created
/// if missing). Returns warnings (e.g. PNG charts skipped for want of a font).
pub fn write_all(results: &BenchResults, dir: &Path) -> Result<Vec<String>> {
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create directory '{}'", dir.display()))?;
    let [json, csv, md] = REPORT_FILES;
    write_json(results, &dir.join(json))?;
    write_csv(results, &dir.join(csv))?;
    write_markdown(results, &dir.join(md))?;
    write_charts(results, dir)
}

/// The report's files in the output folder, besides the charts ([`chart_files`]).
pub const REPORT_FILES: [&str; 3] = ["results.json", "results.csv", "results.md"];

/// The chart files of a scene: stages SVG and PNG, error SVG and PNG.
pub fn chart_files(scene: &str) -> [String; 4] {
    let stem = file_stem(scene);
    [
        format!("stages-{stem}.svg"),
        format!("stages-{stem}.png"),
        format!("error-{stem}.svg"),
        format!("error-{stem}.png"),
    ]
}

/// `results.json`: the results as pretty-printed JSON.
pub fn write_json(results: &BenchResults, path: &Path) -> Result<()> {
    let mut text = serde_json::to_string_pretty(results)?;
    text.push('\n');
    write_file(path, text.as_bytes())
}

/// `results.csv`: one row per run, see [`to_csv`].
pub fn write_csv(results: &BenchResults, path: &Path) -> Result<()> {
    write_file(path, to_csv(results)?.as_bytes())
}

/// `results.md`: see [`to_markdown`].
pub fn write_markdown(results: &BenchResults, path: &Path) -> Result<()> {
    write_file(path, to_markdown(results).as_bytes())
}

fn write_file(path: &Path, bytes: &[u8]) -> Result<()> {
    write_atomically(path, |file| {
        std::io::Write::write_all(file, bytes).map_err(|e| e.to_string())
    })?;
    Ok(())
}

// ---------------------------------------------------------------------------------------
// Grouping

/// Distinct values in order of first appearance.
fn distinct<T: PartialEq + Clone>(items: impl IntoIterator<Item = T>) -> Vec<T> {
    let mut out = Vec::new();
    for item in items {
        if !out.contains(&item) {
            out.push(item);
        }
    }
    out
}

/// Scenes in order of first appearance.
fn scenes(results: &BenchResults) -> Vec<String> {
    distinct(results.runs.iter().map(|r| r.scene.clone()))
}

/// Stage names over all runs, in frame order: a stage that only some runs have (e.g. the
/// interleaving filter) goes right after the stage that precedes it in those runs.
fn stage_names<'a>(runs: impl IntoIterator<Item = &'a BenchRun>) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for run in runs {
        let mut next = 0;
        for stage in &run.stages {
            match out.iter().position(|n| n == &stage.name) {
                Some(i) => next = i + 1,
                None => {
                    out.insert(next, stage.name.clone());
                    next += 1;
                }
            }
        }
    }
    out
}

/// The runs of one scene, with its set-ups (order of appearance) and VPL counts asked
/// (ascending).
struct SceneRuns<'a> {
    name: String,
    runs: Vec<&'a BenchRun>,
    setups: Vec<String>,
    vpls: Vec<u32>,
    stages: Vec<String>,
}

impl<'a> SceneRuns<'a> {
    fn new(results: &'a BenchResults, scene: &str) -> Self {
        let runs: Vec<&BenchRun> = results.runs.iter().filter(|r| r.scene == scene).collect();
        let setups = distinct(runs.iter().map(|r| r.setup.clone()));
        let mut vpls = distinct(runs.iter().map(|r| r.vpls_asked));
        vpls.sort_unstable();
        let stages = stage_names(runs.iter().copied());
        SceneRuns {
            name: scene.to_string(),
            runs,
            setups,
            vpls,
            stages,
        }
    }

    /// The (first) run of a set-up and VPL count.
    fn get(&self, setup: &str, vpls: u32) -> Option<&'a BenchRun> {
        self.runs
            .iter()
            .copied()
            .find(|r| r.setup == setup && r.vpls_asked == vpls)
    }

    fn has_errors(&self) -> bool {
        self.runs.iter().any(|r| r.error.is_some())
    }
}

/// A scene name as part of a file name: ASCII letters, digits, '-', '_' and '.' kept,
/// anything else '_'.
pub fn file_stem(scene: &str) -> String {
    let s: String = scene
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.') {
                c
            } else {
                '_'
            }
        })
        .collect();
    if s.is_empty() || s.starts_with('.') {
        format!("_{s}")
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::super::model::*;
    use super::charts::{ensure_font, stages_chart_size, stages_legend_width, LEGEND_WIDTH};
    use super::tables::{cell, code, fps_cell, sig3};
    use super::*;

    fn run(scene: &str, setup: &str, vpls: u32, with_error: bool, k: f64) -> BenchRun {
        let stages = [
            ("vpl", 0.1),
            ("direct", 0.3),
            ("indirect", 0.5),
            ("compose", 0.1),
        ];
        let frame = 10.0 * k * (vpls as f64 / 30.0);
        let mut stage_list: Vec<StageStats> = stages
            .iter()
            .map(|&(n, share)| StageStats {
                name: n.to_string(),
                time: TimeStats {
                    median_ms: frame * share,
                    min_ms: frame * share * 0.9,
                    max_ms: frame * share * 1.2,
                },
                share,
            })
            .collect();
        if setup.contains("il") {
            stage_list.insert(
                3,
                StageStats {
                    name: "interleave filter".into(),
                    time: TimeStats {
                        median_ms: 0.25,
                        min_ms: 0.2,
                        max_ms: 0.3,
                    },
                    share: 0.25 / frame,
                },
            );
        }
        BenchRun {
            scene: scene.into(),
            scene_path: format!("scenes/{scene}.toml"),
            triangles: 262_267,
            bvh_build_ms: 123.456,
            bvh: "binned".to_string(),
            width: 800,
            height: 600,
            setup: setup.into(),
            vpls_asked: vpls,
            vpl_count: if vpls == 90 && setup == "iv+ds+il" {
                88
            } else {
                vpls
            },
            light_paths: vpls / 3,
            frame: TimeStats {
                median_ms: frame,
                min_ms: frame * 0.95,
                max_ms: frame * 1.3,
            },
            stages: stage_list,
            fps: 1000.0 / frame,
            rays: RayCounts {
                primary: 480_000,
                mirror: 12_345,
                light_shadow: 480_000,
                vpl_shadow: 480_000 * vpls as u64,
                particle: vpls as u64 * 2,
            },
            rays_per_s: 1.0e9 / frame,
            scene_bytes: 50 * 1024 * 1024,
            frame_bytes: 30 * 1024 * 1024 + 17,
            error: with_error.then(|| ImageErrors {
                reference: format!("refs/{scene}.exr"),
                rel_mse: 0.05 / vpls as f64 * k,
                flip: 0.3 / (vpls as f64).sqrt() * k,
            }),
            image_exr: format!("{scene}-{setup}-{vpls}.exr"),
            image_png: format!("{scene}-{setup}-{vpls}.png"),
        }
    }

    fn sample() -> BenchResults {
        let mut runs = Vec::new();
        for (scene, with_error) in [("cornell-box", true), ("sponza atrium", false)] {
            for (setup, k) in [("canonical", 1.0), ("iv+ds+il", 0.4)] {
                for vpls in [30, 90] {
                    runs.push(run(scene, setup, vpls, with_error, k));
                }
            }
        }
        // One run of the second scene with an error after all: "with and without".
        runs[4].error = Some(ImageErrors {
            reference: "refs/sponza.exr".into(),
            rel_mse: 0.0,
            flip: 0.0,
        });
        BenchResults {
            meta: BenchMeta {
                adapter: "NVIDIA H200".into(),
                backend: "Vulkan".into(),
                driver: "NVIDIA 570.124.06".into(),
                git_commit: "0e610d8".into(),
                date: "2025-06-01T12:00:00Z".into(),
                command: "igi bench --scenes cornell-box,sponza --vpls 30,90 | tee `log`".into(),
                igi_version: "0.1.0".into(),
                frames: 100,
                warmup: 10,
            },
            runs,
        }
    }

    fn temp_dir(name: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("igi-report-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        dir
    }

    #[test]
    fn write_all_round_trip_and_contents() {
        let results = sample();
        let dir = temp_dir("all");
        let warnings = write_all(&results, &dir).unwrap();

        // JSON round trip, every field present.
        let text = std::fs::read_to_string(dir.join("results.json")).unwrap();
        let back: BenchResults = serde_json::from_str(&text).unwrap();
        assert_eq!(back, results);
        let value: serde_json::Value = serde_json::from_str(&text).unwrap();
        for key in [
            "adapter",
            "backend",
            "driver",
            "git_commit",
            "date",
            "command",
            "igi_version",
            "frames",
            "warmup",
        ] {
            assert!(value["meta"].get(key).is_some(), "meta.{key}");
        }
        let run0 = &value["runs"][0];
        for key in [
            "scene",
            "scene_path",
            "triangles",
            "bvh_build_ms",
            "width",
            "height",
            "setup",
            "vpls_asked",
            "vpl_count",
            "light_paths",
            "frame",
            "stages",
            "fps",
            "rays",
            "rays_per_s",
            "scene_bytes",
            "frame_bytes",
            "error",
            "image_exr",
            "image_png",
        ] {
            assert!(run0.get(key).is_some(), "runs[0].{key}");
        }
        assert!(value["runs"][7]["error"].is_null());

        // CSV: the header and a row per run.
        let mut rd = csv::Reader::from_path(dir.join("results.csv")).unwrap();
        let header: Vec<String> = rd.headers().unwrap().iter().map(String::from).collect();
        for col in [
            "scene",
            "setup",
            "vpls_asked",
            "vpl_count",
            "width",
            "height",
            "frame_median_ms",
            "frame_min_ms",
            "frame_max_ms",
            "fps",
            "vpl_ms",
            "vpl_share",
            "direct_ms",
            "indirect_share",
            "interleave filter_ms",
            "interleave filter_share",
            "compose_ms",
            "rays_primary",
            "rays_vpl_shadow",
            "rays_total",
            "rays_per_s",
            "scene_mib",
            "frame_mib",
            "rel_mse",
            "flip",
        ] {
            assert!(
                header.contains(&col.to_string()),
                "column {col}: {header:?}"
            );
        }
        // Stages in frame order: the interleaving filter comes before compose.
        let pos = |c: &str| header.iter().position(|h| h == c).unwrap();
        assert!(pos("indirect_ms") < pos("interleave filter_ms"));
        assert!(pos("interleave filter_ms") < pos("compose_ms"));
        let rows: Vec<csv::StringRecord> = rd.records().map(|r| r.unwrap()).collect();
        assert_eq!(rows.len(), results.runs.len());
        for (row, r) in rows.iter().zip(&results.runs) {
            assert_eq!(row.len(), header.len());
            assert_eq!(&row[pos("scene")], r.scene);
            assert_eq!(row[pos("fps")].parse::<f64>().unwrap(), r.fps);
            assert_eq!(
                row[pos("rays_total")].parse::<u64>().unwrap(),
                r.rays.total()
            );
            let il = &row[pos("interleave filter_ms")];
            assert_eq!(il.is_empty(), !r.setup.contains("il"), "{il:?}");
            assert_eq!(row[pos("rel_mse")].is_empty(), r.error.is_none());
        }
        assert_eq!(rows[0][pos("scene_mib")].parse::<f64>().unwrap(), 50.0);

        // Markdown: header, each scene's table with its fps values, shares, errors.
        let md = std::fs::read_to_string(dir.join("results.md")).unwrap();
        assert!(md.contains("NVIDIA H200 (Vulkan)"));
        assert!(md.contains("NVIDIA 570.124.06"));
        assert!(md.contains("0e610d8"));
        assert!(md.contains("2025-06-01T12:00:00Z"));
        assert!(
            md.contains("`` igi bench --scenes cornell-box,sponza --vpls 30,90 \\| tee `log` ``")
        );
        for scene in ["cornell-box", "sponza atrium"] {
            let start = md.find(&format!("## Scene `{scene}`")).expect(scene);
            let section = &md[start..];
            let section = &section[..section[3..].find("\n## ").map_or(section.len(), |e| e + 3)];
            assert!(
                section.contains("| set-up | 30 VPLs | 90 VPLs |"),
                "{section}"
            );
            for r in results.runs.iter().filter(|r| r.scene == scene) {
                let c = fps_cell(r);
                assert!(section.contains(&c), "{c} in {section}");
                let row = format!("| {} |", r.setup);
                assert!(section.contains(&row));
            }
            assert!(section.contains("| interleave filter |"));
            assert!(section.contains("| canonical | 30 | 10.0 | 30.0 | 50.0 | – | 10.0 |"));
            assert!(section.contains("relMSE / FLIP"));
        }
        assert!(md.contains("12.3 fps") || md.contains("(10.0 ms)"));
        assert!(md.contains(&format!("{:.3e} / {:.4}", 0.05 / 30.0, 0.3 / 30f64.sqrt())));
        assert!(md.contains("†"), "fewer VPLs reached is marked");

        // Charts: SVGs always, PNGs when a font exists.
        let font = ensure_font().is_ok();
        for scene in ["cornell-box", "sponza_atrium"] {
            let svg = dir.join(format!("stages-{scene}.svg"));
            let text = std::fs::read_to_string(&svg).unwrap();
            assert!(
                text.contains("<svg") && text.contains("indirect"),
                "{svg:?}"
            );
            let png = dir.join(format!("stages-{scene}.png"));
            assert_eq!(png.exists(), font);
            if font {
                let bytes = std::fs::read(&png).unwrap();
                assert!(bytes.len() > 1000 && bytes.starts_with(b"\x89PNG"));
            }
            // Both scenes have at least one error.
            let svg = dir.join(format!("error-{scene}.svg"));
            assert!(std::fs::metadata(&svg).unwrap().len() > 0, "{svg:?}");
            assert_eq!(dir.join(format!("error-{scene}.png")).exists(), font);
        }
        assert_eq!(warnings.is_empty(), font, "{warnings:?}");

        // Nothing half-written.
        for e in std::fs::read_dir(&dir).unwrap() {
            let name = e.unwrap().file_name().to_string_lossy().to_string();
            assert!(!name.ends_with(".partial"), "{name}");
        }
        if std::env::var_os("IGI_KEEP_REPORT").is_none() {
            std::fs::remove_dir_all(&dir).unwrap();
        } else {
            crate::note!("report kept in {}", dir.display());
        }
    }

    #[test]
    fn no_errors_no_error_chart() {
        let mut results = sample();
        for r in &mut results.runs {
            r.error = None;
        }
        let dir = temp_dir("noerr");
        let warnings = write_all(&results, &dir).unwrap();
        assert!(!dir.join("error-cornell-box.svg").exists());
        assert!(dir.join("stages-cornell-box.svg").exists());
        assert!(warnings.iter().any(|w| w.contains("no error chart")));
        let md = std::fs::read_to_string(dir.join("results.md")).unwrap();
        assert!(md.contains("No reference image"));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn empty_results() {
        let mut results = sample();
        results.runs.clear();
        let dir = temp_dir("empty");
        assert!(write_all(&results, &dir).unwrap().len() <= 1);
        let csv = std::fs::read_to_string(dir.join("results.csv")).unwrap();
        assert_eq!(csv.lines().count(), 1);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn helpers() {
        assert_eq!(sig3(123.456), "123");
        assert_eq!(sig3(12.3456), "12.3");
        assert_eq!(sig3(1.23456), "1.23");
        assert_eq!(sig3(0.0123456), "0.0123");
        assert_eq!(sig3(0.0), "0");
        assert_eq!(sig3(1234.4), "1234");
        assert_eq!(file_stem("sponza atrium/v2"), "sponza_atrium_v2");
        assert_eq!(file_stem(".."), "_..");
        assert_eq!(code("a`b"), "``a`b``");
        assert_eq!(cell("a|b"), "a\\|b");
    }

    #[test]
    fn long_stage_names_widen_the_legend() {
        let mut results = sample();
        let short = SceneRuns::new(&results, "cornell-box");
        let (short_width, _) = stages_chart_size(&short);
        assert_eq!(stages_legend_width(&short), LEGEND_WIDTH);
        let long = "mirror chains + mirror indirect + indirect";
        for run in &mut results.runs {
            run.stages[0].name = long.into();
        }
        let wide = SceneRuns::new(&results, "cornell-box");
        let width = stages_legend_width(&wide);
        assert!(width >= 36 + 8 * long.len() as u32, "{width}");
        let (wide_width, _) = stages_chart_size(&wide);
        assert!(
            wide_width > short_width && wide_width >= width + 120,
            "{wide_width}"
        );
    }
}
