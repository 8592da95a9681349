//! `igi view`: the interactive viewer, the paper's point (section 5: a person walks through
//! a lit interior and sees global illumination at once). A window (winit) showing the
//! composed frame of [`igi_gpu::Renderer`] through the display pass, an egui side panel
//! with every option and the per-stage GPU times, a fly camera, light editing, and
//! progressive convergence: while nothing changes, frames with fresh VPL sets are averaged
//! (the frames of `igi render --accumulate K`, so a still view converges to the same image).

pub mod camera;
pub mod panel;

use anyhow::{anyhow, bail, Context, Result};
use camera::{FlyCamera, Movement};
use igi_core::bvh::Bvh;
use igi_core::image::Image;
use igi_core::scene::{camera_toml, Camera, Scene};
use igi_core::settings::RenderSettings;
use igi_gpu::passes::display::{DisplayOptions, DisplayPass};
use igi_gpu::{AdapterChoice, GpuContext, Renderer};
use panel::{Stats, ViewState};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::window::{Window, WindowId};

/// Width of the side panel, in egui points.
pub const PANEL_WIDTH: f32 = 320.0;

/// Everything `igi view` was asked for.
pub struct ViewOptions {
    pub scene: Scene,
    /// The frame's settings (width and height are replaced, see `fixed_size`).
    pub settings: RenderSettings,
    /// Image size pinned by `--width/--height`; otherwise the image follows the window.
    pub fixed_size: Option<(u32, u32)>,
    pub adapter: AdapterChoice,
    /// The camera to start from (`--camera`), else the scene's.
    pub camera: Option<Camera>,
    /// Render this many frames, then save the screenshot (if asked) and exit.
    pub frames: Option<u32>,
    /// Where the screenshot goes (PNG; the linear frame beside it as .exr).
    pub screenshot: Option<PathBuf>,
    pub max_accumulate: u32,
    pub render_scale: u32,
    pub show_vpls: bool,
    pub bvh: igi_core::bvh::BvhBuilder,
    /// Initial inner size of the window, in physical pixels.
    pub window: (u32, u32),
}

