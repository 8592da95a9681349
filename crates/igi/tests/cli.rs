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
    let out = igi(&[
        "bench",
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
    assert_eq!(results.runs.len(), 1);
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
