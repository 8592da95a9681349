//! The igi command's library part: what `igi bench` measures and how it is reported.

pub mod bench;
pub mod gpu_set_up;
pub mod outputs;
mod print;
pub mod view;

use igi_core::bvh::{Bvh, BvhBuilder};

/// "split BVH of 323506 references built in 81.2 ms", for the commands' first lines.
pub fn bvh_built(bvh: &Bvh, builder: BvhBuilder, ms: f64) -> String {
    format!(
        "{} BVH of {} references built in {ms:.1} ms",
        builder.name(),
        bvh.build_stats.references
    )
}
