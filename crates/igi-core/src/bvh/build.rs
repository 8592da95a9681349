//! Binned SAH builder (in the manner of Wald, "On fast construction of SAH-based bounding
//! volume hierarchies", 2007).
//!
//! A range of more than `SMALL_RANGE` (12) triangles is binned over its centroid bounds,
//! [`SAH_BINS`](super::SAH_BINS) bins per axis (half as many below `FEW_BINS_BELOW` = 256 triangles), and
//! split at the plane of lowest SAH cost among the 3 x (bins - 1); a smaller range is
//! split by an exact sweep over its centroids sorted on each axis. A range becomes a leaf
//! when it has one triangle, when it has at most [`MAX_LEAF_SIZE`] and the SAH prefers a
//! leaf, or when it reaches the depth cap [`MAX_DEPTH`]. Equal centroids (no plane tells
//! the triangles apart) are split by index: at the middle for large ranges, by the sweep
//! for small ones.
//!
//! Primitives are 32-byte boxes (`PrimRef`) partitioned in place, with their triangle
//! indices in a parallel array, so that each level is two sequential passes over memory.
//! The two subtrees of every range of at least `PARALLEL_MIN_PRIMS` triangles are built
//! as two tasks of rayon's work-stealing pool (`rayon_core::join`), each in a region of
//! the node array of its own sized by its triangle count (`Region`), so that the tree
//! does not depend on which thread built what, nor on the machine. Each node makes
//! Kensler's tree rotations as soon as its subtree is built ([`rotate_locally`]), which
//! lowers the SAH cost where the greedy splits left room, and keeps what the layout
//! needs (`NodeInfo`); then the nodes are laid out depth first again (each node's two
//! subtrees right after it, one after the other), and child a, which any-hit walks visit
//! first, becomes the one likelier to stop them per unit of work
//! ([`layout::occluder_first`]); it need not be the left one.
//! [`BuildStats::phases`](super::BuildStats::phases) times the steps.
//!
//! With [`super::BvhBuilder::Split`] the references are not whole triangles but the
//! pieces that early split clipping (`split`) cut the wasteful ones into; the build is
//! the same.
//!
//! This file holds the build's entry points, the references and the recursive,
//! work-stealing build of the node ranges; its phases live in submodules: `binning`
//! (the binned SAH split search and the partition), `sweep` (the exact sweep of small
//! ranges), `tree` (the node places, regions and rotations), `layout` (the depth-first
//! layout and the triangle rows), `parallel` (the passes on all threads outside the
//! recursion) and `stats`.

mod binning;
mod layout;
mod parallel;
mod stats;
mod sweep;
mod tree;

#[cfg(test)]
mod sweep_tests;

use std::mem::MaybeUninit;
use std::time::Instant;

use glam::{Vec3, Vec3A};

use crate::bvh::{
    Bvh, BvhChild, BvhNode, MAX_DEPTH, MAX_LEAF_SIZE, SAH_INTERSECT_COST, SAH_TRAVERSAL_COST,
};
use crate::scene::Triangle;
use binning::{find_split, partition};
use layout::{depth_first_layout, larger_first, triangle_rows};
use parallel::{par_vec2, threads};
use stats::{stats, Tally};
use sweep::SmallSweep;
use tree::{rotate_locally, NodeInfo, Region};

pub(super) use layout::places_as_rows;
pub(super) use parallel::par_chunks;
#[cfg(test)]
pub(super) use parallel::reuse_vec;
#[cfg(test)]
pub(super) use stats::stats_by_walk;
pub(super) use tree::Places;

/// Ranges smaller than this are not worth a task of their own: on the conference room
/// and the 2-core machine, 4,096 and 16,384 measured alike.
const PARALLEL_MIN_PRIMS: usize = 4 * 1024;

/// Ranges up to this size are split by an exact SAH sweep over their sorted centroids
/// instead of bins: most nodes of a tree are small, and for them the fixed cost of
/// clearing and sweeping 3 x SAH_BINS bins dominates (and the exact sweep finds better
/// splits).
const SMALL_RANGE: usize = 12;

#[derive(Clone, Copy, Debug)]
pub(super) struct Aabb {
    pub(super) lo: Vec3A,
    pub(super) hi: Vec3A,
}

