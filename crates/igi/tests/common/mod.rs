//! What the command's tests share: running `igi`, a fresh directory, and the check that a
//! failure is one clear line.
#![allow(dead_code)]

use std::path::PathBuf;
use std::process::{Command, Output};

/// The `igi` binary with a runtime directory for the Vulkan loader.
pub fn igi_command() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_igi"));
    c.env(
        "XDG_RUNTIME_DIR",
        std::env::var("XDG_RUNTIME_DIR").unwrap_or("/tmp".into()),
    );
    c
}

pub fn igi(args: &[&str]) -> Output {
    igi_command().args(args).output().expect("run igi")
}

/// A fresh, empty directory for test `name`.
pub fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("igi-test-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The run failed with exactly one line on stderr starting with "error" that contains
/// every `needle`, and nothing panicked.
pub fn assert_one_error_line(out: &Output, needles: &[&str]) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success(),
        "expected failure, got success; stderr: {stderr}"
    );
    assert!(!stderr.contains("panicked"), "panic: {stderr}");
    let lines: Vec<&str> = stderr.lines().filter(|l| l.starts_with("error")).collect();
    assert_eq!(lines.len(), 1, "one error line expected, got: {stderr}");
    for n in needles {
        assert!(lines[0].contains(n), "'{}' does not name '{n}'", lines[0]);
    }
}
