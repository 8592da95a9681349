//! The `igi` command as a user meets it: bad input gives one clear error line naming the
//! file (and line where known) and a non-zero exit, never a panic; good input renders.

mod common;

use common::{assert_one_error_line, igi, temp_dir};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const CAMERA: &str = "[camera]\neye = [0.0, 1.0, 3.0]\ntarget = [0.0, 1.0, 0.0]\nup = [0.0, 1.0, 0.0]\nfov_y_deg = 40.0\n[film]\nwidth = 16\nheight = 16\n";
const LIGHT: &str = "[[point_light]]\nposition = [0.0, 1.5, 0.0]\nintensity = [1.0, 1.0, 1.0]\n";
const QUAD: &str = "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nf 1 2 3 4\n";

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn scene_with_obj(dir: &Path, obj: &str) -> PathBuf {
    write(dir, "mesh.obj", obj);
    write(
        dir,
        "scene.toml",
        &format!("{CAMERA}[[mesh]]\npath = \"mesh.obj\"\ndefault_material = \"grey\"\n{LIGHT}[materials.grey]\ndiffuse = [0.5, 0.5, 0.5]\n"),
    )
}

#[test]
fn missing_scene_file() {
    let out = igi(&["render", "/no/such/scene.toml", "-o", "/tmp/x.png"]);
    assert_one_error_line(&out, &["/no/such/scene.toml"]);
}

#[test]
fn toml_syntax_error_names_file_and_line() {
    let d = temp_dir("syntax");
    let p = write(
        &d,
        "broken.toml",
        &format!("{CAMERA}[[mesh]\npath = \"m.obj\"\n"),
    );
    let out = igi(&[
        "render",
        p.to_str().unwrap(),
        "-o",
        d.join("x.png").to_str().unwrap(),
    ]);
    assert_one_error_line(&out, &["broken.toml", "9"]);
}

#[test]
fn missing_obj_is_named() {
    let d = temp_dir("missing-obj");
    let p = write(
        &d,
        "scene.toml",
        &format!("{CAMERA}[[mesh]]\npath = \"nowhere.obj\"\n{LIGHT}"),
    );
    let out = igi(&[
        "render",
        p.to_str().unwrap(),
        "-o",
        d.join("x.png").to_str().unwrap(),
    ]);
    assert_one_error_line(&out, &["nowhere.obj"]);
}

#[test]
fn obj_index_out_of_range_names_file_and_line() {
    let d = temp_dir("index");
    let p = scene_with_obj(&d, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 9\n");
    let out = igi(&[
        "render",
        p.to_str().unwrap(),
        "-o",
        d.join("x.png").to_str().unwrap(),
    ]);
    assert_one_error_line(&out, &["mesh.obj", "5"]);
    assert!(!d.join("x.png").exists(), "no output after an error");
}

#[test]
fn output_in_missing_directory() {
    let d = temp_dir("outdir");
    let p = scene_with_obj(&d, QUAD);
    let out = igi(&[
        "render",
        p.to_str().unwrap(),
        "-o",
        d.join("no/such/dir/x.png").to_str().unwrap(),
    ]);
    assert_one_error_line(&out, &["no/such/dir"]);
}

#[test]
fn mirror_depth_past_the_bound_is_one_error() {
    // u32::MAX, "no limit" to a user, wrapped the VPL pass's path length to 7 segments.
    let d = temp_dir("mirror-depth");
    let png = d.join("x.png");
    for depth in ["1025", "4294967295"] {
        let out = igi(&[
            "render",
            "--builtin",
            "cornell-box",
            "--mirror-depth",
            depth,
            "-o",
            png.to_str().unwrap(),
        ]);
        assert_one_error_line(&out, &["--mirror-depth", "at most 1024", depth]);
        assert!(!png.exists(), "an output after an error");
    }
}

#[test]
fn negative_numbers_reach_the_checks() {
    // clap took the "-1" after --exposure for a flag ("unexpected argument '-1' found"),
    // and a valid --normal-threshold of -0.5 could only be given as "=-0.5".
    let d = temp_dir("negative-numbers");
    let png = d.join("x.png");
    let out = igi(&[
        "render",
        "--builtin",
        "cornell-box",
        "-o",
        png.to_str().unwrap(),
        "--normal-threshold",
        "-0.5",
        "--exposure",
        "-1",
    ]);
    assert_one_error_line(&out, &["--exposure must be a positive number, got -1"]);
    // An integer option names itself and the value, with no tip about "-- -5".
    let out = igi(&["render", "--builtin", "cornell-box", "--vpls", "-5"]);
    assert_one_error_line(&out, &["'-5'", "--vpls"]);
    assert!(!String::from_utf8_lossy(&out.stderr).contains("-- -5"));
}

#[test]
fn option_errors_come_before_the_scene_is_read() {
    // Loading a large scene takes seconds: a mistyped option or output name is reported
    // first, not after the load (these named the missing scene, or waited for it).
    let d = temp_dir("errors-before-load");
    let scene = d.join("no-such-scene.toml");
    let scene = scene.to_str().unwrap();
    let exr = d.join("x.exr");
    let exr = exr.to_str().unwrap();
    let bin = d.join("no-such-folder").join("rays.bin");
    let bin = bin.to_str().unwrap();
    for (args, words) in [
        (vec!["render", scene, "-o", exr], vec!["-o", "not .exr"]),
        (
            vec!["render", scene, "--exr", exr, "--vpls", "0"],
            vec!["--vpls must be at least 1"],
        ),
        (
            vec!["render", scene, "--exr", exr, "--mirror-depth", "5000"],
            vec!["--mirror-depth must be at most"],
        ),
        (
            vec!["view", scene, "--bounces", "0"],
            vec!["--bounces must be at least 1"],
        ),
        (
            vec!["bench", "rays", scene, "--kind", "shadow", "--save", bin],
            vec!["--save", "no-such-folder"],
        ),
    ] {
        let out = igi(&args);
        assert_one_error_line(&out, &words);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!stderr.contains("no-such-scene"), "{args:?}: {stderr}");
    }
}