impl Aabb {
    pub(super) const EMPTY: Aabb = Aabb {
        lo: Vec3A::INFINITY,
        hi: Vec3A::NEG_INFINITY,
    };

    #[inline]
    pub(super) fn grow(&mut self, o: &Aabb) {
        self.lo = self.lo.min(o.lo);
        self.hi = self.hi.max(o.hi);
    }

    #[inline]
    pub(super) fn grow_point(&mut self, p: Vec3A) {
        self.lo = self.lo.min(p);
        self.hi = self.hi.max(p);
    }

    /// Half the surface area (the SAH only needs ratios); 0 for an empty box.
    #[inline]
    pub(super) fn half_area(&self) -> f32 {
        let e = (self.hi - self.lo).max(Vec3A::ZERO);
        e.x * e.y + e.y * e.z + e.z * e.x
    }

    fn child(&self, index: u32, count: u32) -> BvhChild {
        BvhChild {
            min: self.lo.into(),
            max: self.hi.into(),
            index,
            count,
        }
    }
}

/// Bounds of one triangle. Its centroid, doubled, is `lo + hi` (the factor 2 is the same
/// for every primitive, so bins and splits do not care).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub(super) struct PrimRef {
    pub(super) lo: Vec3A,
    pub(super) hi: Vec3A,
}

impl PrimRef {
    /// The reference of box `lo`..`hi`, with any -0 bound made +0: SSE's min and max
    /// return their second operand for -0 and +0, so the bins' boxes would depend on the
    /// order of the primitives binned into them (and so on the number of threads that bin
    /// the root) only through such signs.
    #[inline]
    pub(super) fn new(lo: Vec3A, hi: Vec3A) -> PrimRef {
        PrimRef {
            lo: lo + Vec3A::ZERO,
            hi: hi + Vec3A::ZERO,
        }
    }

    #[inline]
    pub(super) fn centroid2(&self) -> Vec3A {
        self.lo + self.hi
    }
}

/// One node range to build.
struct Task<'a> {
    prims: &'a mut [PrimRef],
    ids: &'a mut [u32],
    /// BVH slot of `prims[0]`.
    first: u32,
    bounds: Aabb,
    /// Bounds of the doubled centroids.
    cbounds: Aabb,
    depth: u32,
}

/// Build-wide settings.
struct Limits {
    /// Ranges at this depth become leaves ([`MAX_DEPTH`] outside tests).
    max_depth: u32,
    /// Whether the two subtrees of large ranges are built side by side (work stealing).
    parallel: bool,
    /// Rotations each node may make on the way up ([`rotate_locally`]; 0: none).
    rotation_budget: u32,
    /// Early split clipping of the references (`split`).
    split: bool,
}

impl Limits {
    fn new(max_depth: u32, rotation_budget: u32) -> Limits {
        Limits {
            max_depth,
            parallel: threads() > 1,
            rotation_budget,
            split: false,
        }
    }
}

/// A triangle as the build reads it: its three vertices, in place (so that the rows'
/// pass can prefetch them, see [`triangle_rows`]).
pub(super) trait Vertices: Sync {
    fn vertices(&self) -> &[Vec3; 3];
}

impl Vertices for Triangle {
    #[inline]
    fn vertices(&self) -> &[Vec3; 3] {
        &self.v
    }
}

impl Vertices for [Vec3; 3] {
    #[inline]
    fn vertices(&self) -> &[Vec3; 3] {
        self
    }
}

/// Prefetches the cache lines of `value` (its first and last byte: a triangle's 36 bytes
/// of vertices may straddle two lines) into every cache level. A hint: no effect on
/// what the program computes, and none on targets other than x86-64.
#[inline(always)]
fn prefetch<T>(value: &T) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        let first = (value as *const T).cast::<i8>();
        let last = first.wrapping_add(std::mem::size_of::<T>().saturating_sub(1));
        // SAFETY: SSE is part of x86-64; a prefetch reads nothing and faults on no
        // address, and both are inside `value` anyway.
        unsafe {
            _mm_prefetch::<_MM_HINT_T0>(first);
            _mm_prefetch::<_MM_HINT_T0>(last);
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = value;
}

pub(super) fn build<T: Vertices>(triangles: &[T]) -> Bvh {
    build_impl(triangles, Limits::new(MAX_DEPTH, ROTATION_BUDGET))
}

