//! `igi bench`: the paper's measurements (section 5) over scenes x set-ups x VPL counts,
//! and its subcommands `igi bench rays` ([`super::bench_rays`]) and `igi bench build`.

use super::bench_rays::RaysArgs;
use crate::frame_options::BvhChoice;
use anyhow::Result;
use clap::{Args, Subcommand};
use std::path::PathBuf;

#[derive(Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct BenchCommand {
    #[command(subcommand)]
    pub sub: Option<BenchSub>,
    #[command(flatten)]
    pub args: BenchArgs,
}

#[derive(Subcommand)]
pub enum BenchSub {
    /// The ray-tracing layer alone: rays/s of the any-hit and closest-hit queries on a ray
    /// set (random segments and rays, or the VPL shadow rays of a real frame), in the ray
    /// file format of docs/BENCHMARKS.md so another tracer can trace the very same rays.
    Rays(RaysArgs),
    /// The BVH build alone, on the CPU: median wall time of several builds in this
    /// process, its phases, the tree's size and SAH cost.
    Build(BuildArgs),
}

#[derive(Args)]
pub struct BuildArgs {
    /// Scene files (TOML), or builtin:NAME.
    #[arg(required = true)]
    pub scenes: Vec<String>,
    /// Builds of each scene in this process; the median is reported. Later builds reuse
    /// memory that the first had to map: `--runs 1` in a new process is what `igi render`
    /// pays.
    #[arg(long, default_value_t = 5)]
    pub runs: u32,
    #[command(flatten)]
    pub bvh: BvhChoice,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

#[derive(Args)]
pub struct BenchArgs {
    /// Scene files (TOML), or builtin:NAME.
    #[arg(required = true)]
    pub scenes: Vec<String>,
    /// VPL counts, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "30,90,180")]
    pub vpls: Vec<u32>,
    /// Set-ups, comma-separated: canonical, or iv, ds, il, irregular, fused joined by '+'.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "canonical,iv,iv+ds,iv+ds+il"
    )]
    pub setups: Vec<String>,
    /// Timed frames per combination.
    #[arg(long, default_value_t = 10)]
    pub frames: u32,
    /// Untimed frames before them.
    #[arg(long, default_value_t = 3)]
    pub warmup: u32,
    /// Reference image (EXR) for one scene; otherwise one is looked for beside each scene
    /// (../../references/NAME-full.exr, or NAME-reference.exr).
    #[arg(long, value_name = "EXR")]
    pub reference: Option<PathBuf>,
    /// Output directory.
    #[arg(long, default_value = "bench-out")]
    pub out: PathBuf,
    /// Image width (default: each scene's film).
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height (default: each scene's film).
    #[arg(long)]
    pub height: Option<u32>,
    #[arg(long, default_value_t = 0)]
    pub seed: u32,
    #[command(flatten)]
    pub bvh: BvhChoice,
    /// Adapter: an index or part of a name from `igi info`.
    #[arg(long)]
    pub adapter: Option<String>,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

/// `igi bench`, or the subcommand it was given.
pub fn run(cmd: &BenchCommand) -> Result<()> {
    match &cmd.sub {
        Some(BenchSub::Rays(r)) => super::bench_rays::run(r),
        Some(BenchSub::Build(b)) => {
            igi::bench::build::run(&b.scenes, b.runs, b.bvh.builder.into(), b.quiet)
        }
        None => run_bench(&cmd.args),
    }
}

fn run_bench(args: &BenchArgs) -> Result<()> {
    let opts = igi::bench::run::BenchOptions {
        scenes: args.scenes.clone(),
        vpls: args.vpls.clone(),
        setups: args.setups.clone(),
        frames: args.frames,
        warmup: args.warmup,
        reference: args.reference.clone(),
        out: args.out.clone(),
        width: args.width,
        height: args.height,
        seed: args.seed,
        bvh: args.bvh.builder.into(),
        adapter: args.adapter.clone(),
        quiet: args.quiet,
        command: std::env::args().collect::<Vec<_>>().join(" "),
    };
    let results = igi::bench::run::run(&opts)?;
    for warning in igi::bench::report::write_all(&results, &args.out)? {
        igi::note!("warning: {warning}");
    }
    if !args.quiet {
        igi::say!("{}", igi::bench::report::to_markdown(&results));
    }
    igi::note!("wrote {}", args.out.join("results.json").display());
    Ok(())
}