#[test]
fn render_reports_the_scene_before_the_adapter() {
    // The GPU's set-up runs on a thread of its own while the scene loads: a scene that
    // cannot be read is still the error reported (it was first before), and a bad
    // adapter with a good scene is one error line, with no output written.
    let d = temp_dir("gpu-beside-load");
    let png = d.join("x.png");
    let png = png.to_str().unwrap();
    let missing = d.join("no-such-scene.toml");
    let out = igi(&[
        "render",
        missing.to_str().unwrap(),
        "--adapter",
        "no-such-adapter",
        "-o",
        png,
    ]);
    assert_one_error_line(&out, &["no-such-scene.toml"]);
    let out = igi(&[
        "render",
        "--builtin",
        "cornell-box",
        "--adapter",
        "no-such-adapter",
        "-o",
        png,
    ]);
    assert_one_error_line(&out, &["no adapter matches 'no-such-adapter'"]);
    assert!(!d.join("x.png").exists());
}

#[test]
fn missing_files_other_than_scenes_are_named_in_words() {
    let d = temp_dir("missing-inputs");
    let nowhere = d.join("nowhere.exr");
    let nowhere = nowhere.to_str().unwrap();
    for args in [
        vec!["compare", nowhere, nowhere],
        vec!["bench", "rays", "builtin:cornell-box", "--load", nowhere],
    ] {
        let out = igi(&args);
        assert_one_error_line(&out, &[nowhere, "No such file or directory"]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!stderr.contains("os error"), "{args:?}: {stderr}");
    }
}

#[test]
fn unknown_builtin() {
    let out = igi(&["render", "--builtin", "teapot", "-o", "/tmp/x.png"]);
    assert_one_error_line(&out, &["teapot", "cornell-box"]);
}

#[test]
fn renders_builtin_cornell_box_to_png_and_exr() {
    let d = temp_dir("builtin");
    let png = d.join("box.png");
    let exr = d.join("box.exr");
    let out = igi(&[
        "render",
        "--builtin",
        "cornell-box",
        "--width",
        "64",
        "--height",
        "64",
        "--vpls",
        "30",
        "--timings",
        "-o",
        png.to_str().unwrap(),
        "--exr",
        exr.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    if stderr.contains("no GPU adapter") {
        eprintln!("skipped: {stderr}");
        return;
    }
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("VPLs from"), "{stderr}");
    let image = igi_core::image::Image::read_exr(&exr).unwrap();
    assert_eq!((image.width, image.height), (64, 64));
    let mean = image.mean();
    assert!(
        mean.iter().all(|&m| m > 0.01 && m.is_finite()),
        "mean {mean:?}"
    );
    assert!(std::fs::metadata(&png).unwrap().len() > 100);
    // igi compare: the image against itself, and against a copy with one pixel changed.
    let same = igi(&["compare", exr.to_str().unwrap(), exr.to_str().unwrap()]);
    let stdout = String::from_utf8_lossy(&same.stdout);
    assert!(stdout.contains("relMSE 0.00000\n"), "{stdout}");
    assert!(
        stdout.contains("pixels differing: none of 4096"),
        "{stdout}"
    );
    let mut changed = image.clone();
    changed.data[64 * 10 + 3][1] += 0.5;
    let other = exr.with_file_name("changed.exr");
    changed.write_exr(&other).unwrap();
    let out = igi(&["compare", other.to_str().unwrap(), exr.to_str().unwrap()]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("pixels differing: 1 of 4096; largest difference 5.000e-1 at (3, 10)"),
        "{stdout}"
    );
}

#[test]
fn info_lists_adapters() {
    let out = igi(&["info"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    if out.status.success() {
        assert!(stdout.contains("igi would use adapter"), "{stdout}");
    } else {
        assert!(stderr.contains("mesa-vulkan-drivers"), "{stderr}");
    }
}

#[test]
fn no_adapter_says_what_to_install() {
    // Point the Vulkan loader at no driver and allow only Vulkan: no adapter at all.
    let out = Command::new(env!("CARGO_BIN_EXE_igi"))
        .args([
            "render",
            "--builtin",
            "cornell-box",
            "-o",
            "/tmp/igi-no-adapter.png",
        ])
        .env("XDG_RUNTIME_DIR", "/tmp")
        .env("WGPU_BACKEND", "vulkan")
        .env("VK_DRIVER_FILES", "/nonexistent/icd.json")
        .env("VK_ICD_FILENAMES", "/nonexistent/icd.json")
        .output()
        .unwrap();
    assert_one_error_line(&out, &["mesa-vulkan-drivers"]);
}

#[test]
fn no_runtime_dir_prints_no_error_lines() {
    // Containers and CI runners often have no XDG_RUNTIME_DIR; Mesa's Vulkan drivers then
    // made libwayland print "error: XDG_RUNTIME_DIR is invalid ..." twice on a render
    // that succeeded. A render that works prints no line that starts with "error".
    let d = temp_dir("no-runtime-dir");
    let png = d.join("cb.png");
    let out = Command::new(env!("CARGO_BIN_EXE_igi"))
        .args(["render", "--builtin", "cornell-box"])
        .args(["--width", "16", "--height", "16", "-o"])
        .arg(&png)
        .env_remove("XDG_RUNTIME_DIR")
        .env_remove("WAYLAND_DISPLAY")
        .env_remove("WAYLAND_SOCKET")
        .output()
        .unwrap();
    if skipped_for_no_adapter(&out) {
        return;
    }
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let errors: Vec<&str> = stderr.lines().filter(|l| l.starts_with("error")).collect();
    assert!(
        errors.is_empty(),
        "error lines from a render that worked: {errors:?}"
    );
    assert!(png.exists());
}

fn skipped_for_no_adapter(out: &Output) -> bool {
    let stderr = String::from_utf8_lossy(&out.stderr);
    if stderr.contains("no GPU adapter") {
        eprintln!("skipped: {stderr}");
        return true;
    }
    false
}

#[test]
fn bench_runs_tiny_and_its_json_parses() {
    let d = temp_dir("bench");
    // Three scenes: each renderer gets the passes of the one before; the third has the
    // first one's name, and is reported (and its files written) under a name of its own.
    let quad_dir = temp_dir("bench-quad");
    let quad = scene_with_obj(&quad_dir, QUAD);
    let out = igi(&[
        "bench",
        "builtin:cornell-box",
        quad.to_str().unwrap(),
        "builtin:cornell-box",
        "--width",
        "32",
        "--height",
        "32",
        "--vpls",
        "30",
        "--setups",
        "iv+ds+il",
        "--frames",
        "1",
        "--warmup",
        "0",
        "--quiet",
        "--out",
        d.to_str().unwrap(),
    ]);
    if skipped_for_no_adapter(&out) {
        return;
    }
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(d.join("results.json")).unwrap();
    // Every field present: the typed parse fails on a missing one.
    let results: igi::bench::model::BenchResults = serde_json::from_str(&text).unwrap();
    assert_eq!(results.runs.len(), 3);
    let again = &results.runs[2];
    assert_eq!(
        (again.scene.as_str(), again.image_exr.as_str()),
        ("cornell-box-2", "cornell-box-2-iv_ds_il-30.exr")
    );
    assert!(d.join(&again.image_exr).exists());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("named cornell-box-2"), "{stderr}");
    let quad_run = &results.runs[1];
    assert_eq!(quad_run.scene_path, quad.to_str().unwrap());
    assert_eq!(quad_run.triangles, 2);
    assert!(quad_run.frame.median_ms > 0.0 && d.join(&quad_run.image_exr).exists());
    let run = &results.runs[0];
    assert_eq!(
        (run.width, run.height, run.setup.as_str()),
        (32, 32, "iv+ds+il")
    );
    assert!(run.frame.median_ms > 0.0 && run.fps > 0.0);
    let names: Vec<&str> = run.stages.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "vpl shooting + direct",
            "indirect",
            "discontinuity",
            "upsample + compose"
        ]
    );
    assert_eq!(run.rays.primary, 32 * 32);
    assert!(run.rays.vpl_shadow > 0 && run.rays.particle > 0);
    assert!(d.join("results.csv").exists() && d.join("results.md").exists());
    assert!(d.join(&run.image_exr).exists());
}

