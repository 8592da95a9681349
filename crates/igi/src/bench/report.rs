//! Reports of `igi bench`: `results.json` (the [`BenchResults`] itself), `results.csv`
//! (one row per run), `results.md` (the paper's table per scene: fps and frame time per
//! set-up and VPL count, the stages' shares, the image error) and charts per scene
//! (stacked stage times as in the paper's figures, error against frame time), as SVG and,
//! when a TrueType font is found, PNG.
//!
//! Every file is written to a temporary name and renamed into place, so an interrupted
//! run leaves no half-written file.

use super::model::{BenchResults, BenchRun};
use anyhow::{Context, Result};
use igi_core::image::write_atomically;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::fmt::Write as _;
use std::io::BufWriter;
use std::path::Path;
use std::sync::OnceLock;

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

// ---------------------------------------------------------------------------------------
// CSV

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
fn sig3(v: f64) -> String {
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
fn cell(text: &str) -> String {
    text.replace('|', "\\|").replace(['\n', '\r'], " ")
}

/// Inline code, whatever backticks `text` holds.
fn code(text: &str) -> String {
    let longest = text.split(|c| c != '`').map(str::len).max().unwrap_or(0);
    let fence = "`".repeat(longest + 1);
    let pad = if text.starts_with('`') || text.ends_with('`') {
        " "
    } else {
        ""
    };
    format!("{fence}{pad}{}{pad}{fence}", cell(text))
}

fn fps_cell(r: &BenchRun) -> String {
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

// ---------------------------------------------------------------------------------------
// Charts

/// Tableau 10.
const PALETTE: [RGBColor; 10] = [
    RGBColor(78, 121, 167),
    RGBColor(242, 142, 43),
    RGBColor(225, 87, 89),
    RGBColor(118, 183, 178),
    RGBColor(89, 161, 79),
    RGBColor(237, 201, 72),
    RGBColor(176, 122, 161),
    RGBColor(255, 157, 167),
    RGBColor(156, 117, 95),
    RGBColor(186, 176, 172),
];

fn colour(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// Fonts tried for the PNG charts, after `$IGI_FONT` (a .ttf/.otf path; "none" for no
/// font). Debian/Ubuntu (fonts-dejavu-core, fonts-liberation), Fedora, Arch, macOS, Windows.
const FONT_PATHS: &[&str] = &[
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu-sans-fonts/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
    "/usr/share/fonts/truetype/liberation2/LiberationSans-Regular.ttf",
    "/usr/share/fonts/liberation-sans/LiberationSans-Regular.ttf",
    "/usr/share/fonts/liberation/LiberationSans-Regular.ttf",
    "/usr/share/fonts/truetype/freefont/FreeSans.ttf",
    "/usr/share/fonts/noto/NotoSans-Regular.ttf",
    "/usr/share/fonts/truetype/noto/NotoSans-Regular.ttf",
    "/System/Library/Fonts/Supplemental/Arial.ttf",
    "/Library/Fonts/Arial.ttf",
    "C:\\Windows\\Fonts\\arial.ttf",
];

/// Register a TrueType font as "sans-serif" for plotters' bitmap backend, once per
/// process. Ok(path of the font) or Err(why there is none).
fn ensure_font() -> &'static Result<String, String> {
    static FONT: OnceLock<Result<String, String>> = OnceLock::new();
    FONT.get_or_init(|| {
        let mut notes = Vec::new();
        let mut candidates: Vec<String> = Vec::new();
        if let Ok(p) = std::env::var("IGI_FONT") {
            if p.is_empty() || p.eq_ignore_ascii_case("none") {
                return Err(format!("IGI_FONT={p:?} asks for no font"));
            }
            candidates.push(p);
        }
        candidates.extend(FONT_PATHS.iter().map(|p| p.to_string()));
        for path in candidates {
            let Ok(bytes) = std::fs::read(&path) else {
                continue;
            };
            // plotters keeps fonts for the life of the process: leak the one we register.
            let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
            match plotters::style::register_font("sans-serif", FontStyle::Normal, bytes) {
                Ok(()) => return Ok(path),
                Err(_) => notes.push(format!("'{path}' is not a usable font")),
            }
        }
        notes.push(format!(
            "none of {} found (install fonts-dejavu-core or set IGI_FONT)",
            FONT_PATHS[0]
        ));
        Err(notes.join("; "))
    })
}

type DrawResult = std::result::Result<(), String>;

fn de(e: impl std::fmt::Display) -> String {
    e.to_string()
}

fn render_svg(
    size: (u32, u32),
    draw: impl FnOnce(&DrawingArea<SVGBackend<'_>, Shift>) -> DrawResult,
) -> std::result::Result<String, String> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        draw(&root)?;
        root.present().map_err(de)?;
    }
    Ok(svg)
}

fn render_png(
    size: (u32, u32),
    draw: impl FnOnce(&DrawingArea<BitMapBackend<'_>, Shift>) -> DrawResult,
) -> std::result::Result<Vec<u8>, String> {
    let mut rgb = vec![255u8; size.0 as usize * size.1 as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area();
        draw(&root)?;
        root.present().map_err(de)?;
    }
    let mut out = Vec::new();
    {
        let mut encoder = png::Encoder::new(BufWriter::new(&mut out), size.0, size.1);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().map_err(de)?;
        writer.write_image_data(&rgb).map_err(de)?;
        writer.finish().map_err(de)?;
    }
    Ok(out)
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

/// Per scene: `stages-<scene>.svg/.png` (stacked median stage times, one bar per set-up
/// and VPL count, the median frame time marked) and, when the scene has image errors,
/// `error-<scene>.svg/.png` (relMSE and FLIP against the median frame time, one series
/// per set-up through its VPL counts). PNGs need a TrueType font; without one they are
/// skipped with a warning. Returns the warnings.
pub fn write_charts(results: &BenchResults, dir: &Path) -> Result<Vec<String>> {
    let mut warnings = Vec::new();
    let png = match ensure_font() {
        Ok(_) => true,
        Err(why) => {
            warnings.push(format!("PNG charts skipped: no font ({why})"));
            false
        }
    };
    for scene in scenes(results) {
        let sc = SceneRuns::new(results, &scene);
        let [stages_svg, stages_png, error_svg, error_png] = chart_files(&scene);

        let size = stages_chart_size(&sc);
        let svg = render_svg(size, |a| draw_stages(a, &sc))
            .map_err(|e| anyhow::anyhow!("stage chart of '{scene}': {e}"))?;
        write_file(&dir.join(stages_svg), svg.as_bytes())?;
        if png {
            let bytes = render_png(size, |a| draw_stages(a, &sc))
                .map_err(|e| anyhow::anyhow!("stage chart of '{scene}': {e}"))?;
            write_file(&dir.join(stages_png), &bytes)?;
        }

        if !sc.has_errors() {
            warnings.push(format!(
                "scene '{scene}': no image error measured, no error chart"
            ));
            continue;
        }
        let size = (1200, 520);
        let svg = render_svg(size, |a| draw_errors(a, &sc))
            .map_err(|e| anyhow::anyhow!("error chart of '{scene}': {e}"))?;
        write_file(&dir.join(error_svg), svg.as_bytes())?;
        if png {
            let bytes = render_png(size, |a| draw_errors(a, &sc))
                .map_err(|e| anyhow::anyhow!("error chart of '{scene}': {e}"))?;
            write_file(&dir.join(error_png), &bytes)?;
        }
    }
    Ok(warnings)
}

const LEGEND_WIDTH: u32 = 210;

/// The legend's width for entries named `names`: at least [`LEGEND_WIDTH`], and room for
/// the longest name (13-pixel sans-serif, at most 8 pixels a character, after the
/// 36-pixel swatch), so that long stage names ("mirror chains + mirror indirect +
/// indirect") are not cut off.
fn legend_width<'a>(names: impl IntoIterator<Item = &'a str>) -> u32 {
    let longest = names
        .into_iter()
        .map(|n| n.chars().count())
        .max()
        .unwrap_or(0);
    LEGEND_WIDTH.max(36 + 8 * longest as u32 + 12)
}

/// The stage chart's legend width (its stages and the frame line).
fn stages_legend_width(sc: &SceneRuns) -> u32 {
    let names = stage_names(sc.runs.iter().copied());
    legend_width(names.iter().map(String::as_str).chain(["frame (median)"]))
}
const BAR_PITCH: u32 = 64;

/// Bars of the stage chart: (x position, set-up index, run); set-ups are separated by a
/// gap of one bar.
fn bars<'a>(sc: &SceneRuns<'a>) -> Vec<(f64, usize, &'a BenchRun)> {
    let mut out = Vec::new();
    let mut x = 0.0;
    for (g, setup) in sc.setups.iter().enumerate() {
        for &v in &sc.vpls {
            if let Some(r) = sc.get(setup, v) {
                out.push((x, g, r));
                x += 1.0;
            }
        }
        x += 1.0;
    }
    out
}

fn stages_chart_size(sc: &SceneRuns) -> (u32, u32) {
    let slots = bars(sc).len() as u32 + sc.setups.len() as u32;
    (
        (slots * BAR_PITCH + 120 + stages_legend_width(sc)).max(760),
        560,
    )
}

/// Text centred on a point, `size` pixels high.
fn centred(size: u32) -> TextStyle<'static> {
    ("sans-serif", size)
        .into_font()
        .color(&BLACK)
        .pos(Pos::new(HPos::Center, VPos::Top))
}

