//! `igi view` in a real window, without a person: under Xvfb (an X server drawing into
//! memory) on whatever adapter there is, `--frames N --screenshot` renders N frames in the
//! window and saves the last. A still view accumulates the frames of
//! `igi render --accumulate N`, so the screenshot must be that very image. Where Xvfb is
//! missing the window tests skip with a printed reason (`.ci/run` installs it).

mod common;

use common::{assert_one_error_line, igi, igi_command, temp_dir};
use igi_core::image::{rel_mse, Image};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// `igi ARGS` inside a fresh Xvfb display, or `None` (printed) when there is no xvfb-run.
/// One at a time: `xvfb-run -a` picks a free display number racily.
fn igi_in_xvfb(args: &[&str]) -> Option<Output> {
    static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _turn = ONE_AT_A_TIME.lock().unwrap_or_else(|p| p.into_inner());
    let found = Command::new("xvfb-run").arg("--help").output().is_ok();
    if !found {
        eprintln!("skipped: xvfb-run is not installed (apt-get install xvfb xauth)");
        return None;
    }
    let mut c = Command::new("xvfb-run");
    c.args([
        "-a",
        "-s",
        "-screen 0 1024x768x24",
        env!("CARGO_BIN_EXE_igi"),
    ])
    .args(args)
    .env(
        "XDG_RUNTIME_DIR",
        std::env::var("XDG_RUNTIME_DIR").unwrap_or("/tmp".into()),
    );
    Some(c.output().expect("run xvfb-run"))
}

