//! A run writes all of its outputs or none, says early when it cannot, and is not killed
//! by a signal it can handle (a closed pipe, a file-size limit).

mod common;

use common::{assert_one_error_line, igi_command, temp_dir};
use std::path::Path;
use std::process::{Output, Stdio};

/// The names in `dir`, sorted.
fn names(dir: &Path) -> Vec<String> {
    let mut n: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    n.sort();
    n
}

/// `igi render --builtin cornell-box` at `size` into `png` and `exr`.
fn render_args<'a>(size: &'a str, png: &'a str, exr: &'a str) -> Vec<&'a str> {
    vec![
        "render",
        "--builtin",
        "cornell-box",
        "--width",
        size,
        "--height",
        size,
        "--vpls",
        "8",
        "-o",
        png,
        "--exr",
        exr,
    ]
}

#[test]
fn a_closed_stderr_does_not_stop_the_outputs() {
    let d = temp_dir("closed-stderr");
    let (png, exr) = (d.join("a.png"), d.join("a.exr"));
    let args = render_args("32", png.to_str().unwrap(), exr.to_str().unwrap());
    let mut child = igi_command()
        .args(&args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run igi");
    // The reader of stderr is gone before igi writes its first line.
    drop(child.stderr.take());
    let status = child.wait().expect("wait for igi");
    assert_eq!(status.code(), Some(0), "{status:?}: killed by a signal?");
    assert_eq!(names(&d), ["a.exr", "a.png"]);
}

#[cfg(unix)]
#[test]
fn a_file_size_limit_is_one_error_and_leaves_nothing() {
    use std::os::unix::process::CommandExt;
    let d = temp_dir("file-size-limit");
    let (png, exr) = (d.join("a.png"), d.join("a.exr"));
    let args = render_args("96", png.to_str().unwrap(), exr.to_str().unwrap());
    let mut cmd = igi_command();
    cmd.args(&args);
    // `ulimit -f 8` (8 KiB): the EXR of 96 x 96 float pixels is larger.
    // SAFETY: setrlimit is async-signal-safe; nothing else runs between fork and exec.
    unsafe {
        cmd.pre_exec(|| {
            let limit = libc::rlimit {
                rlim_cur: 8192,
                rlim_max: 8192,
            };
            if libc::setrlimit(libc::RLIMIT_FSIZE, &limit) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
    let out = cmd.output().expect("run igi");
    assert_eq!(out.status.code(), Some(1), "{:?}", out.status);
    assert_one_error_line(&out, &["a.exr", "too large"]);
    assert!(names(&d).is_empty(), "left behind: {:?}", names(&d));
}

/// The run stopped before it loaded the scene (the loaded scene is reported first).
fn stopped_before_rendering(out: &Output) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("triangles"), "rendered first: {stderr}");
}

#[test]
fn a_folder_that_takes_no_files_fails_before_any_frame() {
    let d = temp_dir("no-files");
    let exr = d.join("a.exr");
    // /proc takes no files, even from root; 300 accumulated frames would take minutes.
    let mut args = render_args("64", "/proc/igi-test.png", exr.to_str().unwrap());
    args.extend(["--accumulate", "300"]);
    let out = igi_command().args(&args).output().expect("run igi");
    assert_one_error_line(&out, &["/proc/igi-test.png", "takes no new files"]);
    stopped_before_rendering(&out);
    assert!(names(&d).is_empty(), "left behind: {:?}", names(&d));
}

#[test]
fn the_longest_file_name_is_written() {
    let d = temp_dir("long-name");
    // 255 bytes, the most a file system takes, both names.
    let stem = "n".repeat(251);
    let (png, exr) = (d.join(format!("{stem}.png")), d.join(format!("{stem}.exr")));
    let args = render_args("16", png.to_str().unwrap(), exr.to_str().unwrap());
    let out = igi_command().args(&args).output().expect("run igi");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(names(&d), [format!("{stem}.exr"), format!("{stem}.png")]);
    // One byte more is refused at once, in words.
    let too_long = d.join(format!("{stem}x.png"));
    let args = render_args("16", too_long.to_str().unwrap(), exr.to_str().unwrap());
    let out = igi_command().args(&args).output().expect("run igi");
    assert_one_error_line(&out, &["at most 255"]);
    stopped_before_rendering(&out);
}

#[cfg(unix)]
#[test]
fn a_pipe_as_output_is_refused_at_once() {
    let d = temp_dir("stdout-pipe");
    let exr = d.join("a.exr");
    let args = render_args("16", "/dev/stdout", exr.to_str().unwrap());
    let out = igi_command()
        .args(&args)
        .stdout(Stdio::piped())
        .output()
        .expect("run igi");
    assert_one_error_line(&out, &["/dev/stdout", "not a regular file"]);
    stopped_before_rendering(&out);
    assert!(names(&d).is_empty(), "left behind: {:?}", names(&d));
}