/// `--save` is checked before the rays are made (a frame set of 2^28 rays takes
/// minutes on a software adapter): a missing directory, a directory or the scene's own
/// file is one error at once, whatever adapter there is.
#[test]
fn bench_rays_checks_its_save_file_first() {
    let d = temp_dir("rays-save");
    let scene = scene_with_obj(&d, QUAD);
    let scene_text = std::fs::read_to_string(&scene).unwrap();
    let missing = d.join("no/such/dir/rays.bin");
    for (save, words) in [
        (
            missing.to_str().unwrap(),
            vec!["--save", "no/such/dir", "does not exist"],
        ),
        (
            d.to_str().unwrap(),
            vec!["--save", "cannot write", "a directory, not a regular file"],
        ),
        (
            scene.to_str().unwrap(),
            vec!["--save", "the scene was read from"],
        ),
    ] {
        let out = igi(&[
            "bench",
            "rays",
            scene.to_str().unwrap(),
            "--kind",
            "shadow",
            "--adapter",
            "no-such-adapter",
            "--save",
            save,
        ]);
        assert_one_error_line(&out, &words);
    }
    assert_eq!(std::fs::read_to_string(&scene).unwrap(), scene_text);
}

#[test]
fn bench_rays_saves_and_loads_the_same_rays() {
    let d = temp_dir("rays");
    let file = d.join("rays.bin");
    let first = igi(&[
        "bench",
        "rays",
        "builtin:cornell-box",
        "--count",
        "4096",
        "--kind",
        "shadow",
        "--runs",
        "1",
        "--save",
        file.to_str().unwrap(),
    ]);
    if skipped_for_no_adapter(&first) {
        return;
    }
    assert!(
        first.status.success(),
        "{}",
        String::from_utf8_lossy(&first.stderr)
    );
    assert_eq!(std::fs::metadata(&file).unwrap().len(), 4096 * 32);
    // The saved rays traced again, with the given BVH builder.
    let load = |bvh: &str| {
        igi(&[
            "bench",
            "rays",
            "builtin:cornell-box",
            "--kind",
            "shadow",
            "--runs",
            "1",
            "--bvh",
            bvh,
            "--load",
            file.to_str().unwrap(),
        ])
    };
    let second = load("binned");
    assert!(second.status.success());
    // The same rays give the same occluded fraction.
    let fraction = |o: &Output| {
        let s = String::from_utf8_lossy(&o.stdout).to_string();
        s.split(", ").nth(1).unwrap_or_default().to_string()
    };
    assert_eq!(fraction(&first), fraction(&second));
    // The split BVH (early split clipping) gives every any-hit answer the same.
    let split = load("split");
    assert!(split.status.success());
    assert!(String::from_utf8_lossy(&split.stderr).contains("split BVH of"));
    let hash = |o: &Output| {
        let s = String::from_utf8_lossy(&o.stdout).to_string();
        let at = s.find("answers hash").expect("an answers hash");
        s[at..at + 29].to_string()
    };
    assert_eq!(hash(&second), hash(&split));
    // Both any-hit schedules answer alike; a random set picks the refill one by itself
    // where the adapter runs it (a GPU with subgroup operations).
    let schedule = |name: &str| {
        let mut args = vec!["bench", "rays", "builtin:cornell-box", "--kind", "shadow"];
        args.extend([
            "--runs",
            "1",
            "--schedule",
            name,
            "--load",
            file.to_str().unwrap(),
        ]);
        igi(&args)
    };
    let per_thread = schedule("per-thread");
    assert!(per_thread.status.success());
    assert!(String::from_utf8_lossy(&per_thread.stdout).contains("by one ray per thread"));
    assert_eq!(hash(&per_thread), hash(&split));
    let refill = schedule("refill");
    if refill.status.success() {
        assert!(String::from_utf8_lossy(&refill.stdout).contains("by refilled subgroups"));
        assert_eq!(hash(&refill), hash(&split));
        assert!(String::from_utf8_lossy(&split.stdout).contains("by refilled subgroups"));
    } else {
        assert_one_error_line(&refill, &["--schedule refill", "--schedule per-thread"]);
    }
    let closest = igi(&[
        "bench",
        "rays",
        "builtin:cornell-box",
        "--kind",
        "closest",
        "--schedule",
        "refill",
    ]);
    assert_one_error_line(&closest, &["--schedule refill", "--kind shadow"]);
    // A file that is not a ray file is one clear error.
    std::fs::write(&file, b"not rays").unwrap();
    let bad = igi(&[
        "bench",
        "rays",
        "builtin:cornell-box",
        "--kind",
        "shadow",
        "--load",
        file.to_str().unwrap(),
    ]);
    assert_one_error_line(&bad, &["rays.bin", "multiple of 32"]);
}

