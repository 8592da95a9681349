//! `igi bench build`: the BVH build timed on the user's own scenes (the acceleration
//! structure that OptiX built for Marques and Santos; igi builds its own on the CPU). The
//! figures and their lines are those of the `bvh_build` example, whose rounds
//! `scripts/build-bench.sh` pairs to compare two builds of igi.

use anyhow::{bail, Result};
use igi_core::bvh::timing::time_builds;
use igi_core::bvh::BvhBuilder;
use indicatif::{ProgressBar, ProgressStyle};
use std::time::Instant;

/// Times `runs` builds of each scene in this process and prints the reports. Every scene
/// is loaded before the first build, so that a bad one stops the command before anything
/// is measured.
pub fn run(scenes: &[String], runs: u32, builder: BvhBuilder, quiet: bool) -> Result<()> {
    if runs == 0 {
        bail!("--runs must be at least 1");
    }
    let mut loaded = Vec::with_capacity(scenes.len());
    for arg in scenes {
        let t = Instant::now();
        // The loaders' errors name the file (or the built-in scene) already.
        let scene = super::run::load(arg)?;
        loaded.push((arg, scene, t.elapsed()));
    }
    for (k, (arg, scene, load_time)) in loaded.into_iter().enumerate() {
        if k > 0 {
            crate::say!();
        }
        crate::say!(
            "{arg}: {} triangles (loaded in {:.0} ms)",
            scene.triangles.len(),
            load_time.as_secs_f64() * 1e3
        );
        // Builds done, on a terminal (indicatif draws nothing elsewhere): one build of a
        // large scene can take seconds.
        let bar = if quiet {
            ProgressBar::hidden()
        } else {
            ProgressBar::new(u64::from(runs))
        };
        bar.set_style(
            ProgressStyle::with_template("{bar:30} {pos}/{len} builds, {eta} left")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        let timing = time_builds(&scene.triangles, builder, runs as usize, |k| {
            bar.set_position(k as u64)
        });
        bar.finish_and_clear();
        crate::say!("{timing}");
    }
    Ok(())
}
