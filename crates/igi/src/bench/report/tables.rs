//! The report's tables: `results.csv`, one row per run, and `results.md`, the paper's
//! table per scene.

use super::{distinct, scenes, stage_names, SceneRuns};
use crate::bench::model::{BenchResults, BenchRun};
use anyhow::Result;
use std::fmt::Write as _;

const MIB: f64 = 1024.0 * 1024.0;

/// One row per run. Columns: scene, scene_path, setup, vpls_asked, vpl_count, light_paths,
/// width, height, triangles, bvh_build_ms, frame_median_ms, frame_min_ms, frame_max_ms, fps,
/// then `<stage>_ms` (median) and `<stage>_share` (0..1) for every stage of any run (empty
/// where a run lacks it), then rays_primary, rays_mirror, rays_light_shadow,
/// rays_vpl_shadow, rays_particle, rays_total, rays_per_s, scene_mib, frame_mib, rel_mse,
/// flip, reference (empty without a reference), image_exr, image_png.
pub fn to_csv(results: &BenchResults) -> Result<String> {
    let stages = stage_names(&results.runs);
    let mut header: Vec<String> = [
        "scene",
        "scene_path",
        "setup",
        "vpls_asked",
        "vpl_count",
        "light_paths",
        "width",
        "height",
        "triangles",
        "bvh_build_ms",
        "frame_median_ms",
        "frame_min_ms",
        "frame_max_ms",
        "fps",
    ]
    .map(String::from)
    .to_vec();
    for s in &stages {
        header.push(format!("{s}_ms"));
        header.push(format!("{s}_share"));
    }
    header.extend(
        [
            "rays_primary",
            "rays_mirror",
            "rays_light_shadow",
            "rays_vpl_shadow",
            "rays_particle",
            "rays_total",
            "rays_per_s",
            "scene_mib",
            "frame_mib",
            "rel_mse",
            "flip",
            "reference",
            "image_exr",
            "image_png",
        ]
        .map(String::from),
    );

    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(&header)?;
    for r in &results.runs {
        let mut row: Vec<String> = vec![
            r.scene.clone(),
            r.scene_path.clone(),
            r.setup.clone(),
            r.vpls_asked.to_string(),
            r.vpl_count.to_string(),
            r.light_paths.to_string(),
            r.width.to_string(),
            r.height.to_string(),
            r.triangles.to_string(),
            r.bvh_build_ms.to_string(),
            r.frame.median_ms.to_string(),
            r.frame.min_ms.to_string(),
            r.frame.max_ms.to_string(),
            r.fps.to_string(),
        ];
        for s in &stages {
            match r.stages.iter().find(|st| &st.name == s) {
                Some(st) => {
                    row.push(st.time.median_ms.to_string());
                    row.push(st.share.to_string());
                }
                None => row.extend([String::new(), String::new()]),
            }
        }
        row.extend([
            r.rays.primary.to_string(),
            r.rays.mirror.to_string(),
            r.rays.light_shadow.to_string(),
            r.rays.vpl_shadow.to_string(),
            r.rays.particle.to_string(),
            r.rays.total().to_string(),
            r.rays_per_s.to_string(),
            (r.scene_bytes as f64 / MIB).to_string(),
            (r.frame_bytes as f64 / MIB).to_string(),
        ]);
        match &r.error {
            Some(e) => row.extend([
                e.rel_mse.to_string(),
                e.flip.to_string(),
                e.reference.clone(),
            ]),
            None => row.extend([String::new(), String::new(), String::new()]),
        }
        row.extend([r.image_exr.clone(), r.image_png.clone()]);
        w.write_record(&row)?;
    }
    let bytes = w.into_inner().map_err(|e| anyhow::anyhow!("{e}"))?;
    Ok(String::from_utf8(bytes)?)
}

// ---------------------------------------------------------------------------------------
// Markdown

/// `v` with three significant digits (at least one decimal below 100), e.g. 123, 12.3,
/// 1.23, 0.0123.
pub(super) fn sig3(v: f64) -> String {
    if !v.is_finite() {
        return format!("{v}");
    }
    if v == 0.0 {
        return "0".into();
    }
    let decimals = (2 - v.abs().log10().floor() as i32).clamp(0, 12) as usize;
    format!("{v:.decimals$}")
}

/// A table cell: no pipes, no line breaks.
pub(super) fn cell(text: &str) -> String {
    text.replace('|', "\\|").replace(['\n', '\r'], " ")
}

/// Inline code, whatever backticks `text` holds.
pub(super) fn code(text: &str) -> String {
    let longest = text.split(|c| c != '`').map(str::len).max().unwrap_or(0);
    let fence = "`".repeat(longest + 1);
    let pad = if text.starts_with('`') || text.ends_with('`') {
        " "
    } else {
        ""
    };
    format!("{fence}{pad}{}{pad}{fence}", cell(text))
}