/// With early split clipping of the references (`split`): [`super::BvhBuilder::Split`].
pub(super) fn build_split<T: Vertices>(triangles: &[T], max_depth: u32) -> Bvh {
    let limits = Limits {
        split: true,
        ..Limits::new(max_depth, ROTATION_BUDGET)
    };
    build_impl(triangles, limits)
}

/// With every subtree built on the calling thread (the tree must be the same).
#[cfg(test)]
pub(super) fn build_on_one_thread(triangles: &[[Vec3; 3]]) -> Bvh {
    let limits = Limits {
        parallel: false,
        ..Limits::new(MAX_DEPTH, ROTATION_BUDGET)
    };
    build_impl(triangles, limits)
}

/// With a lower depth cap, to test the cap without a pathological scene (a chain 60
/// levels deep needs areas growing by a factor ~n per level: beyond f32's range).
#[cfg(test)]
pub(super) fn build_with_max_depth(triangles: &[[Vec3; 3]], max_depth: u32) -> Bvh {
    assert!(
        max_depth <= MAX_DEPTH,
        "the traversal stack holds MAX_DEPTH entries"
    );
    build_impl(triangles, Limits::new(max_depth, ROTATION_BUDGET))
}

/// With another rotation budget per node (0: the tree as the splits left it).
#[cfg(test)]
pub(super) fn build_with_rotations(triangles: &[[Vec3; 3]], max_depth: u32, budget: u32) -> Bvh {
    build_impl(triangles, Limits::new(max_depth, budget))
}

fn build_impl<T: Vertices>(tri: &[T], limits: Limits) -> Bvh {
    let count = tri.len();
    let start = Instant::now();
    let mut phases = Phases::new(start);
    // The GPU indexes tri_rows with 3 * slot + 2 in u32.
    assert!(
        count <= (u32::MAX / 3) as usize,
        "too many triangles for one BVH: {count}"
    );
    if count == 0 {
        return Bvh {
            nodes: vec![BvhNode::new(BvhChild::EMPTY, BvhChild::EMPTY)],
            tri_rows: vec![],
            tri_order: vec![],
            build_stats: stats(0, 0, 1, Tally::default(), (0.0, 0), 0.0, start),
        };
    }

    // Early split clipping appends pieces: room for as many again as there are
    // triangles, which costs nothing until written, so that the references are not
    // copied to a larger vector (more pieces than that still fit, after one copy).
    // An even capacity in all, so that the layout can have the allocation (two
    // references to a node, see reuse_vec).
    let spare = if limits.split { count } else { count % 2 };
    let (mut prims, bounds, mut cbounds, tri_area) = whole_references(tri, spare);
    let mut ids: Vec<u32> = Vec::with_capacity(count + spare);
    ids.extend(0..count as u32);
    phases.lap("references");
    if limits.split {
        cbounds = super::split::split_references(&mut prims, &mut ids, &tri_area, &bounds, tri);
        phases.lap("split clipping");
    }
    // References: one per triangle, or more with early split clipping.
    let refs = prims.len();
    assert!(
        refs <= (u32::MAX / 3) as usize,
        "too many triangle references for one BVH: {refs}"
    );

    // Room for refs - 1 interior nodes, the most a tree over refs references has, left
    // unwritten (see Places).
    let places = refs.max(2) - 1;
    let mut nodes: Box<Places<BvhNode>> = Box::new_uninit_slice(places);
    let mut info: Box<Places<NodeInfo>> = Box::new_uninit_slice(places);
    if cfg!(debug_assertions) {
        // Where assertions are on (the tests), every place's info starts out written
        // with an interior count of 0, which no set node has, and each read checks it.
        info.fill(MaybeUninit::new(NodeInfo::default()));
    }
    let mut slot_area = vec![0.0f32; refs];
    phases.lap("node arrays");
    let mut tally = Tally::default();
    let root = build_node(
        Task {
            prims: &mut prims,
            ids: &mut ids,
            first: 0,
            bounds,
            cbounds,
            depth: 0,
        },
        &mut Region {
            nodes: &mut nodes,
            info: &mut info,
            base: 0,
            used: 0,
            slot_area: &mut slot_area,
            slot_base: 0,
        },
        &mut tally,
        &limits,
        &tri_area,
    );
    drop((slot_area, tri_area));
    if root.count > 0 {
        // A root that is a leaf still needs an interior node 0 to hold its box; the leaf
        // is its child, at depth 1, and stays child a.
        nodes[0].write(BvhNode::new(
            bounds.child(root.index, root.count),
            BvhChild::EMPTY,
        ));
        info[0].write(NodeInfo {
            interior: 1,
            ..NodeInfo::default()
        });
    }
    phases.lap("tree");

    // Rotations and larger_first moved subtrees around: each node's subtrees right after it
    // again, with child a the likelier occluder (occluder_first). Laid out where the
    // references were (they are done with), and the rows written where the node places
    // were: in a new process (what `igi render` pays) the build's first touch of fresh
    // memory costs a page fault per 4 KiB, and these two buffers had been half of the
    // memory it touched on the conference room.
    let (nodes_out, interior_area, deepest) = depth_first_layout(&nodes, &info, prims);
    drop(info);
    phases.lap("layout");

    // Per slot the x, y and z rows of its vertices (see Bvh::tri_rows). In a pass of its
    // own rather than at the leaves: the reads of scattered triangles overlap here, and
    // the leaves took twice as long over them.
    let tri_rows = triangle_rows(places_as_rows(nodes), tri, &mut ids);
    phases.lap("rows");
    let nodes = nodes_out;
    let mut build_stats = stats(
        count,
        refs,
        nodes.len(),
        tally,
        (interior_area, deepest),
        bounds.half_area(),
        start,
    );
    build_stats.phases = phases.done();
    Bvh {
        nodes,
        tri_rows,
        tri_order: ids,
        build_stats,
    }
}

