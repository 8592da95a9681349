//! The report's charts per scene, drawn with plotters: stacked stage times, and image
//! error against frame time; SVG always, PNG where a TrueType font is found.

use super::tables::sig3;
use super::{chart_files, scenes, stage_names, write_file, SceneRuns};
use crate::bench::model::{BenchResults, BenchRun};
use anyhow::Result;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::io::BufWriter;
use std::path::Path;
use std::sync::OnceLock;

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
pub(super) fn ensure_font() -> &'static Result<String, String> {
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

pub(super) const LEGEND_WIDTH: u32 = 210;

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
pub(super) fn stages_legend_width(sc: &SceneRuns) -> u32 {
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

pub(super) fn stages_chart_size(sc: &SceneRuns) -> (u32, u32) {
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