fn left(size: u32) -> TextStyle<'static> {
    ("sans-serif", size)
        .into_font()
        .color(&BLACK)
        .pos(Pos::new(HPos::Left, VPos::Center))
}

/// Legend entries drawn by hand (plotters' own legend needs font metrics, which the SVG
/// must do without): a swatch and a name per entry, top to bottom.
fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    title: &str,
    entries: &[(String, ShapeStyle, bool)],
) -> DrawResult {
    let top = 60;
    area.draw(&Text::new(title.to_string(), (10, top), left(15)))
        .map_err(de)?;
    for (i, (name, style, line)) in entries.iter().enumerate() {
        let y = top + 26 + 22 * i as i32;
        if *line {
            area.draw(&PathElement::new(vec![(10, y), (28, y)], *style))
                .map_err(de)?;
        } else {
            area.draw(&Rectangle::new([(10, y - 7), (28, y + 7)], *style))
                .map_err(de)?;
        }
        area.draw(&Text::new(name.clone(), (36, y), left(13)))
            .map_err(de)?;
    }
    Ok(())
}

/// A white chart with `title` on top: the areas left for the plot and for the legend.
type Areas<DB> = (DrawingArea<DB, Shift>, DrawingArea<DB, Shift>);
fn titled<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: String,
    legend_width: u32,
) -> Result<Areas<DB>, String> {
    root.fill(&WHITE).map_err(de)?;
    let (w, _h) = root.dim_in_pixel();
    let (top, body) = root.split_vertically(44);
    top.draw(&Text::new(title, (w as i32 / 2, 12), centred(20)))
        .map_err(de)?;
    Ok(body.split_horizontally(w.saturating_sub(legend_width)))
}

