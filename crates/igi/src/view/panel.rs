//! The viewer's side panel (egui): every option of the frame and of the paper's
//! accelerations (sections 4.1-4.3), the lights, and live GPU timings. Edits change a
//! [`ViewState`]; the viewer compares it with the last frame's to restart accumulation.

use egui::{ComboBox, DragValue, Slider, Ui};
use igi_core::scene::{max_light_intensity, PointLight};
use igi_core::settings::{
    FilterMode, GeometryBound, InterleavePattern, OutputBuffer, RenderSettings,
};
use igi_gpu::profiler::StageTime;

/// What the panel edits.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewState {
    /// The frame's settings; width and height follow the window (or `--width/--height`).
    pub settings: RenderSettings,
    /// Draw the VPLs of the frame as dots over the image.
    pub show_vpls: bool,
    /// The image is the viewport's size divided by this (1, 2, 4, 8).
    pub render_scale: u32,
    /// Still frames averaged at most (each with a fresh VPL set).
    pub max_accumulate: u32,
    /// Movement speed as a fraction of the scene's diagonal per second.
    pub speed: f32,
    pub lights: Vec<PointLight>,
    pub selected_light: usize,
}

/// What the viewer measured of the last frame.
#[derive(Clone, Debug, Default)]
pub struct Stats {
    pub adapter: String,
    pub triangles: usize,
    pub stages: Vec<StageTime>,
    /// GPU time of the frame, first stage start to last stage end.
    pub gpu_ms: Option<f64>,
    /// Wall time of one redraw: frame, readbacks, panel and present (smoothed).
    pub wall_ms: f64,
    pub vpl_count: u32,
    pub accumulated: u32,
    pub image: (u32, u32),
    /// The last error of a screenshot or a print, shown until the next one.
    pub message: Option<String>,
}

/// Buttons pressed this frame.
#[derive(Clone, Copy, Debug, Default)]
pub struct Actions {
    pub screenshot: bool,
    pub reset_camera: bool,
    pub print_camera: bool,
}

const BUFFERS: [(OutputBuffer, &str); 6] = [
    (OutputBuffer::Final, "final"),
    (OutputBuffer::Direct, "direct + specular"),
    (OutputBuffer::Indirect, "indirect"),
    (OutputBuffer::Irradiance, "irradiance E"),
    (OutputBuffer::Normals, "normals"),
    (OutputBuffer::Depth, "depth"),
];

/// The panel's contents.
pub fn show(ui: &mut Ui, state: &mut ViewState, stats: &Stats, diagonal: f32) -> Actions {
    let mut actions = Actions::default();
    egui::ScrollArea::vertical().show(ui, |ui| {
        timings(ui, state, stats);
        ui.separator();
        ui.horizontal(|ui| {
            actions.screenshot = ui.button("Screenshot (F12)").clicked();
            actions.print_camera = ui.button("Print camera (C)").clicked();
        });
        if let Some(m) = &stats.message {
            ui.label(m);
        }
        ui.separator();
        frame_settings(ui, state, diagonal);
        ui.separator();
        accelerations(ui, &mut state.settings);
        ui.separator();
        lights(ui, state, diagonal);
        ui.separator();
        ui.collapsing("Camera", |ui| {
            ui.add(
                Slider::new(&mut state.speed, 0.01..=2.0)
                    .logarithmic(true)
                    .text("speed (diagonal/s)"),
            );
            actions.reset_camera = ui.button("Reset to the scene's camera (R)").clicked();
            ui.label(
                "Right or left mouse button held: look. WASD: move, Q/E: down/up, Shift: faster.",
            );
        });
    });
    actions
}

fn timings(ui: &mut Ui, state: &ViewState, stats: &Stats) {
    ui.heading("igi");
    ui.label(&stats.adapter);
    ui.label(format!(
        "{} x {} pixels, {} triangles",
        stats.image.0, stats.image.1, stats.triangles
    ));
    let fps = if stats.wall_ms > 0.0 {
        1000.0 / stats.wall_ms
    } else {
        0.0
    };
    ui.label(format!("frame {:.2} ms wall ({fps:.1} fps)", stats.wall_ms));
    ui.label(format!(
        "VPLs: {} ({} asked); accumulated {} / {}",
        stats.vpl_count, state.settings.vpls, stats.accumulated, state.max_accumulate
    ));
    if stats.stages.is_empty() {
        ui.label("GPU stage times: no timestamp queries on this adapter");
        return;
    }
    egui::Grid::new("stages").striped(true).show(ui, |ui| {
        for s in &stats.stages {
            ui.label(s.name);
            ui.monospace(format!("{:8.3} ms", s.ms));
            ui.end_row();
        }
        if let Some(ms) = stats.gpu_ms {
            ui.strong("GPU frame");
            ui.monospace(format!("{ms:8.3} ms"));
            ui.end_row();
        }
    });
}

