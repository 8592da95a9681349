//! `igi`: Instant Global Illumination on the GPU (Marques and Santos), from the command line.
//! `igi render` renders a scene file or a built-in scene to PNG/EXR; `igi view` opens the
//! interactive viewer; `igi bench` measures; `igi info` lists the GPU adapters. Each
//! subcommand is a module of [`cmd`]; this file holds the top level of the command line
//! and what runs before and after a subcommand.

mod cmd;
mod error_line;
mod frame_options;
#[cfg(unix)]
mod start_up;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};
use error_line::error_line;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "igi",
    version,
    about = "Instant Global Illumination on the GPU: VPLs from point lights, gathered through shadow rays"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene to an sRGB PNG (and optionally linear OpenEXR).
    Render(cmd::render::RenderArgs),
    /// Open a window: fly through the scene, change any option and watch the GPU times;
    /// a still view converges (frames with fresh VPL sets are averaged).
    View(cmd::view::ViewArgs),
    /// List the GPU adapters wgpu sees and the one igi would pick.
    Info,
    /// Measure like the paper: GPU time per stage, fps, rays and image error for every
    /// scene x set-up x VPL count; writes results.json/.csv/.md, charts and images.
    Bench(cmd::bench::BenchCommand),
    /// Compare a linear image with a reference (OpenEXR): relative MSE and channel means.
    Compare {
        /// The image to measure.
        image: PathBuf,
        /// The reference it is measured against.
        reference: PathBuf,
    },
}

/// `cmd` and its subcommands, each option that takes a value taking a negative number as
/// one (see [`parse_command_line`]). Flags take no value, and clap refuses the setting on
/// them.
fn negative_numbers_as_values(cmd: clap::Command) -> clap::Command {
    cmd.mut_args(|a| {
        let takes_value = a.get_action().takes_values();
        a.allow_negative_numbers(takes_value)
    })
    .mut_subcommands(negative_numbers_as_values)
}

/// The command line, with a negative number taken as the value of the option before it:
/// clap's default reads `--exposure -1` as a stray flag ("unexpected argument '-1'", with
/// a tip to write `-- -1`), and a valid `--normal-threshold -0.5` needed `=`. Every
/// option of every subcommand that takes a value gets the setting here, so that igi's own checks answer
/// ("--exposure must be a positive number, got -1", or clap's "-5 is not in 0..=...").
fn parse_command_line() -> Cli {
    let mut cmd = negative_numbers_as_values(Cli::command());
    let matches = cmd.get_matches_mut();
    Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.format(&mut cmd).exit())
}

fn main() -> ExitCode {
    #[cfg(unix)]
    start_up::errors_not_signals();
    let cli = parse_command_line();
    #[cfg(unix)]
    if !matches!(cli.command, Command::View(_)) {
        start_up::no_wayland_for_headless_commands();
    }
    // The first thread besides main: the environment is settled by now.
    #[cfg(unix)]
    if let Err(e) = igi::outputs::remove_partial_files_on_signals() {
        igi::note!("error: cannot handle signals: {}", error_line(&e));
        return ExitCode::FAILURE;
    }
    env_logger::Builder::from_env(
        env_logger::Env::default()
            .default_filter_or("warn,wgpu_core=error,wgpu_hal=off,naga=error"),
    )
    .format_timestamp(None)
    .init();
    let result = match &cli.command {
        Command::Render(args) => cmd::render::run(args),
        Command::View(args) => cmd::view::run(args),
        Command::Info => cmd::info::run(),
        Command::Bench(args) => cmd::bench::run(args),
        Command::Compare { image, reference } => cmd::compare::run(image, reference),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            igi::note!("error: {}", error_line(&e));
            ExitCode::FAILURE
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_command_line_passes_clap_checks() {
        // clap checks every subcommand's arguments when it builds them; a setting that
        // does not fit an argument (as on a flag) panics only once that subcommand is
        // used.
        negative_numbers_as_values(Cli::command()).debug_assert();
    }
}