fn draw_stages<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, sc: &SceneRuns) -> DrawResult {
    let (plot, legend) = titled(
        root,
        format!("{}: GPU time per stage (medians)", sc.name),
        stages_legend_width(sc),
    )?;

    let bars = bars(sc);
    let top = bars
        .iter()
        .map(|(_, _, r)| {
            let stacked: f64 = r.stages.iter().map(|s| s.time.median_ms).sum();
            stacked.max(r.frame.median_ms)
        })
        .fold(0.0f64, f64::max);
    let ymax = if top > 0.0 { top * 1.15 } else { 1.0 };
    let xmax = bars.last().map_or(1.0, |b| b.0) + 0.7;

    let mut chart = ChartBuilder::on(&plot)
        .margin(10)
        .x_label_area_size(56)
        .y_label_area_size(64)
        .build_cartesian_2d(-0.7f64..xmax, 0f64..ymax)
        .map_err(de)?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_labels(0)
        .y_desc("GPU time (ms)")
        .label_style(("sans-serif", 13))
        .axis_desc_style(("sans-serif", 14))
        .draw()
        .map_err(de)?;

    for &(x, _, r) in &bars {
        let mut base = 0.0;
        for st in &r.stages {
            let k = sc.stages.iter().position(|n| n == &st.name).unwrap_or(0);
            let t = st.time.median_ms.max(0.0);
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(x - 0.4, base), (x + 0.4, base + t)],
                    colour(k).filled(),
                )))
                .map_err(de)?;
            base += t;
        }
        chart
            .draw_series(std::iter::once(PathElement::new(
                vec![(x - 0.47, r.frame.median_ms), (x + 0.47, r.frame.median_ms)],
                BLACK.stroke_width(2),
            )))
            .map_err(de)?;
        let label_y = base.max(r.frame.median_ms);
        chart
            .draw_series(std::iter::once(
                EmptyElement::at((x, label_y))
                    + Text::new(format!("{} fps", sig3(r.fps)), (0, -18), centred(11)),
            ))
            .map_err(de)?;
    }

    // Axis labels by hand: the VPL count under each bar, the set-up under its group.
    for &(x, _, r) in &bars {
        let (px, py) = chart.backend_coord(&(x, 0.0));
        root.draw(&Text::new(
            r.vpls_asked.to_string(),
            (px, py + 6),
            centred(12),
        ))
        .map_err(de)?;
    }
    for (g, setup) in sc.setups.iter().enumerate() {
        let xs: Vec<f64> = bars.iter().filter(|b| b.1 == g).map(|b| b.0).collect();
        if xs.is_empty() {
            continue;
        }
        let mid = (xs[0] + xs[xs.len() - 1]) / 2.0;
        let (px, py) = chart.backend_coord(&(mid, 0.0));
        root.draw(&Text::new(setup.clone(), (px, py + 24), centred(14)))
            .map_err(de)?;
    }
    let (px, py) = chart.backend_coord(&(-0.7, 0.0));
    root.draw(&Text::new(
        "VPLs".to_string(),
        (px - 8, py + 12),
        ("sans-serif", 12)
            .into_font()
            .color(&BLACK)
            .pos(Pos::new(HPos::Right, VPos::Center)),
    ))
    .map_err(de)?;

    // Stages top to bottom as they are stacked.
    let mut entries: Vec<(String, ShapeStyle, bool)> = sc
        .stages
        .iter()
        .enumerate()
        .rev()
        .map(|(k, n)| (n.clone(), colour(k).filled(), false))
        .collect();
    entries.push(("frame (median)".into(), BLACK.stroke_width(2), true));
    draw_legend(&legend, "Stages", &entries)
}