/// Wall time of the build's phases, for [`BuildStats::phases`](super::BuildStats::phases).
struct Phases {
    last: Instant,
    done: Vec<(&'static str, f64)>,
}

impl Phases {
    fn new(start: Instant) -> Phases {
        Phases {
            last: start,
            done: vec![],
        }
    }

    /// Ends the phase `name`.
    fn lap(&mut self, name: &'static str) {
        let now = Instant::now();
        self.done
            .push((name, (now - self.last).as_secs_f64() * 1e3));
        self.last = now;
    }

    fn done(self) -> Vec<(&'static str, f64)> {
        self.done
    }
}

/// One reference per triangle, its box: (boxes, box of all, box of the doubled centroids,
/// area of each triangle), the boxes' vector with room for `spare` more. A triangle
/// with a non-finite vertex has area 0 (see [`layout::occluder_first`]).
pub(super) fn whole_references<T: Vertices>(
    tri: &[T],
    spare: usize,
) -> (Vec<PrimRef>, Aabb, Aabb, Vec<f32>) {
    let count = tri.len();
    let (prims, areas, chunk_bounds) = par_vec2(
        count,
        spare,
        |i| {
            let [a, b, c] = tri[i].vertices().map(Vec3A::from);
            let (lo, hi) = (a.min(b).min(c), a.max(b).max(c));
            // A triangle with a non-finite vertex is never hit (the triangle test fails
            // on it); a point box keeps it out of everyone's way and keeps centroids
            // comparable (no NaN), which the sort of SmallSweep relies on.
            let prim = if lo.is_finite() && hi.is_finite() {
                PrimRef::new(lo, hi)
            } else {
                PrimRef {
                    lo: Vec3A::ZERO,
                    hi: Vec3A::ZERO,
                }
            };
            let area = 0.5 * (b - a).cross(c - a).length();
            (prim, if area.is_finite() { area } else { 0.0 })
        },
        range_bounds,
    );
    let (mut bounds, mut cbounds) = (Aabb::EMPTY, Aabb::EMPTY);
    for (b, c) in chunk_bounds {
        bounds.grow(&b);
        cbounds.grow(&c);
    }
    (prims, bounds, cbounds, areas)
}

/// Rotations a node may make on the way up of the build (see [`rotate_locally`]).
const ROTATION_BUDGET: u32 = 8;

/// The box around two children's boxes.
pub(super) fn union(a: &BvhChild, b: &BvhChild) -> Aabb {
    Aabb {
        lo: Vec3A::from(a.min.min(b.min)),
        hi: Vec3A::from(a.max.max(b.max)),
    }
}

/// Box and (doubled) centroid box of a range.
fn range_bounds(prims: &[PrimRef]) -> (Aabb, Aabb) {
    let mut b = Aabb::EMPTY;
    let mut c = Aabb::EMPTY;
    for p in prims {
        b.lo = b.lo.min(p.lo);
        b.hi = b.hi.max(p.hi);
        c.grow_point(p.centroid2());
    }
    (b, c)
}

/// Builds the subtree of `task`; writes its interior nodes and their [`NodeInfo`] into
/// `tree` (this node first) and its leaves' triangle areas (from `tri_area`, per
/// triangle), and returns the
/// reference to it as a child (an interior node: count 0, index into the node array; or
/// a leaf: count > 0, index = first BVH slot). Each node makes its rotations as soon as
/// its subtree is built.
fn build_node(
    task: Task<'_>,
    tree: &mut Region,
    tally: &mut Tally,
    limits: &Limits,
    tri_area: &[f32],
) -> BvhChild {
    let n = task.prims.len();
    let area = task.bounds.half_area();
    let leaf = |tally: &mut Tally, tree: &mut Region| {
        tally.leaf(n, area);
        tree.write_leaf(task.first, task.ids, tri_area);
        task.bounds.child(task.first, n as u32)
    };
    if n == 1 || task.depth >= limits.max_depth {
        return leaf(tally, tree);
    }

    let leaf_cost = SAH_INTERSECT_COST * n as f32 * area;
    let worth_a_leaf = |split_cost: f32| {
        n <= MAX_LEAF_SIZE
            && leaf_cost <= SAH_TRAVERSAL_COST * area + SAH_INTERSECT_COST * split_cost
    };

    let (k, lb, lc, rb, rc) = if n <= SMALL_RANGE {
        let sweep = SmallSweep::new(task.prims);
        if worth_a_leaf(sweep.cost) {
            return leaf(tally, tree);
        }
        sweep.apply(task.prims, task.ids)
    } else {
        // The root's binning is the only large pass no thread shares: spread it.
        let parallel = task.depth == 0 && n >= 4 * PARALLEL_MIN_PRIMS;
        match find_split(task.prims, &task.cbounds, parallel) {
            Some(split) => {
                if worth_a_leaf(split.cost) {
                    return leaf(tally, tree);
                }
                let (k, lc, rc) = partition(task.prims, task.ids, &task.cbounds, &split);
                debug_assert!(k > 0 && k < n);
                (k, split.left, lc, split.right, rc)
            }
            None => {
                // All centroids equal: nothing tells the triangles apart.
                let k = n / 2;
                let (lb, lc) = range_bounds(&task.prims[..k]);
                let (rb, rc) = range_bounds(&task.prims[k..]);
                (k, lb, lc, rb, rc)
            }
        }
    };

    let slot = tree.push();
    let depth = task.depth + 1;
    let (lp, rp) = task.prims.split_at_mut(k);
    let (li, ri) = task.ids.split_at_mut(k);
    let left = Task {
        prims: lp,
        ids: li,
        first: task.first,
        bounds: lb,
        cbounds: lc,
        depth,
    };
    let right = Task {
        prims: rp,
        ids: ri,
        first: task.first + k as u32,
        bounds: rb,
        cbounds: rc,
        depth,
    };

    let (a, b) = if limits.parallel && n >= PARALLEL_MIN_PRIMS {
        let mut right_tally = Tally::default();
        let (mut left_tree, mut right_tree) = tree.split(k, task.first);
        let (a, b) = rayon_core::join(
            || build_node(left, &mut left_tree, tally, limits, tri_area),
            || build_node(right, &mut right_tree, &mut right_tally, limits, tri_area),
        );
        // This subtree now ends where the right one's nodes end (the left one's unused
        // places stay a gap).
        let right_end = right_tree.base + right_tree.used;
        tree.used = right_end - tree.base;
        tally.merge(right_tally);
        (a, b)
    } else {
        let a = build_node(left, tree, tally, limits, tri_area);
        let b = build_node(right, tree, tally, limits, tri_area);
        (a, b)
    };
    tree.set(slot, larger_first(a, b));
    let mut budget = limits.rotation_budget;
    rotate_locally(tree, slot, task.depth, limits.max_depth, &mut budget);
    task.bounds.child(slot as u32, 0)
}