fn succeeded(out: &Output, what: &str) {
    assert!(
        out.status.success(),
        "{what} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The decoded RGB bytes of a PNG.
fn png_pixels(path: &Path) -> (u32, u32, Vec<u8>) {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    buf.truncate(info.buffer_size());
    (info.width, info.height, buf)
}

/// The screenshot of `igi view --frames 3` is the offline render of the same view with
/// three accumulated frames, pixel for pixel; and it is the scene, not a blank image.
#[test]
fn screenshot_after_n_frames_is_the_offline_frame() {
    let dir = temp_dir("frames");
    let shot = dir.join("view.png");
    let frame = [
        "--builtin",
        "cornell-box",
        "--width",
        "64",
        "--height",
        "48",
        "--vpls",
        "32",
    ];
    let mut args = vec!["view"];
    args.extend(frame);
    args.extend(["--frames", "3", "--window", "480x320", "--vpl-dots"]);
    args.extend(["--screenshot", shot.to_str().unwrap()]);
    let Some(out) = igi_in_xvfb(&args) else {
        return;
    };
    succeeded(&out, "igi view");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("3 frames accumulated"), "{stderr}");

    let render_png = dir.join("render.png");
    let render_exr = dir.join("render.exr");
    let mut args = vec!["render"];
    args.extend(frame);
    args.extend(["--accumulate", "3", "-o", render_png.to_str().unwrap()]);
    args.extend(["--exr", render_exr.to_str().unwrap()]);
    succeeded(&igi(&args), "igi render");

    let view = Image::read_exr(&shot.with_extension("exr")).unwrap();
    let offline = Image::read_exr(&render_exr).unwrap();
    assert_eq!((view.width, view.height), (64, 48));
    assert_eq!(rel_mse(&view, &offline).unwrap(), 0.0);
    let (w, h, pixels) = png_pixels(&shot);
    assert_eq!((w, h), (64, 48));
    assert_eq!(pixels, png_pixels(&render_png).2);
    // The Cornell box: red left wall, green right wall, many distinct values.
    let at = |x: u32, y: u32| &pixels[3 * (y * w + x) as usize..3 * (y * w + x) as usize + 3];
    let row = |xs: std::ops::Range<u32>| xs.map(|x| at(x, h / 2)).collect::<Vec<_>>();
    let red = row(0..w / 3)
        .iter()
        .any(|p| p[0] > p[1].saturating_add(60) && p[0] > p[2].saturating_add(60));
    let green = row(2 * w / 3..w)
        .iter()
        .any(|p| p[1] > p[0].saturating_add(40) && p[1] > p[2].saturating_add(40));
    assert!(
        red && green,
        "no red wall on the left or green wall on the right"
    );
    let mut distinct = pixels.chunks(3).map(|p| p.to_vec()).collect::<Vec<_>>();
    distinct.sort();
    distinct.dedup();
    assert!(
        distinct.len() > 200,
        "only {} distinct colours",
        distinct.len()
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

const QUAD: &str =
    "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nf 1 2 3 4\nv -1 0 -1\nv 1 0 -1\nv 0 1 -1\nf 5 6 7\n";

fn scene_file(dir: &Path, name: &str, camera: &str) -> PathBuf {
    std::fs::write(dir.join("mesh.obj"), QUAD).unwrap();
    let p = dir.join(name);
    std::fs::write(
        &p,
        format!("{camera}[film]\nwidth = 40\nheight = 30\n[[mesh]]\npath = \"mesh.obj\"\ndefault_material = \"grey\"\n[[point_light]]\nposition = [0.3, 1.5, 0.2]\nintensity = [2.0, 2.0, 2.0]\n[materials.grey]\ndiffuse = [0.6, 0.5, 0.4]\n"),
    )
    .unwrap();
    p
}

/// `--camera` replaces the scene's camera: the screenshot equals the offline render of a
/// scene file holding that camera.
#[test]
fn camera_option_is_the_scene_files_camera() {
    let dir = temp_dir("camera");
    let a = "[camera]\neye = [0.0, 1.0, 3.0]\ntarget = [0.0, 0.5, 0.0]\nfov_y_deg = 40.0\n";
    let b = "eye = [1.5, 2.0, 2.0]\ntarget = [0.0, 0.2, -0.5]\nup = [0.0, 1.0, 0.0]\nfov_y_deg = 55.0\n";
    let scene_a = scene_file(&dir, "a.toml", a);
    let scene_b = scene_file(&dir, "b.toml", &format!("[camera]\n{b}"));
    let shot = dir.join("view.png");
    let args = [
        "view",
        scene_a.to_str().unwrap(),
        "--camera",
        b,
        "--width",
        "40",
        "--height",
        "30",
        "--vpls",
        "16",
        "--frames",
        "2",
        "--screenshot",
        shot.to_str().unwrap(),
    ];
    let Some(out) = igi_in_xvfb(&args) else {
        return;
    };
    succeeded(&out, "igi view");
    let exr = dir.join("b.exr");
    let render = [
        "render",
        scene_b.to_str().unwrap(),
        "--vpls",
        "16",
        "--accumulate",
        "2",
        "--exr",
        exr.to_str().unwrap(),
    ];
    succeeded(&igi(&render), "igi render");
    let view = Image::read_exr(&shot.with_extension("exr")).unwrap();
    assert_eq!(
        rel_mse(&view, &Image::read_exr(&exr).unwrap()).unwrap(),
        0.0
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn no_display_is_one_clear_error() {
    let out = igi_command()
        .args(["view", "--builtin", "cornell-box", "--frames", "1"])
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .env_remove("WAYLAND_SOCKET")
        .output()
        .unwrap();
    assert_one_error_line(&out, &["cannot open a window", "no display", "xvfb-run"]);
    // No place in winit's source: the line is for the user.
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !stderr.contains(".rs:") && !stderr.contains("os error"),
        "{stderr}"
    );
    // A display that is named but not there is said by name, not as unset (a number
    // no `xvfb-run -a` of these tests takes: they count up from 99).
    let out = igi_command()
        .args(["view", "--builtin", "cornell-box", "--frames", "1"])
        .env("DISPLAY", ":7351")
        .env_remove("WAYLAND_DISPLAY")
        .env_remove("WAYLAND_SOCKET")
        .output()
        .unwrap();
    assert_one_error_line(&out, &["cannot connect to display ':7351'"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !stderr.contains(".rs:") && !stderr.contains("set DISPLAY"),
        "{stderr}"
    );
}

#[test]
fn bad_camera_and_options_are_one_clear_error() {
    let out = igi(&[
        "view",
        "--builtin",
        "cornell-box",
        "--camera",
        "eye = [0, 1, 0]\ntarget = [0, 1, 0]\nfov_y_deg = 40",
    ]);
    assert_one_error_line(&out, &["--camera", "view direction is undefined"]);
    let out = igi(&[
        "view",
        "--builtin",
        "cornell-box",
        "--camera",
        "/no/such/camera.toml",
    ]);
    assert_one_error_line(&out, &["/no/such/camera.toml"]);
    // Text without '=' is a file name; when there is no such file the line names the
    // option, the text, and both forms the option takes.
    let out = igi(&["view", "--builtin", "cornell-box", "--camera", "garbage["]);
    assert_one_error_line(
        &out,
        &["--camera 'garbage['", "no such file", "[camera] table"],
    );
    let out = igi(&["view", "--builtin", "cornell-box", "--frames", "0"]);
    assert_one_error_line(&out, &["--frames"]);
    let out = igi(&[
        "view",
        "--builtin",
        "cornell-box",
        "--screenshot",
        "/no/such/dir/s.png",
    ]);
    assert_one_error_line(&out, &["/no/such/dir"]);
}

/// Without --width/--height the image is the window less the panel, at 1/--scale.
#[test]
fn image_follows_the_window() {
    let dir = temp_dir("follow");
    let shot = dir.join("view.png");
    let args = [
        "view",
        "--builtin",
        "cornell-box",
        "--vpls",
        "8",
        "--window",
        "480x200",
        "--scale",
        "2",
        "--frames",
        "1",
        "--screenshot",
        shot.to_str().unwrap(),
    ];
    let Some(out) = igi_in_xvfb(&args) else {
        return;
    };
    succeeded(&out, "igi view");
    let panel = igi::view::PANEL_WIDTH as u32;
    let (w, h, _) = png_pixels(&shot);
    assert_eq!((w, h), ((480 - panel) / 2, 100));
    std::fs::remove_dir_all(&dir).unwrap();
}