/// (set-up index, VPLs asked, median frame ms, error) of one scene's runs with an error.
type ErrorPoint = (usize, u32, f64, f64);

/// One line per set-up through its VPL counts, points labelled with the VPL count.
fn draw_setup_series<DB, X, Y>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<X, Y>>,
    setups: usize,
    points: &[ErrorPoint],
) -> DrawResult
where
    DB: DrawingBackend,
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    for g in 0..setups {
        let series: Vec<&ErrorPoint> = points.iter().filter(|p| p.0 == g).collect();
        if series.is_empty() {
            continue;
        }
        let c = colour(g);
        chart
            .draw_series(LineSeries::new(
                series.iter().map(|p| (p.2, p.3)),
                c.stroke_width(2),
            ))
            .map_err(de)?;
        chart
            .draw_series(series.iter().map(|p| {
                EmptyElement::at((p.2, p.3))
                    + Circle::new((0, 0), 4, c.filled())
                    + Text::new(
                        p.1.to_string(),
                        (6, -16),
                        ("sans-serif", 11).into_font().color(&BLACK),
                    )
            }))
            .map_err(de)?;
    }
    Ok(())
}

/// Powers of ten around the positive values (one decade when there are none).
fn decades(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| *v > 0.0 && v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if !lo.is_finite() {
        return (1e-3, 1e-2);
    }
    let lo = lo.log10().floor();
    let hi = hi.log10().ceil().max(lo + 1.0);
    (10f64.powf(lo), 10f64.powf(hi))
}

