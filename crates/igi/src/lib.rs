//! The igi command's library part: what `igi bench` measures and how it is reported.

pub mod bench;
pub mod view;

use igi_core::bvh::{Bvh, BvhBuilder};

/// "BVH built in 61.2 ms", naming the builder and the references where it is not the
/// default one; for the commands' first lines.
pub fn bvh_built(bvh: &Bvh, builder: BvhBuilder, ms: f64) -> String {
    match builder {
        BvhBuilder::Binned => format!("BVH built in {ms:.1} ms"),
        b => format!(
            "{} BVH of {} references built in {ms:.1} ms",
            b.name(),
            bvh.build_stats.references
        ),
    }
}
