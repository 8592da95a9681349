//! Checks of a command's output files, made before anything is rendered: a run that
//! cannot write every output writes none, and no output replaces an input or another
//! output, or gets the other format's bytes under its name.

use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};

/// What an output option writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Png,
    Exr,
    /// A ray file (`bench rays --save`): any name.
    Rays,
}

/// One output file and the option that named it.
pub struct Output<'a> {
    /// The option as the user typed it, e.g. "-o" or "--exr".
    pub option: &'static str,
    pub path: &'a Path,
    pub format: Format,
    /// Where the other format goes, for the error of a name with its extension, e.g.
    /// "write EXR with --exr".
    pub other: &'static str,
}

/// Errors where an output could not be written ([`igi_core::image::output_target`]: a
/// missing directory, an entry that is not a regular file), where its extension names the
/// other format, where two outputs are one file, or where an output is one of `inputs`
/// (the files a scene was read from).
pub fn check(outputs: &[Output], inputs: &[PathBuf]) -> Result<()> {
    let inputs: Vec<PathBuf> = inputs
        .iter()
        .filter_map(|p| p.canonicalize().ok())
        .collect();
    let mut targets: Vec<(PathBuf, &Output)> = vec![];
    for out in outputs {
        // The extension of the other image format, and what this option writes.
        let other_format = match out.format {
            Format::Png => Some(("exr", "an sRGB PNG")),
            Format::Exr => Some(("png", "OpenEXR")),
            Format::Rays => None,
        };
        let ext = out.path.extension().map(|e| e.to_string_lossy());
        if let Some((named, writes)) =
            other_format.filter(|(named, _)| ext.is_some_and(|e| e.eq_ignore_ascii_case(named)))
        {
            bail!(
                "{} {}: {} writes {writes}, not .{named} ({})",
                out.option,
                out.path.display(),
                out.option,
                out.other
            );
        }
        let target = igi_core::image::output_target(out.path).context(out.option)?;
        if inputs.contains(&target) {
            bail!(
                "{} {}: that is a file the scene was read from; give another output name",
                out.option,
                out.path.display()
            );
        }
        if let Some((_, first)) = targets.iter().find(|(t, _)| t == &target) {
            bail!(
                "{} {} and {} {} name the same file; give each its own",
                first.option,
                first.path.display(),
                out.option,
                out.path.display()
            );
        }
        targets.push((target, out));
    }
    Ok(())
}

/// The in-flight temporary files of [`igi_core::image::write_atomically`] are removed
/// when SIGINT, SIGTERM or SIGHUP arrives, and the process exits as a shell reports a
/// death by that signal (128 + its number: 130 for Ctrl-C), so an interrupted run leaves
/// neither a half-written file nor a temporary one. The handler runs on a thread of its
/// own (signal-hook's iterator), where it may lock the list of temporary files, which a
/// signal handler proper could not.
#[cfg(unix)]
pub fn remove_partial_files_on_signals() -> Result<()> {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    let mut signals = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP])?;
    std::thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            if let Some(signal) = signals.forever().next() {
                igi_core::image::remove_partial_files();
                std::process::exit(128 + signal);
            }
        })?;
    Ok(())
}