/// relMSE (log axis) and FLIP (linear axis) against the median frame time.
fn draw_errors<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, sc: &SceneRuns) -> DrawResult {
    let (plots, legend) = titled(
        root,
        format!("{}: image error against frame time", sc.name),
        legend_width(
            sc.setups
                .iter()
                .map(String::as_str)
                .chain(["Set-ups (points: VPLs)"]),
        ),
    )?;
    let panels = plots.split_evenly((1, 2));

    let mut mse: Vec<ErrorPoint> = Vec::new();
    let mut flip: Vec<ErrorPoint> = Vec::new();
    for (g, setup) in sc.setups.iter().enumerate() {
        for &v in &sc.vpls {
            if let Some(r) = sc.get(setup, v) {
                if let Some(e) = &r.error {
                    mse.push((g, v, r.frame.median_ms, e.rel_mse));
                    flip.push((g, v, r.frame.median_ms, e.flip));
                }
            }
        }
    }
    let xmax = mse.iter().map(|p| p.2).fold(0.0f64, f64::max);
    let xmax = if xmax > 0.0 { xmax * 1.15 } else { 1.0 };
    let (lo, hi) = decades(mse.iter().map(|p| p.3));
    // Zero (identical images) sits on the bottom of the log axis.
    for p in &mut mse {
        p.3 = if p.3 > 0.0 { p.3.max(lo) } else { lo };
    }
    let flip_max = flip.iter().map(|p| p.3).fold(0.0f64, f64::max);
    let flip_max = if flip_max > 0.0 {
        (flip_max * 1.2).min(1.0)
    } else {
        0.1
    };
    let fmt_mse = |y: &f64| format!("{y:.0e}");

    let mut chart = ChartBuilder::on(&panels[0])
        .margin(12)
        .x_label_area_size(44)
        .y_label_area_size(64)
        // A hair wider than the decades, so that both end labels survive rounding.
        .build_cartesian_2d(0f64..xmax, (lo * 0.999..hi * 1.001).log_scale())
        .map_err(de)?;
    chart
        .configure_mesh()
        .x_desc("median frame time (ms)")
        .y_desc("relMSE (log scale)")
        .y_label_formatter(&fmt_mse)
        .label_style(("sans-serif", 13))
        .axis_desc_style(("sans-serif", 14))
        .draw()
        .map_err(de)?;
    draw_setup_series(&mut chart, sc.setups.len(), &mse)?;

    let mut chart = ChartBuilder::on(&panels[1])
        .margin(12)
        .x_label_area_size(44)
        .y_label_area_size(64)
        .build_cartesian_2d(0f64..xmax, 0f64..flip_max)
        .map_err(de)?;
    chart
        .configure_mesh()
        .x_desc("median frame time (ms)")
        .y_desc("mean FLIP")
        .label_style(("sans-serif", 13))
        .axis_desc_style(("sans-serif", 14))
        .draw()
        .map_err(de)?;
    draw_setup_series(&mut chart, sc.setups.len(), &flip)?;

    let entries: Vec<(String, ShapeStyle, bool)> = sc
        .setups
        .iter()
        .enumerate()
        .map(|(g, s)| (s.clone(), colour(g).stroke_width(3), true))
        .collect();
    draw_legend(&legend, "Set-ups (points: VPLs)", &entries)
}

#[cfg(test)]
mod tests {
    use super::super::model::*;
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
            eprintln!("report kept in {}", dir.display());
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
