//! How `igi` prints an error: one line on stderr after "error: ".

/// The one line `igi` prints for an error: the error and its causes joined by ": ",
/// without the " (os error 2)" tails of OS errors (their message says it in words, as
/// the scene loader's do) and with any line breaks of a message made spaces.
pub fn error_line(e: &anyhow::Error) -> String {
    let causes: Vec<String> = e
        .chain()
        .map(|cause| igi_core::scene::without_os_error_code(&cause.to_string()).to_string())
        .collect();
    causes
        .join(": ")
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
}