/// Open the window and run until it is closed (or `frames` are done).
pub fn run(opts: ViewOptions) -> Result<()> {
    let t = Instant::now();
    let bvh = Bvh::build_with(&opts.scene.triangles, opts.bvh);
    crate::note!(
        "scene {}: {} triangles, {} lights ({})",
        opts.scene.source,
        opts.scene.triangles.len(),
        opts.scene.lights.len(),
        crate::bvh_built(&bvh, opts.bvh, t.elapsed().as_secs_f64() * 1e3)
    );
    let event_loop = EventLoop::new().map_err(|e| {
        let var = |name: &str| std::env::var(name).ok().filter(|v| !v.is_empty());
        let wayland = var("WAYLAND_DISPLAY").or_else(|| var("WAYLAND_SOCKET"));
        anyhow!(no_display_message(
            &winit_reason(&e),
            wayland,
            var("DISPLAY")
        ))
    })?;
    let mut app = App {
        opts,
        bvh,
        viewer: None,
        error: None,
    };
    event_loop
        .run_app(&mut app)
        .map_err(|e| anyhow!("the window's event loop failed: {e}"))?;
    match app.error {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

/// A winit error without the place in winit's source that raised it: its OS errors read
/// "os error at /root/.cargo/registry/.../mod.rs:765: REASON", which tells a user nothing.
fn winit_reason(e: &impl std::fmt::Display) -> String {
    let text = e.to_string();
    let reason = match text.strip_prefix("os error at ") {
        Some(rest) => rest.split_once(": ").map_or(rest, |(_, reason)| reason),
        None => &text,
    };
    reason.trim().trim_end_matches('.').to_string()
}

/// Why no event loop could start, from winit's `reason` and the display variables as winit
/// reads them (Wayland first, then X): a display named but not reachable is said by name,
/// as "set DISPLAY" would be no help there.
fn no_display_message(reason: &str, wayland: Option<String>, x: Option<String>) -> String {
    match (wayland, x) {
        (Some(w), _) => format!(
            "cannot open a window: cannot connect to Wayland display '{w}' ({reason})"
        ),
        (None, Some(d)) => format!(
            "cannot open a window: cannot connect to display '{d}' ({reason}): start an X server there, or run under xvfb-run"
        ),
        (None, None) => "cannot open a window: no display: set DISPLAY or WAYLAND_DISPLAY, or run under xvfb-run".to_string(),
    }
}

struct App {
    opts: ViewOptions,
    bvh: Bvh,
    viewer: Option<Viewer>,
    error: Option<anyhow::Error>,
}

impl App {
    fn fail(&mut self, event_loop: &ActiveEventLoop, e: anyhow::Error) {
        if self.error.is_none() {
            self.error = Some(e);
        }
        event_loop.exit();
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.viewer.is_some() {
            return;
        }
        match Viewer::new(event_loop, &self.opts, &self.bvh) {
            Ok(v) => {
                v.window.request_redraw();
                self.viewer = Some(v);
            }
            Err(e) => self.fail(event_loop, e),
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let Some(viewer) = self.viewer.as_mut() else {
            return;
        };
        let result = match event {
            WindowEvent::CloseRequested => {
                event_loop.exit();
                Ok(())
            }
            WindowEvent::RedrawRequested => viewer.redraw(&self.opts).map(|done| {
                if done {
                    event_loop.exit();
                }
            }),
            event => {
                if viewer.input(&event) == Control::Exit {
                    event_loop.exit();
                }
                Ok(())
            }
        };
        if let Err(e) = result {
            self.fail(event_loop, e);
        }
    }
}

#[derive(PartialEq, Eq)]
enum Control {
    Continue,
    Exit,
}

/// The window, the GPU and what the viewer keeps between frames.
struct Viewer {
    window: Arc<Window>,
    ctx: GpuContext,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    renderer: Renderer,
    display: DisplayPass,
    egui_ctx: egui::Context,
    egui_state: egui_winit::State,
    egui_renderer: egui_wgpu::Renderer,
    /// Where the camera starts and returns to (R).
    home: Camera,
    fly: FlyCamera,
    movement: Movement,
    /// The last cursor position, while a mouse button looks around.
    looking: Option<(f64, f64)>,
    looked: bool,
    state: ViewState,
    /// What the colour buffer's accumulation was made with.
    applied: Option<(RenderSettings, Camera, Vec<igi_core::scene::PointLight>)>,
    accumulated: u32,
    frames_rendered: u32,
    stats: Stats,
    last: Instant,
    /// When the first frame was presented: the frame rate `--frames` reports leaves out
    /// the first frame (pipeline compilation, the pilot run).
    started: Option<Instant>,
    diagonal: f32,
    /// Asked by a key, done after the next frame.
    screenshot: bool,
    print_camera: bool,
}

impl Viewer {
    fn new(event_loop: &ActiveEventLoop, opts: &ViewOptions, bvh: &Bvh) -> Result<Viewer> {
        let scene = &opts.scene;
        let attributes = Window::default_attributes()
            .with_title(format!("igi: {}", scene.source))
            .with_inner_size(winit::dpi::PhysicalSize::new(opts.window.0, opts.window.1));
        let window = Arc::new(
            event_loop
                .create_window(attributes)
                .map_err(|e| anyhow!("cannot open a window: {}", winit_reason(&e)))?,
        );
        let (ctx, surface) = GpuContext::for_window(
            &opts.adapter,
            window.clone(),
            Box::new(event_loop.owned_display_handle()),
        )?;
        crate::note!("adapter: {}", ctx.describe());
        let size = window.inner_size();
        let mut config = surface
            .get_default_config(&ctx.adapter, size.width.max(1), size.height.max(1))
            .ok_or_else(|| anyhow!("adapter '{}' cannot present to this window", ctx.info.name))?;
        // Uncapped: the panel's fps says how fast igi is, not the display's refresh rate.
        config.present_mode = wgpu::PresentMode::AutoNoVsync;
        // A plain 8-bit format where there is one (egui blends in gamma space there); the
        // display pass encodes sRGB itself.
        let caps = surface.get_capabilities(&ctx.adapter);
        if let Some(f) = caps.formats.iter().find(|f| {
            matches!(
                f,
                wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Rgba8Unorm
            )
        }) {
            config.format = *f;
        }
        surface.configure(&ctx.device, &config);
        let renderer = Renderer::new(&ctx, scene, bvh)?;
        let display = DisplayPass::new(&ctx.device, config.format);
        let egui_ctx = egui::Context::default();
        let egui_state = egui_winit::State::new(
            egui_ctx.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            Some(ctx.device.limits().max_texture_dimension_2d as usize),
        );
        let egui_renderer =
            egui_wgpu::Renderer::new(&ctx.device, config.format, Default::default());
        let home = opts.camera.unwrap_or(scene.camera);
        let stats = Stats {
            adapter: ctx.describe(),
            triangles: scene.triangles.len(),
            ..Stats::default()
        };
        Ok(Viewer {
            fly: FlyCamera::new(&home),
            home,
            movement: Movement::default(),
            looking: None,
            looked: false,
            state: ViewState {
                settings: opts.settings.clone(),
                show_vpls: opts.show_vpls,
                render_scale: opts.render_scale.max(1),
                max_accumulate: opts.max_accumulate.max(1),
                speed: 0.2,
                lights: scene.lights.clone(),
                selected_light: 0,
            },
            applied: None,
            accumulated: 0,
            frames_rendered: 0,
            stats,
            last: Instant::now(),
            started: None,
            diagonal: scene.diagonal(),
            screenshot: false,
            print_camera: false,
            window,
            ctx,
            surface,
            config,
            renderer,
            display,
            egui_ctx,
            egui_state,
            egui_renderer,
        })
    }

    /// Input other than redraws: egui first, then the camera and the keys.
    fn input(&mut self, event: &WindowEvent) -> Control {
        let response = self.egui_state.on_window_event(&self.window, event);
        if response.repaint {
            self.window.request_redraw();
        }
        match event {
            WindowEvent::Resized(size) => {
                self.config.width = size.width.max(1);
                self.config.height = size.height.max(1);
                self.surface.configure(&self.ctx.device, &self.config);
                self.window.request_redraw();
            }
            WindowEvent::KeyboardInput { event, .. } => {
                if self.egui_ctx.egui_wants_keyboard_input() {
                    return Control::Continue;
                }
                let pressed = event.state == ElementState::Pressed;
                let PhysicalKey::Code(code) = event.physical_key else {
                    return Control::Continue;
                };
                let m = &mut self.movement;
                match code {
                    KeyCode::KeyW | KeyCode::ArrowUp => m.forward = pressed,
                    KeyCode::KeyS | KeyCode::ArrowDown => m.back = pressed,
                    KeyCode::KeyA | KeyCode::ArrowLeft => m.left = pressed,
                    KeyCode::KeyD | KeyCode::ArrowRight => m.right = pressed,
                    KeyCode::KeyE | KeyCode::PageUp => m.up = pressed,
                    KeyCode::KeyQ | KeyCode::PageDown => m.down = pressed,
                    KeyCode::ShiftLeft | KeyCode::ShiftRight => m.fast = pressed,
                    KeyCode::KeyR if pressed => self.fly = FlyCamera::new(&self.home),
                    KeyCode::KeyC if pressed => self.print_camera = true,
                    KeyCode::F12 | KeyCode::KeyP if pressed => self.screenshot = true,
                    KeyCode::Escape if pressed => return Control::Exit,
                    _ => {}
                }
                self.window.request_redraw();
            }
            WindowEvent::MouseInput { state, button, .. } => {
                if matches!(button, MouseButton::Left | MouseButton::Right) {
                    if *state == ElementState::Pressed && !self.egui_ctx.is_pointer_over_egui() {
                        self.looking = Some((f64::NAN, f64::NAN));
                    } else if *state == ElementState::Released {
                        self.looking = None;
                    }
                }
            }
            WindowEvent::CursorMoved { position, .. } => {
                if let Some((x, y)) = self.looking {
                    if x.is_finite() {
                        self.fly
                            .look((position.x - x) as f32, (position.y - y) as f32);
                        self.looked = true;
                        self.window.request_redraw();
                    }
                    self.looking = Some((position.x, position.y));
                }
            }
            WindowEvent::Focused(false) => {
                self.movement = Movement::default();
                self.looking = None;
            }
            _ => {}
        }
        Control::Continue
    }

    /// One frame: the panel, the camera, a frame of the renderer (while it converges),
    /// the display and the panel drawn into the window. Returns whether to exit.
    fn redraw(&mut self, opts: &ViewOptions) -> Result<bool> {
        let now = Instant::now();
        let seconds = (now - self.last).as_secs_f32().min(0.25);
        self.last = now;
        let moved = self
            .fly
            .fly(&self.movement, seconds, self.state.speed * self.diagonal);

        // The panel, and the rectangle it leaves for the image.
        let raw = self.egui_state.take_egui_input(&self.window);
        let mut actions = panel::Actions::default();
        let mut central = egui::Rect::NOTHING;
        let (state, stats, diagonal) = (&mut self.state, &self.stats, self.diagonal);
        let output = self.egui_ctx.run_ui(raw, |ui| {
            egui::Panel::left("settings")
                .exact_size(PANEL_WIDTH)
                .resizable(false)
                .show(ui, |ui| actions = panel::show(ui, state, stats, diagonal));
            central = ui.available_rect_before_wrap();
        });
        self.egui_state
            .handle_platform_output(&self.window, output.platform_output);
        if actions.reset_camera {
            self.fly = FlyCamera::new(&self.home);
        }
        self.print_camera |= actions.print_camera;
        self.screenshot |= actions.screenshot;

        // The image and where it goes.
        let ppp = output.pixels_per_point;
        let area = [
            (central.min.x * ppp).round(),
            (central.min.y * ppp).round(),
            (central.width() * ppp).round().max(1.0),
            (central.height() * ppp).round().max(1.0),
        ];
        let (width, height, viewport) = match opts.fixed_size {
            Some((w, h)) => (w, h, letterbox(area, w, h)),
            None => {
                let s = self.state.render_scale.max(1) as f32;
                let w = (area[2] / s).round().max(1.0) as u32;
                let h = (area[3] / s).round().max(1.0) as u32;
                (w, h, area)
            }
        };
        let settings = RenderSettings {
            width,
            height,
            ..self.state.settings.clone()
        };
        let camera = self.fly.camera();

        // Any change restarts accumulation; exposure only changes the display.
        let same_frame = |a: &RenderSettings| {
            RenderSettings {
                exposure: settings.exposure,
                ..a.clone()
            } == settings
        };
        let lights_changed = self
            .applied
            .as_ref()
            .is_some_and(|(_, _, l)| *l != self.state.lights);
        if lights_changed {
            self.renderer.set_lights(&self.ctx, &self.state.lights)?;
        }
        let unchanged = !moved
            && !self.looked
            && !lights_changed
            && self
                .applied
                .as_ref()
                .is_some_and(|(s, c, _)| same_frame(s) && *c == camera);
        if !unchanged {
            self.accumulated = 0;
        }
        self.looked = false;
        if self.accumulated < self.state.max_accumulate {
            self.renderer.set_camera(camera);
            // Frame k of an accumulation is the frame k of `igi render --accumulate`.
            let frame = RenderSettings {
                frame: settings.frame + self.accumulated,
                ..settings.clone()
            };
            // The panel keeps every value within these limits; a modifier it leaves idle
            // (a pattern without interleaving) is no error here, as the renderer ignores it.
            frame.validate_limits()?;
            let (names, _) = self
                .renderer
                .submit_frame(&self.ctx, &frame, self.accumulated)?;
            match self.renderer.read_timings(&self.ctx, &names)? {
                Some((stages, span)) => {
                    self.stats.stages = stages;
                    self.stats.gpu_ms = Some(span);
                }
                None => self.stats.stages.clear(),
            }
            self.stats.vpl_count = self.renderer.vpl_count(&self.ctx)?;
            // A software adapter's cut walks end the viewer with the renderer's error.
            self.renderer.check_walks(&self.ctx)?;
            self.accumulated += 1;
            self.frames_rendered += 1;
            self.applied = Some((settings.clone(), camera, self.state.lights.clone()));
        }
        self.stats.accumulated = self.accumulated;
        self.stats.image = (width, height);

        self.present(output.shapes, output.textures_delta, ppp, viewport)?;
        self.ctx.check()?;
        // The time this redraw took: frame, readbacks, panel and present.
        let wall_ms = now.elapsed().as_secs_f64() * 1e3;
        self.stats.wall_ms = if self.stats.wall_ms == 0.0 {
            wall_ms
        } else {
            0.9 * self.stats.wall_ms + 0.1 * wall_ms
        };

        if self.print_camera {
            self.print_camera = false;
            crate::say!("{}", camera_toml(&camera));
            self.stats.message = Some("camera printed to the standard output".into());
        }
        if self.screenshot {
            self.screenshot = false;
            let path = match &opts.screenshot {
                Some(p) => p.clone(),
                None => next_free("igi-screenshot", "png"),
            };
            self.stats.message = Some(match self.save(&path) {
                Ok(msg) => msg,
                Err(e) => format!("screenshot failed: {e:#}"),
            });
        }
        if self.frames_rendered == 1 {
            self.started.get_or_insert_with(Instant::now);
        }
        if let Some(n) = opts.frames {
            if self.frames_rendered >= n {
                if let Some(started) = self.started.filter(|_| n > 1) {
                    let seconds = started.elapsed().as_secs_f64();
                    crate::note!(
                        "frames 2 to {n} of {width}x{height} in a {}x{} window: {:.2} fps, {:.1} ms a frame{}",
                        self.config.width,
                        self.config.height,
                        (n - 1) as f64 / seconds.max(1e-9),
                        seconds * 1e3 / (n - 1) as f64,
                        self.stats.gpu_ms.map_or(String::new(), |ms| format!(
                            " (the last {ms:.3} ms of GPU time)"
                        )),
                    );
                }
                if let Some(path) = &opts.screenshot {
                    crate::note!("{}", self.save(path)?);
                }
                return Ok(true);
            }
        }
        let repaint = output
            .viewport_output
            .get(&egui::ViewportId::ROOT)
            .is_some_and(|v| v.repaint_delay.is_zero());
        if self.accumulated < self.state.max_accumulate || self.movement.any() || repaint {
            self.window.request_redraw();
        }
        Ok(false)
    }

    /// The display pass and the panel into the window's next texture.
    fn present(
        &mut self,
        shapes: Vec<egui::epaint::ClippedShape>,
        mut textures: egui::TexturesDelta,
        ppp: f32,
        viewport: [f32; 4],
    ) -> Result<()> {
        use wgpu::CurrentSurfaceTexture as Current;
        // The panel's texture changes apply whether or not this frame is shown.
        let (device, queue) = (&self.ctx.device, &self.ctx.queue);
        for (id, deltas) in textures.set.drain() {
            for delta in deltas {
                self.egui_renderer.update_texture(device, queue, id, &delta);
            }
        }
        let frees: Vec<egui::TextureId> = textures.free.drain().collect();
        let frame = match self.surface.get_current_texture() {
            Current::Success(t) | Current::Suboptimal(t) => t,
            Current::Timeout | Current::Occluded => return Ok(()),
            Current::Outdated | Current::Lost => {
                self.surface.configure(&self.ctx.device, &self.config);
                self.window.request_redraw();
                return Ok(());
            }
            Current::Validation => {
                self.ctx.check()?;
                bail!("the window's surface could not be acquired");
            }
        };
        let view = frame.texture.create_view(&Default::default());
        let (device, queue) = (&self.ctx.device, &self.ctx.queue);
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("display"),
        });
        let background = wgpu::Color {
            r: 0.02,
            g: 0.02,
            b: 0.02,
            a: 1.0,
        };
        let inputs = self.renderer.display_inputs();
        if let Some(inputs) = &inputs {
            let options = DisplayOptions {
                viewport: clip_to(viewport, self.config.width, self.config.height),
                exposure: self.state.settings.exposure,
                vpl_dots: self.state.show_vpls.then_some(2.0 * ppp),
                background,
            };
            self.display
                .draw(device, queue, &mut encoder, &view, inputs, &options);
        }
        let primitives = self.egui_ctx.tessellate(shapes, ppp);
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [self.config.width, self.config.height],
            pixels_per_point: ppp,
        };
        let extra =
            self.egui_renderer
                .update_buffers(device, queue, &mut encoder, &primitives, &screen);
        {
            let mut pass = encoder
                .begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("panel"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: &view,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: if inputs.is_some() {
                                wgpu::LoadOp::Load
                            } else {
                                wgpu::LoadOp::Clear(background)
                            },
                            store: wgpu::StoreOp::Store,
                        },
                    })],
                    depth_stencil_attachment: None,
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                })
                .forget_lifetime();
            self.egui_renderer.render(&mut pass, &primitives, &screen);
        }
        queue.submit(extra.into_iter().chain([encoder.finish()]));
        self.window.pre_present_notify();
        queue.present(frame);
        for id in &frees {
            self.egui_renderer.free_texture(id);
        }
        Ok(())
    }

    /// The frame as PNG (at the panel's exposure) and its linear radiance as EXR beside it.
    fn save(&self, png: &Path) -> Result<String> {
        let image: Image = self.renderer.read_image(&self.ctx)?;
        let exr = png.with_extension("exr");
        // Both files or neither.
        let mut files =
            igi_core::image::OutputFiles::reserve([png, exr.as_path()]).context("screenshot")?;
        files
            .write(png, |file| {
                image.write_png_to(file, self.state.settings.exposure)
            })
            .context("screenshot")?;
        files
            .write(&exr, |file| image.write_exr_to(file))
            .context("screenshot")?;
        files.commit().context("screenshot")?;
        Ok(format!(
            "wrote {} and {} ({} frames accumulated)",
            png.display(),
            exr.display(),
            self.accumulated
        ))
    }
}