#[test]
fn image_sizes_of_zero_or_beyond_the_adapter_are_clear_errors() {
    let zero = igi(&[
        "render",
        "--builtin",
        "cornell-box",
        "--width",
        "0",
        "-o",
        "/tmp/igi-zero.png",
    ]);
    if skipped_for_no_adapter(&zero) {
        return;
    }
    assert_one_error_line(&zero, &["0x512"]);
    let huge = igi(&[
        "render",
        "--builtin",
        "cornell-box",
        "--width",
        "200000",
        "--height",
        "200000",
        "-o",
        "/tmp/igi-huge.png",
    ]);
    assert_one_error_line(&huge, &["200000x200000", "max_storage_buffer_binding_size"]);
    assert!(!std::path::Path::new("/tmp/igi-huge.png").exists());
}

#[test]
fn an_image_side_past_the_dispatch_limit_is_refused_before_the_gpu() {
    // Taller than 65,535 workgroups of 4 rows: the GPU's dispatch would fail, with an
    // internal error, after the scene is loaded.
    for (w, h) in [("300000", "2"), ("2", "262141")] {
        let out = igi(&[
            "render",
            "--builtin",
            "cornell-box",
            "--width",
            w,
            "--height",
            h,
            "-o",
            "/tmp/igi-tall.png",
        ]);
        assert_one_error_line(&out, &[&format!("{w}x{h}"), "at most 262140"]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            !stderr.contains("adapter:"),
            "the GPU was set up first: {stderr}"
        );
    }
}

#[test]
fn output_where_no_file_can_be_created() {
    // /proc takes no new files, even for root (who bypasses permission bits): the case of
    // an output directory without write permission.
    let out = igi(&[
        "render",
        "--builtin",
        "cornell-box",
        "--width",
        "16",
        "--height",
        "16",
        "-o",
        "/proc/igi-test.png",
    ]);
    if skipped_for_no_adapter(&out) {
        return;
    }
    assert_one_error_line(&out, &["/proc/igi-test.png"]);
}

#[test]
fn a_device_or_pipe_as_mesh_is_refused_not_read_forever() {
    let d = temp_dir("device");
    let p = write(
        &d,
        "scene.toml",
        &format!("{CAMERA}[[mesh]]\npath = \"/dev/zero\"\n{LIGHT}"),
    );
    let out = igi(&[
        "render",
        p.to_str().unwrap(),
        "-o",
        d.join("x.png").to_str().unwrap(),
    ]);
    assert_one_error_line(&out, &["/dev/zero", "not a regular file"]);
}

/// Peak virtual size (VmPeak) of a run of `igi args`, in bytes, sampled from /proc while
/// it runs (a high-water mark, so the last sample holds nearly all of it).
fn peak_address_space(args: &[&str]) -> Option<u64> {
    let mut child = Command::new(env!("CARGO_BIN_EXE_igi"))
        .args(args)
        .env("XDG_RUNTIME_DIR", "/tmp")
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .expect("run igi");
    let status = format!("/proc/{}/status", child.id());
    let mut peak = 0;
    loop {
        if let Ok(text) = std::fs::read_to_string(&status) {
            let kib = text
                .lines()
                .find_map(|l| l.strip_prefix("VmPeak:"))
                .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok());
            peak = peak.max(kib.unwrap_or(0) * 1024);
        }
        if let Some(exit) = child.try_wait().expect("wait for igi") {
            return (exit.success() && peak > 0).then_some(peak);
        }
        std::thread::sleep(std::time::Duration::from_millis(1));
    }
}

#[test]
fn out_of_memory_in_a_frame_is_one_clear_error() {
    // A software adapter's "GPU memory" is the process's own: limiting the address space
    // of an `igi` run (prlimit --as) makes its large frame buffers fail to allocate for
    // real, in the driver, as they would on a GPU whose memory is full. Nothing large is
    // ever touched: the allocations that fail reserve no memory, and the ones that
    // succeed are freed before the frame runs.
    let skip = |why: &str| eprintln!("skipped: {why}");
    if !Path::new("/proc/self/status").exists() {
        return skip("no /proc to measure the address space of a run");
    }
    if Command::new("prlimit").arg("--version").output().is_err() {
        return skip("prlimit (util-linux) is not installed");
    }
    let ctx = match igi_gpu::GpuContext::new(&igi_gpu::AdapterChoice::Best) {
        Ok(ctx) => ctx,
        Err(e) => return skip(&format!("no GPU adapter ({e})")),
    };
    if format!("{:?}", ctx.info.device_type) != "Cpu" {
        return skip(&format!(
            "{} is not a software adapter: an address-space limit does not bound its memory",
            ctx.describe()
        ));
    }
    // Frame buffers of at most 128 MiB each (and within one storage binding, else the
    // size check refuses the image before any allocation).
    let per_buffer = ctx.max_storage_binding().min(128 << 20);
    let side = ((per_buffer / 16) as f64).sqrt() as u64;
    let frame = 13 * side * side * 16;
    // Room above a small run's peak for what a frame needs besides its image buffers,
    // and well short of those.
    let margin = (512 << 20).min(frame / 3);
    drop(ctx);
    let d = temp_dir("oom");
    let base = d.join("base.png");
    let Some(baseline) = peak_address_space(&[
        "render",
        "--builtin",
        "cornell-box",
        "--width",
        "16",
        "--height",
        "16",
        "--vpls",
        "10",
        "-o",
        base.to_str().unwrap(),
    ]) else {
        return skip("a small render failed or its address space could not be read");
    };
    let limit = baseline + margin;
    let (png, exr) = (d.join("oom.png"), d.join("oom.exr"));
    let side = side.to_string();
    let out = Command::new("prlimit")
        .arg(format!("--as={limit}"))
        .arg("--")
        .arg(env!("CARGO_BIN_EXE_igi"))
        .args([
            "render",
            "--builtin",
            "cornell-box",
            "--width",
            &side,
            "--height",
            &side,
            "--vpls",
            "10",
            "-o",
            png.to_str().unwrap(),
            "--exr",
            exr.to_str().unwrap(),
        ])
        .env("XDG_RUNTIME_DIR", "/tmp")
        .output()
        .expect("run prlimit");
    let stderr = String::from_utf8_lossy(&out.stderr);
    eprintln!(
        "address space limited to {} MiB (a small run peaks at {} MiB), {side}x{side} image ({} MiB of frame buffers):\n{stderr}",
        limit >> 20,
        baseline >> 20,
        frame.div_ceil(1 << 20)
    );
    // An exit through a signal (the driver crashing, an aborted allocation) has no code.
    assert_eq!(out.status.code(), Some(1), "{:?}: {stderr}", out.status);
    // The first large allocation, the frame buffers, is the one that fails.
    assert_one_error_line(&out, &["out of memory", "frame buffers", "MiB"]);
    let left: Vec<String> = std::fs::read_dir(&d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| name != "base.png")
        .collect();
    assert!(left.is_empty(), "left behind: {left:?}");
}

