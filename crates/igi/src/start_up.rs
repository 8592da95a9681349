//! What the process settles before a command runs, on Unix: the actions of SIGPIPE and
//! SIGXFSZ, and the
//! environment of the commands that open no window. Both run first in `main`, before any
//! other thread exists.

/// Signals whose default action would kill igi mid-write, ignored so that the write fails
/// with an error instead and the run ends with one error line and no output (see
/// igi_core::image::OutputFiles): SIGPIPE (Rust's runtime ignores it already; a closed
/// pipe on stdout or stderr is an error that igi's printing drops, see print.rs) and
/// SIGXFSZ (a file-size limit, `ulimit -f`: the write fails with "File too large").
#[cfg(unix)]
pub fn errors_not_signals() {
    // SAFETY: called first in main, before any thread exists; SIG_IGN is a valid action.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_IGN);
        libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
    }
}

/// Mesa's Vulkan drivers (lavapipe among them) connect to a Wayland display when an
/// instance is made, for window surfaces; where `XDG_RUNTIME_DIR` is not set
/// (containers, CI runners, many ssh sessions), libwayland then prints "error:
/// XDG_RUNTIME_DIR is invalid or not set in the environment." once per instance, lines
/// that read like igi failing and that break the one error line of a real failure. For
/// the commands that open no window, a `WAYLAND_DISPLAY` that is an absolute path to no
/// socket makes that connection fail without a word (libwayland needs no runtime
/// directory for an absolute path). Where a Wayland session is set up, nothing changes.
#[cfg(unix)]
pub fn no_wayland_for_headless_commands() {
    let set = |name: &str| std::env::var_os(name).is_some_and(|v| !v.is_empty());
    let runtime_dir =
        std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| std::path::Path::new(&d).is_absolute());
    if !runtime_dir && !set("WAYLAND_DISPLAY") && !set("WAYLAND_SOCKET") {
        // Called in main before any other thread exists (see main), so no thread can
        // read the environment while it changes.
        std::env::set_var("WAYLAND_DISPLAY", "/nonexistent/igi-opens-no-window");
    }
}
