//! The build's statistics: counts and areas tallied while building, the SAH cost, and
//! (for the tests) the same figures from a walk of the finished tree.

use std::time::Instant;

use crate::bvh::{BuildStats, MAX_LEAF_SIZE, SAH_INTERSECT_COST, SAH_TRAVERSAL_COST};
#[cfg(test)]
use crate::bvh::{Bvh, BvhChild};

/// Counts and areas gathered while building, for [`BuildStats`].
#[derive(Default)]
pub(super) struct Tally {
    pub(super) leaves: usize,
    pub(super) max_leaf_size: u32,
    pub(super) oversized_leaves: usize,
    /// Sum of half area x triangle count over leaves.
    pub(super) leaf_area: f64,
}

impl Tally {
    pub(super) fn leaf(&mut self, count: usize, half_area: f32) {
        self.leaves += 1;
        self.max_leaf_size = self.max_leaf_size.max(count as u32);
        self.oversized_leaves += usize::from(count > MAX_LEAF_SIZE);
        self.leaf_area += (half_area * count as f32) as f64;
    }

    pub(super) fn merge(&mut self, o: Tally) {
        self.leaves += o.leaves;
        self.max_leaf_size = self.max_leaf_size.max(o.max_leaf_size);
        self.oversized_leaves += o.oversized_leaves;
        self.leaf_area += o.leaf_area;
    }
}

pub(super) fn stats(
    triangles: usize,
    references: usize,
    nodes: usize,
    t: Tally,
    (interior_area, max_depth): (f64, u32),
    root_area: f32,
    start: Instant,
) -> BuildStats {
    let cost = if root_area > 0.0 {
        (SAH_TRAVERSAL_COST as f64 * interior_area + SAH_INTERSECT_COST as f64 * t.leaf_area)
            / root_area as f64
    } else {
        0.0
    };
    BuildStats {
        build_ms: start.elapsed().as_secs_f64() * 1e3,
        triangles,
        references,
        nodes,
        leaves: t.leaves,
        max_depth,
        max_leaf_size: t.max_leaf_size,
        oversized_leaves: t.oversized_leaves,
        sah_cost: (SAH_TRAVERSAL_COST as f64 + cost) as f32,
        phases: vec![],
    }
}

/// The same statistics by walking the finished tree (tests check both agree).
#[cfg(test)]
pub(in crate::bvh) fn stats_by_walk(bvh: &Bvh) -> BuildStats {
    let area = BvhChild::half_area;
    let (lo, hi) = bvh.bounds();
    let root_area = area(&BvhChild {
        min: lo,
        max: hi,
        index: 0,
        count: 0,
    });
    let mut t = Tally::default();
    let (mut interior_area, mut max_depth) = (0.0f64, 0u32);
    // Children come after their parent (depth-first order): one pass in index order sees
    // every node's depth before its children's.
    let mut depth = vec![0u32; bvh.nodes.len()];
    for (i, n) in bvh.nodes.iter().enumerate() {
        for c in [n.a(), n.b()] {
            if c.is_leaf() {
                if c.is_empty() {
                    continue; // the empty child
                }
                t.leaf(c.count as usize, area(&c));
                max_depth = max_depth.max(depth[i] + 1);
            } else {
                assert!(c.index as usize > i, "child {} before parent {i}", c.index);
                depth[c.index as usize] = depth[i] + 1;
                interior_area += area(&c) as f64;
            }
        }
    }
    let mut distinct = bvh.tri_order.clone();
    distinct.sort_unstable();
    distinct.dedup();
    let mut s = stats(
        distinct.len(),
        bvh.tri_order.len(),
        bvh.nodes.len(),
        t,
        (interior_area, max_depth),
        root_area,
        Instant::now(),
    );
    s.build_ms = bvh.build_stats.build_ms;
    s.phases = bvh.build_stats.phases.clone();
    s
}
