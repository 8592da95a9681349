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
    assert_no_repeated_clause(lines[0]);
}

/// An error line says each thing once: no clause (the parts between ": ") comes back
/// later in the line, as when an error prints its cause and the chain of causes prints
/// it again.
pub fn assert_no_repeated_clause(line: &str) {
    let clauses: Vec<&str> = line
        .split(": ")
        .map(|c| match c.rfind(" (os error ") {
            Some(i) if c.ends_with(')') => c[..i].trim(),
            _ => c.trim(),
        })
        .filter(|c| c.len() > 3)
        .collect();
    for (i, c) in clauses.iter().enumerate() {
        assert!(!clauses[i + 1..].contains(c), "'{c}' said twice in: {line}");
    }
}
