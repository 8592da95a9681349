//! How the igi command prints: lines on stderr (progress, what was written) and on stdout
//! (results), written without a panic and without a signal where the reader has gone.
//! SIGPIPE is ignored (see start_up.rs), so a write to a closed pipe returns an error;
//! `crate::note!` and `crate::say!` would turn that error into a panic. Here it is dropped: a
//! reader that stops reading does not stop a run from writing all of its outputs.

/// `crate::note!` that drops a failed write (a closed pipe) instead of panicking.
#[macro_export]
macro_rules! note {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}

/// `crate::say!` that drops a failed write (a closed pipe) instead of panicking.
#[macro_export]
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($arg)*);
    }};
}