/// The largest rectangle of the image's aspect centred in `area` (x, y, w, h).
pub fn letterbox(area: [f32; 4], width: u32, height: u32) -> [f32; 4] {
    let scale = (area[2] / width as f32).min(area[3] / height as f32);
    let (w, h) = (
        (width as f32 * scale).floor().max(1.0),
        (height as f32 * scale).floor().max(1.0),
    );
    [
        (area[0] + (area[2] - w) * 0.5).floor(),
        (area[1] + (area[3] - h) * 0.5).floor(),
        w,
        h,
    ]
}

/// `viewport` cut to a target of `width` x `height` (a viewport must lie inside it).
fn clip_to(viewport: [f32; 4], width: u32, height: u32) -> [f32; 4] {
    let (tw, th) = (width as f32, height as f32);
    let x = viewport[0].clamp(0.0, tw);
    let y = viewport[1].clamp(0.0, th);
    [
        x,
        y,
        viewport[2].min(tw - x).max(0.0),
        viewport[3].min(th - y).max(0.0),
    ]
}

/// `STEM-N.EXT` in the working directory for the first N not taken.
fn next_free(stem: &str, ext: &str) -> PathBuf {
    (1..)
        .map(|n| PathBuf::from(format!("{stem}-{n}.{ext}")))
        .find(|p| !p.exists())
        .expect("some number is free")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn window_errors_name_the_display_not_winits_source() {
        let e = "os error at /root/.cargo/registry/src/x/winit-0.30.13/src/platform_impl/linux/mod.rs:788: Failed to open connection to X server";
        assert_eq!(winit_reason(&e), "Failed to open connection to X server");
        assert_eq!(winit_reason(&"not supported"), "not supported");
        let x = no_display_message("Failed", None, Some(":99".into()));
        assert!(
            x.contains("cannot connect to display ':99' (Failed)"),
            "{x}"
        );
        assert!(!x.contains("set DISPLAY"), "{x}");
        let w = no_display_message("No compositor", Some("wayland-9".into()), Some(":0".into()));
        assert!(w.contains("Wayland display 'wayland-9'"), "{w}");
        let none = no_display_message("neither is set", None, None);
        assert!(none.contains("set DISPLAY or WAYLAND_DISPLAY"), "{none}");
    }

    #[test]
    fn letterbox_keeps_the_aspect_and_centres() {
        let v = letterbox([100.0, 0.0, 800.0, 600.0], 400, 400);
        assert_eq!(v, [200.0, 0.0, 600.0, 600.0]);
        let v = letterbox([0.0, 0.0, 800.0, 600.0], 1600, 600);
        assert_eq!(v, [0.0, 150.0, 800.0, 300.0]);
    }

    #[test]
    fn viewports_stay_inside_the_target() {
        assert_eq!(
            clip_to([300.0, 10.0, 900.0, 700.0], 1000, 600),
            [300.0, 10.0, 700.0, 590.0]
        );
        assert_eq!(clip_to([1200.0, 0.0, 10.0, 10.0], 1000, 600)[2], 0.0);
    }
}
