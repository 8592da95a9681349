//! One module per subcommand: its options (clap) and what it runs.

pub mod bench;
pub mod bench_rays;
pub mod compare;
pub mod info;
pub mod render;
pub mod view;