pub(super) fn fps_cell(r: &BenchRun) -> String {
    let mark = if r.vpl_count != r.vpls_asked {
        " †"
    } else {
        ""
    };
    format!("{} ({} ms){mark}", sig3(r.fps), sig3(r.frame.median_ms))
}

/// The report: a header (adapter, driver, date, commit, command), then per scene the
/// paper's table (rows = set-ups, columns = VPL counts, cells "fps (median frame ms)"),
/// the stages' shares of the median frame in %, and the image error (relMSE / FLIP).
pub fn to_markdown(results: &BenchResults) -> String {
    let m = &results.meta;
    let mut s = String::new();
    let _ = writeln!(s, "# igi bench results\n");
    let _ = writeln!(s, "| | |\n|---|---|");
    let _ = writeln!(
        s,
        "| Adapter | {} ({}) |",
        cell(&m.adapter),
        cell(&m.backend)
    );
    let _ = writeln!(s, "| Driver | {} |", cell(&m.driver));
    let _ = writeln!(s, "| Date | {} |", cell(&m.date));
    let _ = writeln!(
        s,
        "| Commit | {} (igi {}) |",
        cell(&m.git_commit),
        cell(&m.igi_version)
    );
    let _ = writeln!(s, "| Command | {} |", code(&m.command));
    let _ = writeln!(
        s,
        "| Frames | {} timed after {} warm-up, per combination; times are GPU medians |",
        m.frames, m.warmup
    );

    for scene in scenes(results) {
        let sc = SceneRuns::new(results, &scene);
        let _ = writeln!(s, "\n## Scene {}\n", code(&scene));
        let sizes = distinct(sc.runs.iter().map(|r| format!("{}x{}", r.width, r.height)));
        let first = sc.runs[0];
        let _ = writeln!(
            s,
            "{} triangles ({} BVH built in {} ms), rendered at {}.\n",
            first.triangles,
            first.bvh,
            sig3(first.bvh_build_ms),
            sizes.join(", ")
        );

        // The paper's table.
        let _ = writeln!(s, "### Frame rate: fps (median frame time)\n");
        let _ = write!(s, "| set-up |");
        for v in &sc.vpls {
            let _ = write!(s, " {v} VPLs |");
        }
        let _ = writeln!(s, "\n|---|{}", "---|".repeat(sc.vpls.len()));
        let mut short = false;
        for setup in &sc.setups {
            let _ = write!(s, "| {} |", cell(setup));
            for &v in &sc.vpls {
                match sc.get(setup, v) {
                    Some(r) => {
                        short |= r.vpl_count != r.vpls_asked;
                        let _ = write!(s, " {} |", fps_cell(r));
                    }
                    None => s.push_str(" – |"),
                }
            }
            s.push('\n');
        }
        if short {
            let _ = writeln!(
                s,
                "\n† The VPL count reached differs from the count asked (the number of light paths is fixed in advance from a pilot run; `vpl_count` in results.csv)."
            );
        }

        // Stage shares.
        let _ = writeln!(s, "\n### Stage shares (% of the median frame time)\n");
        let _ = write!(s, "| set-up | VPLs |");
        for st in &sc.stages {
            let _ = write!(s, " {} |", cell(st));
        }
        let _ = writeln!(s, "\n|---|---|{}", "---|".repeat(sc.stages.len()));
        for setup in &sc.setups {
            for &v in &sc.vpls {
                let Some(r) = sc.get(setup, v) else { continue };
                let _ = write!(s, "| {} | {v} |", cell(setup));
                for st in &sc.stages {
                    match r.stages.iter().find(|x| &x.name == st) {
                        Some(x) => {
                            let _ = write!(s, " {:.1} |", x.share * 100.0);
                        }
                        None => s.push_str(" – |"),
                    }
                }
                s.push('\n');
            }
        }

        // Image error.
        let _ = writeln!(s, "\n### Image error: relMSE / FLIP\n");
        if !sc.has_errors() {
            let _ = writeln!(s, "No reference image: no error measured.");
            continue;
        }
        let _ = write!(s, "| set-up |");
        for v in &sc.vpls {
            let _ = write!(s, " {v} VPLs |");
        }
        let _ = writeln!(s, "\n|---|{}", "---|".repeat(sc.vpls.len()));
        for setup in &sc.setups {
            let _ = write!(s, "| {} |", cell(setup));
            for &v in &sc.vpls {
                match sc.get(setup, v).and_then(|r| r.error.as_ref()) {
                    Some(e) => {
                        let _ = write!(s, " {:.3e} / {:.4} |", e.rel_mse, e.flip);
                    }
                    None => s.push_str(" – |"),
                }
            }
            s.push('\n');
        }
        let refs = distinct(
            sc.runs
                .iter()
                .filter_map(|r| r.error.as_ref().map(|e| e.reference.clone())),
        );
        let refs: Vec<String> = refs.iter().map(|r| code(r)).collect();
        let _ = writeln!(s, "\nReference: {}.", refs.join(", "));
    }
    s
}
