//! `igi bench` reports without a font: the SVG charts are still written (their text is
//! laid out by the viewer), the PNGs are skipped with a warning, never an error.
//!
//! Alone in its own test binary because the font is looked up once per process.

use igi::bench::model::*;
use igi::bench::report::write_all;

fn results() -> BenchResults {
    let mut runs = Vec::new();
    for (setup, k) in [("canonical", 1.0), ("iv+ds", 0.5)] {
        for vpls in [30u32, 180] {
            let frame = k * vpls as f64 / 3.0;
            runs.push(BenchRun {
                scene: "interior".into(),
                scene_path: "scenes/interior.toml".into(),
                triangles: 1000,
                bvh_build_ms: 1.5,
                bvh: "binned".to_string(),
                width: 800,
                height: 600,
                setup: setup.into(),
                vpls_asked: vpls,
                vpl_count: vpls,
                light_paths: vpls / 3,
                frame: TimeStats {
                    median_ms: frame,
                    min_ms: frame,
                    max_ms: frame,
                },
                stages: vec![
                    StageStats {
                        name: "direct".into(),
                        time: TimeStats {
                            median_ms: frame * 0.25,
                            min_ms: frame * 0.25,
                            max_ms: frame * 0.25,
                        },
                        share: 0.25,
                    },
                    StageStats {
                        name: "indirect".into(),
                        time: TimeStats {
                            median_ms: frame * 0.75,
                            min_ms: frame * 0.75,
                            max_ms: frame * 0.75,
                        },
                        share: 0.75,
                    },
                ],
                fps: 1000.0 / frame,
                rays: RayCounts::default(),
                rays_per_s: 0.0,
                scene_bytes: 0,
                frame_bytes: 0,
                error: Some(ImageErrors {
                    reference: "refs/interior.exr".into(),
                    rel_mse: 0.1 / vpls as f64,
                    flip: 0.5 / (vpls as f64).sqrt(),
                }),
                image_exr: String::new(),
                image_png: String::new(),
            });
        }
    }
    BenchResults {
        meta: BenchMeta {
            adapter: "test".into(),
            backend: "none".into(),
            driver: "none".into(),
            git_commit: "unknown".into(),
            date: "2025-01-01T00:00:00Z".into(),
            command: "igi bench".into(),
            igi_version: "0.1.0".into(),
            frames: 1,
            warmup: 0,
        },
        runs,
    }
}

#[test]
fn no_font_gives_svg_and_a_warning() {
    // Edition 2021: set_var is safe; this binary has no other test touching the environment.
    std::env::set_var("IGI_FONT", "none");
    let dir = std::env::temp_dir().join(format!("igi-report-nofont-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);

    let warnings = write_all(&results(), &dir).unwrap();
    assert!(
        warnings.iter().any(|w| w.contains("PNG charts skipped")),
        "{warnings:?}"
    );
    for chart in ["stages-interior", "error-interior"] {
        let svg = std::fs::read_to_string(dir.join(format!("{chart}.svg"))).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("</svg>"), "{chart}");
        assert!(
            svg.contains("canonical") && svg.contains("iv+ds"),
            "{chart}"
        );
        assert!(!dir.join(format!("{chart}.png")).exists(), "{chart}");
    }
    let md = std::fs::read_to_string(dir.join("results.md")).unwrap();
    assert!(
        md.contains("| canonical | 100 (10.0 ms) | 16.7 (60.0 ms) |"),
        "{md}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