fn frame_settings(ui: &mut Ui, state: &mut ViewState, diagonal: f32) {
    let s = &mut state.settings;
    ui.strong("Frame");
    ui.add(
        Slider::new(&mut s.vpls, 1..=4096)
            .logarithmic(true)
            .text("VPLs"),
    );
    ui.add(Slider::new(&mut s.bounces, 1..=16).text("bounces"));
    ui.add(Slider::new(&mut s.mirror_depth, 0..=16).text("mirror depth"));
    let mut auto = s.min_dist.is_none();
    ui.horizontal(|ui| {
        ui.checkbox(&mut auto, "bounding distance: auto (5% diagonal)");
    });
    if auto {
        s.min_dist = None;
    } else {
        let mut m = s
            .min_dist
            .unwrap_or(igi_core::settings::DEFAULT_MIN_DIST_FRACTION * diagonal);
        ui.add(
            Slider::new(&mut m, (1e-4 * diagonal)..=(0.5 * diagonal))
                .logarithmic(true)
                .text("m"),
        );
        s.min_dist = Some(m);
    }
    ComboBox::from_label("bound of G")
        .selected_text(match s.geometry_bound {
            GeometryBound::Smoothstep => "smoothstep",
            GeometryBound::Clamp => "clamp",
        })
        .show_ui(ui, |ui| {
            ui.selectable_value(
                &mut s.geometry_bound,
                GeometryBound::Smoothstep,
                "smoothstep",
            );
            ui.selectable_value(&mut s.geometry_bound, GeometryBound::Clamp, "clamp");
        });
    ui.add(DragValue::new(&mut s.seed).prefix("seed "));
    ui.add(
        Slider::new(&mut s.exposure, 0.01..=100.0)
            .logarithmic(true)
            .text("exposure"),
    );
    let shown = BUFFERS
        .iter()
        .find(|(b, _)| *b == s.output)
        .map_or("?", |(_, n)| n);
    ComboBox::from_label("buffer")
        .selected_text(shown)
        .show_ui(ui, |ui| {
            for (b, name) in BUFFERS {
                ui.selectable_value(&mut s.output, b, name);
            }
        });
    ui.checkbox(&mut state.show_vpls, "VPL positions as dots");
    ComboBox::from_label("render scale")
        .selected_text(format!("1/{}", state.render_scale))
        .show_ui(ui, |ui| {
            for f in [1, 2, 4, 8] {
                ui.selectable_value(&mut state.render_scale, f, format!("1/{f}"));
            }
        });
    ui.add(
        Slider::new(&mut state.max_accumulate, 1..=4096)
            .logarithmic(true)
            .text("accumulate at most"),
    );
}

fn accelerations(ui: &mut Ui, s: &mut RenderSettings) {
    let a = &mut s.accelerations;
    ui.strong("Accelerations");
    ui.horizontal(|ui| {
        for (name, setup) in [
            ("canonical", "canonical"),
            ("iv", "iv"),
            ("iv+ds", "iv+ds"),
            ("iv+ds+il", "iv+ds+il"),
        ] {
            if ui.small_button(name).clicked() {
                *a = igi_core::settings::Accelerations::from_setup(setup).expect("known set-up");
            }
        }
    });
    ui.checkbox(&mut a.imperfect_visibility, "imperfect visibility (4.1)");
    ui.add(Slider::new(&mut a.downsample, 1..=16).text("downsample (4.2)"));
    ui.horizontal(|ui| {
        ui.label("interleave (4.3)");
        ui.add(DragValue::new(&mut a.interleave.0).range(1..=8));
        ui.label("x");
        ui.add(DragValue::new(&mut a.interleave.1).range(1..=8));
    });
    ComboBox::from_label("pattern")
        .selected_text(match a.pattern {
            InterleavePattern::Regular => "regular",
            InterleavePattern::Irregular => "irregular",
        })
        .show_ui(ui, |ui| {
            ui.selectable_value(&mut a.pattern, InterleavePattern::Regular, "regular");
            ui.selectable_value(&mut a.pattern, InterleavePattern::Irregular, "irregular");
        });
    ComboBox::from_label("filter")
        .selected_text(match a.filter {
            FilterMode::TwoPass => "two passes",
            FilterMode::Fused => "fused",
        })
        .show_ui(ui, |ui| {
            ui.selectable_value(&mut a.filter, FilterMode::TwoPass, "two passes");
            ui.selectable_value(&mut a.filter, FilterMode::Fused, "fused");
        });
    ui.collapsing("filter thresholds", |ui| {
        ui.add(Slider::new(&mut a.upsample_sigma, 0.25..=4.0).text("upsample sigma"));
        ui.add(Slider::new(&mut a.upsample_normal_power, 0.0..=64.0).text("normal power"));
        ui.checkbox(&mut a.upsample_depth, "depth in the upsampler's weight");
        ui.add(
            Slider::new(&mut a.depth_threshold, 0.001..=1.0)
                .logarithmic(true)
                .text("depth threshold"),
        );
        ui.add(Slider::new(&mut a.normal_threshold, -1.0..=1.0).text("normal threshold"));
    });
}

fn lights(ui: &mut Ui, state: &mut ViewState, diagonal: f32) {
    ui.strong(format!("Lights ({})", state.lights.len()));
    if state.lights.is_empty() {
        return;
    }
    state.selected_light = state.selected_light.min(state.lights.len() - 1);
    ComboBox::from_label("light")
        .selected_text(format!("light {}", state.selected_light))
        .show_ui(ui, |ui| {
            for i in 0..state.lights.len() {
                ui.selectable_value(&mut state.selected_light, i, format!("light {i}"));
            }
        });
    // Each channel at most what keeps the lights' total power within f32, as loading
    // requires (beyond it, light choice divides by infinity and the image turns NaN).
    let max = [0, 1, 2].map(|c| max_light_intensity(&state.lights, state.selected_light, c));
    let light = &mut state.lights[state.selected_light];
    let speed = 0.002 * diagonal;
    ui.horizontal(|ui| {
        ui.label("position");
        for c in 0..3 {
            ui.add(DragValue::new(&mut light.position[c]).speed(speed));
        }
    });
    let step = 0.01 * light.intensity.max_element().max(0.1);
    ui.horizontal(|ui| {
        ui.label("intensity");
        for (channel, max) in light.intensity.as_mut().iter_mut().zip(max) {
            ui.add(DragValue::new(channel).speed(step).range(0.0..=max));
        }
    });
}