#[test]
fn closed_stdout_is_no_panic() {
    // `igi info | head -0`: the reader is gone before igi writes. A Unix tool stops
    // quietly there (SIGPIPE); Rust's print! would panic with "failed printing to stdout".
    let mut child = common::igi_command()
        .arg("info")
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("run igi");
    drop(child.stdout.take());
    let out = child.wait_with_output().expect("wait for igi");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "panic: {stderr}");
    assert_ne!(
        out.status.code(),
        Some(101),
        "exit code of a panic; stderr: {stderr}"
    );
}

/// The error line of `igi args` holds `text` exactly once (no "'foo' in 'foo'").
fn said_once(out: &Output, text: &str) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(stderr.matches(text).count(), 1, "{stderr}");
}

#[test]
fn setup_names_are_checked_naming_the_option_and_the_valid_names() {
    let d = temp_dir("setups");
    let png = d.join("x.png");
    let out = igi(&[
        "render",
        "--builtin",
        "cornell-box",
        "--setup",
        "foo",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert_one_error_line(&out, &["--setup", "unknown set-up 'foo'", "iv, ds, il"]);
    said_once(&out, "foo");
    let bench = |setups: &str| {
        let out_dir = d.join("bench-out");
        igi(&[
            "bench",
            "builtin:cornell-box",
            "--setups",
            setups,
            "--out",
            out_dir.to_str().unwrap(),
        ])
    };
    let out = bench("canonical,foo");
    assert_one_error_line(&out, &["--setups", "unknown set-up 'foo'", "canonical"]);
    said_once(&out, "foo");
    // A trailing comma leaves an empty name: said as such, not as "unknown part ''".
    let out = bench("canonical,");
    assert_one_error_line(&out, &["--setups", "an empty set-up name", "iv, ds, il"]);
    let out = bench("iv+");
    assert_one_error_line(&out, &["--setups", "an empty part in set-up 'iv+'"]);
    let out = bench("iv+foo");
    assert_one_error_line(&out, &["unknown part 'foo' in set-up 'iv+foo'"]);
    assert!(
        !d.join("bench-out").exists(),
        "nothing written on bad set-ups"
    );
}

#[test]
fn interleave_limits_state_the_real_rule() {
    let run = |il: &str| {
        igi(&[
            "render",
            "--builtin",
            "cornell-box",
            "--interleave",
            il,
            "-o",
            "/tmp/igi-il.png",
        ])
    };
    // Both sides under 64 but 72 subsets: the rule is on the product.
    assert_one_error_line(
        &run("9x8"),
        &[
            "--interleave",
            "9x8 is 72 subsets",
            "N x M must be at most 64",
        ],
    );
    assert_one_error_line(
        &run("99999999999x3"),
        &["--interleave", "99999999999 is too large"],
    );
    // 65536 x 65536 wraps to 0 in 32 bits: refused, not taken for 1 subset.
    assert_one_error_line(&run("65536x65536"), &["4294967296 subsets"]);
    assert_one_error_line(&run("0x3"), &["each side must be at least 1"]);
    assert_one_error_line(&run("3by3"), &["is not NxM"]);
}

#[test]
fn zero_counts_are_refused_not_taken_for_one() {
    let d = temp_dir("zero-counts");
    let png = d.join("x.png");
    let out = igi(&[
        "render",
        "--builtin",
        "cornell-box",
        "--accumulate",
        "0",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert_one_error_line(&out, &["--accumulate must be at least 1"]);
    let rays = |extra: &[&str]| {
        let mut args = vec!["bench", "rays", "builtin:cornell-box", "--count", "64"];
        args.extend(extra);
        igi(&args)
    };
    assert_one_error_line(&rays(&["--runs", "0"]), &["--runs must be at least 1"]);
    // render refuses --vpls 0; so does the frame set of bench rays.
    let out = rays(&["--set", "frame", "--kind", "shadow", "--vpls", "0"]);
    assert_one_error_line(&out, &["--vpls must be at least 1"]);
    assert!(!png.exists());
}

#[test]
fn loaded_rays_refuse_the_options_that_generate_rays() {
    let d = temp_dir("load-conflicts");
    let file = d.join("rays.bin");
    std::fs::write(&file, [0u8; 32]).unwrap();
    for extra in [
        ["--count", "16777216"],
        ["--set", "random"],
        ["--width", "8"],
        ["--height", "8"],
        ["--vpls", "30"],
        ["--seed", "1"],
    ] {
        let mut args = vec![
            "bench",
            "rays",
            "builtin:cornell-box",
            "--load",
            file.to_str().unwrap(),
        ];
        args.extend(extra);
        let out = igi(&args);
        assert_one_error_line(&out, &["--load", extra[0]]);
    }
}

#[test]
fn pattern_and_filter_need_the_acceleration_they_modify() {
    let d = temp_dir("idle-modifiers");
    let png = d.join("x.png");
    let render = |extra: &[&str]| {
        let mut args = vec![
            "render",
            "--builtin",
            "cornell-box",
            "-o",
            png.to_str().unwrap(),
        ];
        args.extend(extra);
        igi(&args)
    };
    let out = render(&["--pattern", "irregular"]);
    assert_one_error_line(&out, &["--pattern irregular", "--interleave"]);
    let out = render(&["--setup", "iv+ds", "--pattern", "irregular"]);
    assert_one_error_line(&out, &["--pattern irregular", "--interleave"]);
    let out = render(&["--filter", "fused"]);
    assert_one_error_line(&out, &["--filter fused", "--downsample", "--interleave"]);
    // Switched off again by an option: the modifier is left with nothing to modify.
    let out = render(&["--setup", "il+fused", "--interleave", "1x1"]);
    assert_one_error_line(&out, &["--filter fused (from --setup il+fused)"]);
    // A set-up name is checked whole.
    let out = render(&["--setup", "iv+irregular"]);
    assert_one_error_line(
        &out,
        &["--setup", "set-up 'iv+irregular'", "irregular modifies il"],
    );
    let out = igi(&[
        "bench",
        "builtin:cornell-box",
        "--setups",
        "fused",
        "--out",
        d.join("b").to_str().unwrap(),
    ]);
    assert_one_error_line(&out, &["--setups", "fused modifies ds or il"]);
    assert!(!png.exists());
}

#[test]
fn compare_says_when_a_file_is_not_openexr() {
    let d = temp_dir("not-exr");
    let empty = d.join("empty.exr");
    std::fs::write(&empty, b"").unwrap();
    let png = d.join("picture.exr");
    std::fs::write(&png, b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR").unwrap();
    for (file, why) in [(&empty, "the file is empty"), (&png, "it is a PNG image")] {
        let f = file.to_str().unwrap();
        let out = igi(&["compare", f, f]);
        assert_one_error_line(&out, &[&format!("'{f}' is not an OpenEXR file ({why})")]);
    }
}

#[test]
fn adapters_with_too_few_storage_buffers_are_marked_and_refused() {
    let info = igi(&["info"]);
    let stdout = String::from_utf8_lossy(&info.stdout).to_string();
    // "  1: NAME (Gl, ...)" followed by "     unusable: it allows ...".
    let lines: Vec<&str> = stdout.lines().collect();
    let unusable: Vec<String> = lines
        .windows(2)
        .filter(|w| w[1].trim_start().starts_with("unusable:"))
        .filter_map(|w| {
            let index = w[0].trim_start_matches(['*', ' ']).split(':').next()?;
            Some(index.to_string())
        })
        .collect();
    if unusable.is_empty() {
        eprintln!("skipped: every adapter here has enough storage buffers ({stdout})");
        return;
    }
    let d = temp_dir("unusable-adapter");
    let png = d.join("x.png");
    for index in &unusable {
        let out = igi(&[
            "render",
            "--builtin",
            "cornell-box",
            "--width",
            "16",
            "--height",
            "16",
            "--adapter",
            index,
            "-o",
            png.to_str().unwrap(),
        ]);
        assert_one_error_line(
            &out,
            &["storage buffers per shader stage", "igi needs", "igi info"],
        );
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!stderr.contains("Validation Error"), "{stderr}");
    }
    // igi never picks one of them by itself.
    assert!(!stdout.contains(&format!("use adapter {} ", unusable[0])));
}

// ---------------------------------------------------------------------------------------
// Inputs that could block, outputs that could destroy, and what a failed or interrupted
// run leaves behind.

/// `igi args`, failing the test if it has not ended after `secs` (a run that blocks on a
/// FIFO would otherwise hang the test suite).
fn igi_in_time(args: &[&str], secs: u64) -> Output {
    let mut child = common::igi_command()
        .args(args)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("run igi");
    let start = std::time::Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed().as_secs() > secs {
            let _ = child.kill();
            let _ = child.wait();
            panic!("igi {args:?} still running after {secs} s");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

fn mkfifo(path: &Path) {
    let status = Command::new("mkfifo").arg(path).status().expect("mkfifo");
    assert!(status.success(), "mkfifo {}", path.display());
}

fn is_fifo(path: &Path) -> bool {
    use std::os::unix::fs::FileTypeExt;
    std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_fifo())
}

/// The names in `dir` (none of them a temporary `.partial` file).
fn names_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .collect();
    names.sort();
    names
}

const TINY: [&str; 8] = [
    "--builtin",
    "cornell-box",
    "--width",
    "16",
    "--height",
    "16",
    "--vpls",
    "1",
];

fn render_tiny(extra: &[&str]) -> Output {
    let mut args = vec!["render"];
    args.extend(TINY);
    args.extend(extra);
    igi_in_time(&args, 120)
}

#[test]
fn a_huge_ray_count_is_one_error_before_allocating() {
    let out = igi_in_time(
        &[
            "bench",
            "rays",
            "builtin:cornell-box",
            "--runs",
            "1",
            "--count",
            "4294967295",
        ],
        60,
    );
    assert_one_error_line(&out, &["--count 4294967295", "at most 268435456 rays"]);
}

#[test]
fn a_pipe_or_device_as_image_or_ray_file_is_refused_not_read_forever() {
    let d = temp_dir("fifo-inputs");
    let fifo = d.join("fifo.exr");
    mkfifo(&fifo);
    let other = d.join("other.exr");
    let out = igi_in_time(
        &["compare", fifo.to_str().unwrap(), other.to_str().unwrap()],
        60,
    );
    assert_one_error_line(&out, &["fifo.exr", "not a regular file"]);
    // bench's --reference reads the same way, before the GPU is asked for.
    let bench_out = d.join("bench-out");
    let out = igi_in_time(
        &[
            "bench",
            "builtin:cornell-box",
            "--reference",
            fifo.to_str().unwrap(),
            "--out",
            bench_out.to_str().unwrap(),
        ],
        60,
    );
    assert_one_error_line(&out, &["fifo.exr", "not a regular file"]);
    for load in [fifo.to_str().unwrap(), "/dev/zero"] {
        let out = igi_in_time(
            &[
                "bench",
                "rays",
                "builtin:cornell-box",
                "--runs",
                "1",
                "--kind",
                "shadow",
                "--load",
                load,
            ],
            120,
        );
        if skipped_for_no_adapter(&out) {
            return;
        }
        assert_one_error_line(&out, &[load, "not a regular file"]);
    }
}

#[test]
fn an_output_symlink_writes_its_target_and_stays_a_link() {
    let d = temp_dir("out-link");
    let target = write(&d, "target.png", "not yet an image");
    let link = d.join("link.png");
    std::os::unix::fs::symlink("target.png", &link).unwrap();
    let out = render_tiny(&["-o", link.to_str().unwrap()]);
    if skipped_for_no_adapter(&out) {
        return;
    }
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let meta = std::fs::symlink_metadata(&link).unwrap();
    assert!(meta.file_type().is_symlink(), "the link was replaced");
    assert!(std::fs::read(&target).unwrap().starts_with(b"\x89PNG"));
    assert_eq!(names_in(&d), ["link.png", "target.png"]);
}

#[test]
fn an_output_that_is_a_pipe_or_directory_is_refused_and_kept() {
    let d = temp_dir("out-fifo");
    let fifo = d.join("fifo.png");
    mkfifo(&fifo);
    let out = render_tiny(&["-o", fifo.to_str().unwrap()]);
    assert_one_error_line(&out, &["fifo.png", "not a regular file"]);
    assert!(is_fifo(&fifo), "the FIFO was replaced");
    std::fs::create_dir(d.join("dir.exr")).unwrap();
    let out = render_tiny(&["--exr", d.join("dir.exr").to_str().unwrap()]);
    assert_one_error_line(&out, &["dir.exr", "not a regular file"]);
    assert!(d.join("dir.exr").is_dir());
    assert_eq!(names_in(&d), ["dir.exr", "fifo.png"]);
}

#[test]
fn an_output_naming_an_input_or_another_output_is_refused() {
    let d = temp_dir("out-input");
    let scene = scene_with_obj(&d, QUAD);
    let before = std::fs::read(&scene).unwrap();
    let mesh = d.join("mesh.obj");
    // The scene file and the mesh it names, also by another spelling of the path.
    let other_spelling = d.join(".").join("mesh.obj");
    for (option, path) in [
        ("-o", scene.as_path()),
        ("--exr", mesh.as_path()),
        ("-o", other_spelling.as_path()),
    ] {
        let out = igi_in_time(
            &[
                "render",
                scene.to_str().unwrap(),
                option,
                path.to_str().unwrap(),
            ],
            60,
        );
        assert_one_error_line(&out, &[option, "read from"]);
    }
    assert_eq!(std::fs::read(&scene).unwrap(), before);
    assert_eq!(std::fs::read(&mesh).unwrap(), QUAD.as_bytes());
    // No extension, which neither option would refuse alone.
    let same = d.join("same");
    let out = render_tiny(&[
        "-o",
        same.to_str().unwrap(),
        "--exr",
        same.to_str().unwrap(),
    ]);
    assert_one_error_line(&out, &["-o", "--exr", "same file"]);
    assert!(!same.exists());
}

#[test]
fn an_output_named_for_the_other_format_is_refused() {
    let d = temp_dir("out-format");
    let exr = d.join("out.exr");
    let out = render_tiny(&["-o", exr.to_str().unwrap()]);
    assert_one_error_line(&out, &["-o", "out.exr", "writes an sRGB PNG", "--exr"]);
    let png = d.join("x.PNG");
    let out = render_tiny(&["--exr", png.to_str().unwrap()]);
    assert_one_error_line(&out, &["--exr", "x.PNG", "writes OpenEXR", "-o"]);
    // The viewer's screenshot is the PNG; its EXR goes beside it.
    let shot = d.join("shot.exr");
    let out = igi_in_time(
        &[
            "view",
            "--builtin",
            "cornell-box",
            "--frames",
            "1",
            "--screenshot",
            shot.to_str().unwrap(),
        ],
        60,
    );
    assert_one_error_line(&out, &["--screenshot", "shot.exr", "PNG"]);
    assert!(names_in(&d).is_empty());
}

#[test]
fn a_bad_output_fails_the_run_before_any_output_is_written() {
    let d = temp_dir("out-first");
    let good = d.join("good.exr");
    let missing = d.join("missing-dir/x.png");
    let out = render_tiny(&[
        "-o",
        missing.to_str().unwrap(),
        "--exr",
        good.to_str().unwrap(),
    ]);
    assert_one_error_line(&out, &["-o", "missing-dir", "does not exist"]);
    assert!(names_in(&d).is_empty(), "left {:?}", names_in(&d));
}

#[test]
fn an_interrupted_render_leaves_no_temporary_file() {
    use std::time::{Duration, Instant};
    let d = temp_dir("interrupt");
    let (exr, png) = (d.join("o.exr"), d.join("o.png"));
    // A large image takes long enough to write that a signal can arrive meanwhile; each
    // try watches for the temporary file and signals as soon as it appears. A render that
    // ends first is tried again; none caught in all tries fails the test.
    for signal in [libc::SIGINT, libc::SIGTERM] {
        let mut caught = false;
        for _ in 0..5 {
            let mut child = common::igi_command()
                .args(["render", "--builtin", "cornell-box", "--vpls", "1"])
                .args(["--width", "2048", "--height", "2048"])
                .args(["--exr", exr.to_str().unwrap(), "-o", png.to_str().unwrap()])
                .stdout(std::process::Stdio::null())
                .stderr(std::process::Stdio::piped())
                .spawn()
                .unwrap();
            let start = Instant::now();
            let mut seen = false;
            while child.try_wait().unwrap().is_none() {
                assert!(start.elapsed() < Duration::from_secs(300), "render hung");
                if names_in(&d).iter().any(|n| n.ends_with(".partial")) {
                    seen = true;
                    // SAFETY: kill(2) on our own child's id, which it keeps until waited for.
                    assert_eq!(unsafe { libc::kill(child.id() as i32, signal) }, 0);
                    break;
                }
                std::thread::sleep(Duration::from_millis(1));
            }
            let out = child.wait_with_output().unwrap();
            if skipped_for_no_adapter(&out) {
                return;
            }
            let left = names_in(&d);
            assert!(
                !left.iter().any(|n| n.ends_with(".partial")),
                "left {left:?} after signal {signal}"
            );
            if seen {
                assert_eq!(
                    out.status.code(),
                    Some(128 + signal),
                    "{}",
                    String::from_utf8_lossy(&out.stderr)
                );
                caught = true;
                break;
            }
            assert!(
                out.status.success(),
                "{}",
                String::from_utf8_lossy(&out.stderr)
            );
            eprintln!("the render ended before a temporary file was seen; trying again");
        }
        assert!(
            caught,
            "no try was interrupted while writing (signal {signal})"
        );
    }
}

#[test]
fn bench_makes_its_folder_only_after_its_inputs_and_outputs_are_checked() {
    let d = temp_dir("bench-out-late");
    let out_dir = d.join("out");
    let not_exr = write(&d, "ref.exr", "not an EXR");
    for bad in [
        vec!["builtin:nope"],
        vec!["builtin:cornell-box", "--width", "0"],
        vec![
            "builtin:cornell-box",
            "--reference",
            not_exr.to_str().unwrap(),
        ],
    ] {
        let mut args = vec!["bench", "--quiet", "--frames", "1", "--warmup", "0"];
        args.extend(["--vpls", "1", "--setups", "canonical"]);
        args.extend(["--out", out_dir.to_str().unwrap()]);
        args.extend(bad);
        let out = igi_in_time(&args, 120);
        if skipped_for_no_adapter(&out) {
            return;
        }
        assert!(!out.status.success());
        assert!(!out_dir.exists(), "{args:?} left {}", out_dir.display());
    }
    // A report's name taken by a directory fails the run before any image is written.
    std::fs::create_dir_all(out_dir.join("results.md")).unwrap();
    let out = igi_in_time(
        &[
            "bench",
            "builtin:cornell-box",
            "--quiet",
            "--frames",
            "1",
            "--warmup",
            "0",
            "--vpls",
            "1",
            "--setups",
            "canonical",
            "--width",
            "16",
            "--height",
            "16",
            "--out",
            out_dir.to_str().unwrap(),
        ],
        120,
    );
    assert_one_error_line(&out, &["results.md", "not a regular file"]);
    assert_eq!(names_in(&out_dir), ["results.md"]);
}

#[test]
fn output_paths_that_name_directories_say_so() {
    let d = temp_dir("output-dirs");
    let file = write(&d, "file", "");
    let render = |out: &str| {
        igi(&[
            "render",
            "--builtin",
            "cornell-box",
            "--width",
            "16",
            "--height",
            "16",
            "-o",
            out,
        ])
    };
    let dir = d.to_str().unwrap();
    // Not the OS's "Not a directory" for an existing directory given with its '/'.
    let out = render(&format!("{dir}/"));
    assert_one_error_line(&out, &["names a directory", "give a file name"]);
    let out = render(dir);
    assert_one_error_line(&out, &["a directory, not a regular file"]);
    let out = render(&format!("{}/x.png", file.display()));
    assert_one_error_line(
        &out,
        &[&format!(
            "'{}' exists and is not a directory",
            file.display()
        )],
    );
    let out = igi(&[
        "bench",
        "builtin:cornell-box",
        "--out",
        file.to_str().unwrap(),
    ]);
    assert_one_error_line(
        &out,
        &[&format!(
            "--out '{}' exists and is not a directory",
            file.display()
        )],
    );
    // /proc takes no new files: not "No such file or directory" of a directory that is
    // there (the file is never created).
    let out = render("/proc/igi-test-takes-no-files.png");
    if skipped_for_no_adapter(&out) {
        return;
    }
    assert_one_error_line(&out, &["directory '/proc' takes no new files"]);
}

#[test]
fn bench_build_times_every_scene_and_needs_no_adapter() {
    // No GPU is touched: the build runs on the CPU, so this runs wherever the tests do.
    let d = temp_dir("bench-build");
    let scene = scene_with_obj(&d, QUAD);
    let scene = scene.to_str().unwrap();
    let out = igi(&[
        "bench",
        "build",
        "builtin:cornell-box",
        scene,
        "--runs",
        "3",
        "--bvh",
        "binned",
    ]);
    assert!(out.status.success(), "{out:?}");
    let text = String::from_utf8_lossy(&out.stdout);
    // One report per scene, in order, with the figures the build bench reads.
    let reports: Vec<&str> = text.split("builder: binned").collect();
    assert_eq!(reports.len(), 3, "two reports in\n{text}");
    assert!(
        reports[0].starts_with("builtin:cornell-box: 30 triangles"),
        "{text}"
    );
    assert!(
        reports[1].contains("build: median") && reports[1].contains(" of 3 "),
        "{text}"
    );
    assert!(
        reports[1].contains(&format!("{scene}: 2 triangles")),
        "{text}"
    );
    assert!(reports[2].contains("references 2, nodes 1 ("), "{text}");
}

#[test]
fn bench_build_refuses_bad_input_before_measuring() {
    let d = temp_dir("bench-build-bad");
    // The second scene is missing: nothing is measured, one error names it.
    let missing = d.join("missing.toml");
    let out = igi(&[
        "bench",
        "build",
        "builtin:cornell-box",
        missing.to_str().unwrap(),
    ]);
    assert_one_error_line(&out, &["missing.toml"]);
    common::assert_no_repeated_clause(&String::from_utf8_lossy(&out.stderr));
    assert!(out.stdout.is_empty(), "measured before the error: {out:?}");
    let out = igi(&["bench", "build", "builtin:cornell-box", "--runs", "0"]);
    assert_one_error_line(&out, &["--runs"]);
    let out = igi(&["bench", "build", "builtin:teapot"]);
    assert_one_error_line(&out, &["teapot", "cornell-box"]);
}
