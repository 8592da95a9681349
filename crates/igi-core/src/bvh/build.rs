//! Binned SAH builder (in the manner of Wald, "On fast construction of SAH-based bounding
//! volume hierarchies", 2007).
//!
//! A range of more than `SMALL_RANGE` (12) triangles is binned over its centroid bounds,
//! [`SAH_BINS`] bins per axis (half as many below `FEW_BINS_BELOW` = 256 triangles), and
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
//! first, becomes the one likelier to stop them per unit of work ([`occluder_first`]);
//! it need not be the left one. [`BuildStats::phases`] times the steps.
//!
//! With [`super::BvhBuilder::Split`] the references are not whole triangles but the
//! pieces that early split clipping (`split`) cut the wasteful ones into; the build is
//! the same.

use std::mem::MaybeUninit;
use std::time::Instant;

use glam::{Vec3, Vec3A};

use super::{
    BuildStats, Bvh, BvhChild, BvhNode, TriRow, MAX_DEPTH, MAX_LEAF_SIZE, SAH_BINS,
    SAH_INTERSECT_COST, SAH_TRAVERSAL_COST,
};
use crate::scene::Triangle;

/// Ranges smaller than this are not worth a task of their own: on the conference room
/// and the 2-core machine, 4,096 and 16,384 measured alike (docs/PERFORMANCE.md attempt
/// 111).
const PARALLEL_MIN_PRIMS: usize = 4 * 1024;

/// Ranges up to this size are split by an exact SAH sweep over their sorted centroids
/// instead of bins: most nodes of a tree are small, and for them the fixed cost of
/// clearing and sweeping 3 x SAH_BINS bins dominates (and the exact sweep finds better
/// splits).
const SMALL_RANGE: usize = 12;

/// See [`bin_count`].
const FEW_BINS_BELOW: usize = 256;

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

/// The chosen split: bins `< bin` of `axis` go left.
struct Split {
    axis: usize,
    bin: u32,
    /// Sum of A(child) N(child) over both children (half areas).
    cost: f32,
    left: Aabb,
    right: Aabb,
}

/// 2^23: for 0 <= x < 2^22, the low mantissa bits of x + 2^23 are round(x).
const ROUND_MAGIC: f32 = 8_388_608.0;
const BIN_MASK: u32 = SAH_BINS as u32 - 1;
const _: () = assert!(SAH_BINS.is_power_of_two() && SAH_BINS >= 4);
const _: () = assert!(SMALL_RANGE <= 16, "ranks are read back with a 4-bit mask");

/// Maps doubled centroids to bin indices for one node. Binning and partitioning must
/// agree exactly, so both go through [`Binner::bins`] (the same f32 operations).
/// Bin = round((c - cmin) (bins - 1) / extent): monotone in c, the minimum centroid in
/// bin 0 and the maximum in the last, so a split between them always exists.
/// The rounding is done with [`ROUND_MAGIC`] and a mask rather than a float-to-int
/// cast: the cast's saturation checks cost more than the rest of the binning, and the
/// mask keeps any index (even of a NaN) inside the bins.
struct Binner {
    cmin: Vec3A,
    scale: Vec3A,
}

/// Bins per axis for a range of `n` primitives: [`SAH_BINS`] for large ranges, half as
/// many below [`FEW_BINS_BELOW`] primitives, where the fixed cost of clearing and
/// sweeping the bins is a large share of the work and the split matters less.
fn bin_count(n: usize) -> usize {
    if n < FEW_BINS_BELOW {
        SAH_BINS / 2
    } else {
        SAH_BINS
    }
}

impl Binner {
    fn new(cbounds: &Aabb, bins: usize) -> Binner {
        debug_assert!(bins <= SAH_BINS);
        let extent = cbounds.hi - cbounds.lo;
        // Axes without extent get scale 0: everything in bin 0, and they are skipped.
        let scale = Vec3A::select(
            extent.cmpgt(Vec3A::ZERO),
            Vec3A::splat((bins - 1) as f32) / extent,
            Vec3A::ZERO,
        );
        Binner {
            cmin: cbounds.lo,
            scale,
        }
    }

    #[inline]
    fn bins(&self, c: Vec3A) -> [usize; 3] {
        let x = (c - self.cmin) * self.scale + Vec3A::splat(ROUND_MAGIC);
        let bits: [u32; 4] = bytemuck::cast(x);
        [0, 1, 2].map(|axis| (bits[axis] & BIN_MASK) as usize)
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

/// Threads of the work-stealing pool the build runs on (rayon's global pool: one per core).
fn threads() -> usize {
    rayon_core::current_num_threads()
}

/// Runs `f(chunk_start, chunk)` over `data` split into chunks on all threads; returns
/// the results in chunk order. Four chunks per thread, taken by whichever thread is free,
/// so that uneven work (the few triangles that split clipping cuts) does not wait for
/// one thread.
pub(super) fn par_chunks<T: Send, R: Send, F>(data: &mut [T], f: F) -> Vec<R>
where
    F: Fn(usize, &mut [T]) -> R + Sync,
{
    let mut none = vec![(); data.len()];
    par_chunks_zip(data, &mut none, |base, chunk, _| f(base, chunk))
}

/// [`par_chunks`] over two slices of one length, split alike: `f(chunk_start, a, b)`.
fn par_chunks_zip<A: Send, B: Send, R: Send, F>(a: &mut [A], b: &mut [B], f: F) -> Vec<R>
where
    F: Fn(usize, &mut [A], &mut [B]) -> R + Sync,
{
    assert_eq!(a.len(), b.len(), "slices of one length");
    let Some(chunk) = chunk_len(a.len()) else {
        return vec![f(0, a, b)];
    };
    let mut results: Vec<Option<R>> = a.chunks(chunk).map(|_| None).collect();
    let f = &f;
    rayon_core::scope(|s| {
        let chunks = a.chunks_mut(chunk).zip(b.chunks_mut(chunk));
        for (k, ((ca, cb), r)) in chunks.zip(&mut results).enumerate() {
            s.spawn(move |_| *r = Some(f(k * chunk, ca, cb)));
        }
    });
    results
        .into_iter()
        .map(|r| r.expect("every chunk ran"))
        .collect()
}

/// Two vectors of `n` items (the first with room for `spare` more) made on all threads:
/// items i are `item(i)`, and `reduce` runs over each chunk of the first once it is
/// written (its results come in chunk order). The threads write the memory once: zeroed
/// first, as `vec!` does, it would be written twice, the first time in one thread when
/// the allocator reuses memory (docs/PERFORMANCE.md attempt 111).
fn par_vec2<A, B, R, I, G>(n: usize, spare: usize, item: I, reduce: G) -> (Vec<A>, Vec<B>, Vec<R>)
where
    A: Send + Sync,
    B: Send,
    R: Send,
    I: Fn(usize) -> (A, B) + Sync,
    G: Fn(&[A]) -> R + Sync,
{
    let mut va: Vec<A> = Vec::with_capacity(n + spare);
    let mut vb: Vec<B> = Vec::with_capacity(n);
    let results = par_chunks_zip(
        &mut va.spare_capacity_mut()[..n],
        &mut vb.spare_capacity_mut()[..n],
        |base, ca, cb| {
            for (k, (sa, sb)) in ca.iter_mut().zip(cb).enumerate() {
                let (a, b) = item(base + k);
                sa.write(a);
                sb.write(b);
            }
            // SAFETY: every element of the chunk was initialised just above, and
            // MaybeUninit<A> has the layout of A.
            let done = unsafe { &*(ca as *const [std::mem::MaybeUninit<A>] as *const [A]) };
            reduce(done)
        },
    );
    // SAFETY: par_chunks_zip ran the closure above over every chunk of the first n
    // elements of both (a panic in it would have ended this function), and it
    // initialised each of them.
    unsafe {
        va.set_len(n);
        vb.set_len(n);
    }
    (va, vb, results)
}

/// An empty vector of `B` in the allocation of `v`, whose items are dropped, where that
/// holds `n` of them (the same alignment, and a size that divides); otherwise a new one.
/// A buffer that a finished phase wrote has its pages mapped, a new one does not (see
/// `build_impl`).
pub(super) fn reuse_vec<A: bytemuck::NoUninit, B: bytemuck::AnyBitPattern>(
    mut v: Vec<A>,
    n: usize,
) -> Vec<B> {
    v.clear();
    match bytemuck::allocation::try_cast_vec::<A, B>(v) {
        Ok(b) if b.capacity() >= n => b,
        _ => Vec::with_capacity(n),
    }
}

/// The allocation of the node places as an empty vector of rows: a [`BvhNode`] is four
/// [`TriRow`]s in size and alignment.
pub(super) fn places_as_rows(places: Box<Places<BvhNode>>) -> Vec<TriRow> {
    const _: () = assert!(
        std::mem::size_of::<BvhNode>() == 4 * std::mem::size_of::<TriRow>()
            && std::mem::align_of::<BvhNode>() == std::mem::align_of::<TriRow>()
    );
    let len = places.len();
    let ptr = Box::into_raw(places).cast::<TriRow>();
    // SAFETY: the allocation holds `len` BvhNodes, which is the layout (size and alignment,
    // asserted above) of 4 len TriRows; a vector of length 0 reads none of it, and the
    // places' contents need no drop (MaybeUninit).
    unsafe { Vec::from_raw_parts(ptr, 0, 4 * len) }
}

/// Writes the three rows of each slot (see [`Bvh::tri_rows`]) of the triangles `ids`
/// into `rows` (empty; grown where it is too small), on all threads (`ids` is only read;
/// it is split alike by `par_chunks_zip`, which takes two mutable slices).
fn triangle_rows<T: Vertices>(mut rows: Vec<TriRow>, tri: &[T], ids: &mut [u32]) -> Vec<TriRow> {
    let refs = ids.len();
    if rows.capacity() < 3 * refs {
        rows = Vec::with_capacity(3 * refs);
    }
    let spare = &mut rows.spare_capacity_mut()[..3 * refs];
    // SAFETY: [MaybeUninit<TriRow>; 3] has the layout of three MaybeUninit<TriRow> in a
    // row, so the 3 refs places are refs triples.
    let slots = unsafe {
        std::slice::from_raw_parts_mut(spare.as_mut_ptr().cast::<MaybeUninit<[TriRow; 3]>>(), refs)
    };
    par_chunks_zip(slots, ids, |_, slots, ids| {
        for (k, (slot, &id)) in slots.iter_mut().zip(ids.iter()).enumerate() {
            // The triangles are read in the tree's order, scattered over the scene's
            // array: each read waited on the cache until they were asked for ahead,
            // which halved this pass on the conference room (attempt 124).
            if let Some(t) = ids
                .get(k + ROWS_PREFETCH_AHEAD)
                .and_then(|&a| tri.get(a as usize))
            {
                prefetch(t.vertices());
            }
            let [v0, v1, v2] = *tri[id as usize].vertices();
            slot.write([0, 1, 2].map(|axis| TriRow([v0[axis], v1[axis], v2[axis], 0.0])));
        }
    });
    // SAFETY: par_chunks_zip ran the closure over every slot, which wrote its three rows.
    unsafe { rows.set_len(3 * refs) };
    // Gives back the places' pages beyond the rows (glibc shrinks in place, no copy).
    rows.shrink_to_fit();
    rows
}

/// How many slots ahead [`triangle_rows`] prefetches the triangles it will read: 16 and
/// 32 measured alike, 8 and 64 less well (docs/PERFORMANCE.md attempt 124).
const ROWS_PREFETCH_AHEAD: usize = 24;

/// The chunk length of [`par_chunks`] for `n` items, or None where one thread does it all.
fn chunk_len(n: usize) -> Option<usize> {
    let t = threads();
    (t > 1 && n >= 4096).then(|| n.div_ceil(4 * t))
}

/// Counts and areas gathered while building, for [`BuildStats`].
#[derive(Default)]
struct Tally {
    leaves: usize,
    max_leaf_size: u32,
    oversized_leaves: usize,
    /// Sum of half area x triangle count over leaves.
    leaf_area: f64,
}

impl Tally {
    fn leaf(&mut self, count: usize, half_area: f32) {
        self.leaves += 1;
        self.max_leaf_size = self.max_leaf_size.max(count as u32);
        self.oversized_leaves += usize::from(count > MAX_LEAF_SIZE);
        self.leaf_area += (half_area * count as f32) as f64;
    }

    fn merge(&mut self, o: Tally) {
        self.leaves += o.leaves;
        self.max_leaf_size = self.max_leaf_size.max(o.max_leaf_size);
        self.oversized_leaves += o.oversized_leaves;
        self.leaf_area += o.leaf_area;
    }
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
    // memory costs a page fault per 4 KiB, about 1.7 us on the 2-core machine, and these
    // two buffers had been 26 MB of the 52 MB it touched on the conference room
    // (docs/PERFORMANCE.md attempt 113).
    let (nodes_out, interior_area, deepest) = depth_first_layout(&nodes, &info, prims);
    drop(info);
    phases.lap("layout");

    // Per slot the x, y and z rows of its vertices (see Bvh::tri_rows). In a pass of its
    // own rather than at the leaves: the reads of scattered triangles overlap here, and
    // the leaves took twice as long over them (docs/PERFORMANCE.md attempt 111).
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

/// Wall time of the build's phases, for [`BuildStats::phases`].
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
/// with a non-finite vertex has area 0 (see [`occluder_first`]).
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

/// What the build keeps per interior node besides the node itself: its height for the
/// rotations' depth cap ([`rotate_locally`]), and what [`occluder_first`] orders its
/// children by, so that the layout can place them without a pass of its own.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, bytemuck::Pod, bytemuck::Zeroable)]
struct NodeInfo {
    /// Triangle area below the node (see [`occluder_first`]).
    area: f32,
    /// SAH cost of the interior nodes below the node and of the node itself, not divided
    /// by any area (see [`occluder_first`]).
    cost: f32,
    /// Interior nodes in the node's subtree, itself included (where the layout puts its
    /// second subtree).
    interior: u32,
    /// Levels below the node: 1 for a node whose children are leaves.
    height: u8,
    /// 1 where child b is the likelier occluder and the layout makes it child a.
    swap: u8,
    _pad: [u8; 2],
}

/// Places of the node array (or of the [`NodeInfo`] array) while the tree is built, left
/// unwritten until a node is stored there: a subtree of n references gets the n - 1
/// places it might need ([`Region`]) and uses about half of them, and zeroing them all
/// cost 2.5-4 ms a build on the 2-core machine wherever the allocator reused memory
/// (docs/PERFORMANCE.md attempt 112). A place is read only where a child refers to it
/// (and the root, place 0, which is always written), and a child refers to a node only
/// once [`Region::set`] has stored it: `build_node` hands out a node's reference after
/// setting it, and the rotations only store nodes that were set before. So no unwritten
/// place is read ([`written`]).
pub(super) type Places<T> = [MaybeUninit<T>];

/// The node (or [`NodeInfo`]) at place `i`.
///
/// # Safety
/// Place `i` must have been written: the root's place, or one a child refers to (see
/// [`Places`]).
#[inline]
unsafe fn written<T: Copy>(places: &Places<T>, i: usize) -> T {
    // SAFETY: the caller's guarantee.
    unsafe { places[i].assume_init() }
}

/// The part of the tree's node array (and of the nodes' [`NodeInfo`]) that a subtree
/// writes: nodes at global indices `base ..`, `used` of them so far; with the triangle
/// areas of the BVH slots from `slot_base` on, which its leaves write. A subtree
/// of n triangles gets n - 1 places, the most it can need; one built on another thread
/// gets a region of its own, carved from its parent's, so that the two sides of a split
/// are built in place side by side. The places a subtree leaves unused stay unwritten and
/// unreachable, and the depth-first layout drops them. (The right subtree used to be
/// built in a vector of its own and copied behind the left one: 6 ms of copies, mostly
/// after joins, on the conference room; docs/PERFORMANCE.md attempt 63.)
struct Region<'a> {
    nodes: &'a mut Places<BvhNode>,
    info: &'a mut Places<NodeInfo>,
    base: usize,
    used: usize,
    /// Per slot the area of its triangle (0 for a non-finite one).
    slot_area: &'a mut [f32],
    slot_base: usize,
}

impl Region<'_> {
    /// A new node's global index.
    fn push(&mut self) -> usize {
        self.used += 1;
        self.base + self.used - 1
    }

    /// Node `i`, which must have been set: node `i` being built or rotated, or a child's.
    fn node(&self, i: usize) -> BvhNode {
        debug_assert!(self.info(i).interior > 0, "node {i} read before it was set");
        // SAFETY: every caller passes such an index (see Places).
        unsafe { written(self.nodes, i - self.base) }
    }

    /// Node `i`'s info, as for [`Region::node`].
    fn info(&self, i: usize) -> NodeInfo {
        // SAFETY: as in Region::node.
        let info = unsafe { written(self.info, i - self.base) };
        debug_assert!(info.interior > 0, "node {i}'s info read before it was set");
        info
    }

    /// Stores node `i`, whose children are final, with its [`NodeInfo`].
    fn set(&mut self, i: usize, node: BvhNode) {
        let (a, b) = (node.a(), node.b());
        let ((area_a, cost_a), (area_b, cost_b)) = (self.content(&a), self.content(&b));
        let visit = SAH_TRAVERSAL_COST * union(&a, &b).half_area();
        // The sums are taken in the final order of the children.
        let swap = occluder_first((area_a, cost_a), (area_b, cost_b));
        let (area, cost) = if swap {
            (area_b + area_a, visit + cost_b + cost_a)
        } else {
            (area_a + area_b, visit + cost_a + cost_b)
        };
        let info = NodeInfo {
            area,
            cost,
            interior: 1 + self.interior(&a) + self.interior(&b),
            height: 1 + self.height(&a).max(self.height(&b)),
            swap: u8::from(swap),
            _pad: [0; 2],
        };
        self.nodes[i - self.base].write(node);
        self.info[i - self.base].write(info);
    }

    /// Levels below a child: 0 for a leaf, its node's height for an interior node.
    fn height(&self, c: &BvhChild) -> u8 {
        if is_node(c) {
            self.info(c.index as usize).height
        } else {
            0
        }
    }

    /// Interior nodes of a child's subtree (0 for a leaf).
    fn interior(&self, c: &BvhChild) -> u32 {
        if is_node(c) {
            self.info(c.index as usize).interior
        } else {
            0
        }
    }

    /// The triangle area and the interior nodes' SAH cost below a child (see
    /// [`occluder_first`]); a leaf's area summed slot by slot.
    fn content(&self, c: &BvhChild) -> (f32, f32) {
        if is_node(c) {
            let info = self.info(c.index as usize);
            (info.area, info.cost)
        } else if c.is_empty() {
            (0.0, 0.0)
        } else {
            let first = c.index as usize - self.slot_base;
            let area = self.slot_area[first..first + c.count as usize].iter().sum();
            (area, 0.0)
        }
    }

    /// Writes the triangle areas of the leaf of `ids`, whose first slot is `first`.
    fn write_leaf(&mut self, first: u32, ids: &[u32], tri_area: &[f32]) {
        let first = first as usize - self.slot_base;
        for (area, &id) in self.slot_area[first..first + ids.len()].iter_mut().zip(ids) {
            *area = tri_area[id as usize];
        }
    }

    /// The rest of the region split for a node's two subtrees built side by side: the
    /// left one (k triangles from slot `first`) gets k - 1 places, the right one the
    /// rest; the slots split after the left one's.
    fn split(&mut self, k: usize, first: u32) -> (Region<'_>, Region<'_>) {
        let (ln, rn) = self.nodes[self.used..].split_at_mut(k - 1);
        let (li, ri) = self.info[self.used..].split_at_mut(k - 1);
        let at = first as usize + k - self.slot_base;
        let (la, ra) = self.slot_area.split_at_mut(at);
        let base = self.base + self.used;
        (
            Region {
                nodes: ln,
                info: li,
                base,
                used: 0,
                slot_area: la,
                slot_base: self.slot_base,
            },
            Region {
                nodes: rn,
                info: ri,
                base: base + k - 1,
                used: 0,
                slot_area: ra,
                slot_base: self.slot_base + at,
            },
        )
    }
}

/// Whether a child is an interior node (not a leaf; the empty child of a root leaf is a
/// leaf of one triangle, `BvhChild::EMPTY`).
fn is_node(c: &BvhChild) -> bool {
    !c.is_leaf()
}

/// Kensler's tree rotations ("Tree Rotations for Improving Bounding Volume Hierarchies",
/// 2008) at node `i` of a subtree just built, after each rotation at the child that
/// changed too (its new children may rotate in turn), at most `budget` rotations in all.
/// `depth` is node i's; `heights` holds the levels below each node (1 for a node whose
/// children are leaves).
///
/// A rotation swaps one child x with a grandchild g under its other child y, which
/// becomes (x, the other grandchild): only y's box changes, so it is taken when it
/// shrinks y's surface area (the SAH cost of the tree falls by the same amount), the
/// best of the node's four, and only if it keeps every interior node above `max_depth`
/// (the traversal stack's bound). Made as each node's subtree is finished, while it is in
/// cache, this is one bottom-up pass over the tree in which every node settles before its
/// parent looks at it. On the conference room: SAH cost 35.6 -> 33.0, as with three
/// separate passes over the finished tree, for 3-9% less build time on the 2-core machine
/// (docs/PERFORMANCE.md attempts 48 and 49).
fn rotate_locally(tree: &mut Region, i: usize, depth: u32, max_depth: u32, budget: &mut u32) {
    while *budget > 0 {
        let Some(y) = rotate_node(tree, i, depth, max_depth) else {
            return;
        };
        *budget -= 1;
        rotate_locally(tree, y, depth + 1, max_depth, budget);
        // y's subtree may have changed again: i's info anew.
        tree.set(i, tree.node(i));
    }
}

/// The best rotation at node `i` (see [`rotate_locally`]), if one shrinks a box within
/// the depth cap; returns the index of the child whose children changed.
fn rotate_node(tree: &mut Region, i: usize, depth: u32, max_depth: u32) -> Option<usize> {
    let n = tree.node(i);
    let kids = [n.a(), n.b()];
    let h = |c: &BvhChild| tree.height(c);
    // (area saved, the side of x, the grandchild that moves up)
    let mut best: Option<(f32, usize, usize)> = None;
    for side in 0..2 {
        let (x, y) = (kids[side], kids[1 - side]);
        if !is_node(&y) {
            continue;
        }
        let grand = tree.node(y.index as usize);
        let g = [grand.a(), grand.b()];
        for k in 0..2 {
            let saved = y.half_area() - union(&x, &g[1 - k]).half_area();
            let y_height = 1 + h(&x).max(h(&g[1 - k]));
            let i_height = 1 + h(&g[k]).max(y_height);
            // A relative threshold, so that rounding cannot make rotations cycle.
            if saved > 1e-6 * y.half_area()
                && depth + i_height as u32 <= max_depth
                && best.is_none_or(|b| saved > b.0)
            {
                best = Some((saved, side, k));
            }
        }
    }
    let (_, side, k) = best?;
    let (x, y) = (kids[side], kids[1 - side]);
    let grand = tree.node(y.index as usize);
    let g = [grand.a(), grand.b()];
    let (up, stays) = (g[k], g[1 - k]);
    tree.set(y.index as usize, larger_first(x, stays));
    let y = union(&x, &stays).child(y.index, 0);
    tree.set(i, larger_first(up, y));
    Some(y.index as usize)
}

/// Whether child b of a node, not child a, is the child likelier to stop an any-hit walk
/// per unit of work, given each child's (triangle area, interior nodes' SAH cost) below
/// it: the one with the larger ratio of the two (ties keep the order). The build keeps
/// these sums per node ([`NodeInfo`]) and the layout makes the likelier child child a.
/// Any-hit walks visit child a first. When a segment enters both children, visiting A
/// first costs C_A + (1 - p_A) C_B, where p is the chance of an occluder in the child and
/// C the expected work there; A goes first when p_A / C_A > p_B / C_B. Given that the
/// segment enters a child's box, p grows with the triangle area inside over the box's
/// area (Cauchy: a random line meets a flat triangle of area a in a box of half area h
/// with probability a / h), and C with the half areas of the interior nodes below over
/// the box's (the node visits to expect), so the box areas cancel. Leaves cost 0: the
/// walks test a leaf child's triangles as soon as its box is hit, whichever child it is,
/// so the order only matters between two interior children (then the key decides) and
/// between two leaves (then 0 against 0 keeps the larger box first, which measured best).
/// Counting the leaves' triangle tests in C at the SAH's weight made the walks slower,
/// and the less they weighed the faster they were (docs/PERFORMANCE.md attempt 84). On the
/// H200 against child a holding more triangle area (attempt 80): canonical frames 10.69 ->
/// 10.40 ms, the frame's shadow rays 5.43 -> 5.62 and the random segments 2.09 -> 2.12
/// G rays/s. A triangle with a non-finite vertex counts 0; one cut by early split
/// clipping counts in full in each leaf that holds one of its pieces. Where the children
/// are swapped, child b's subtree is the one right after the node: laying the tree out
/// again so that child a's came first measured the same on the H200 (attempt 80) and cost
/// the build 4-8 ms.
fn occluder_first((area_a, cost_a): (f32, f32), (area_b, cost_b): (f32, f32)) -> bool {
    // area_b / cost_b > area_a / cost_a without dividing (two leaves, or a leaf and the
    // empty child: 0 > 0).
    area_b * cost_a > area_a * cost_b
}

/// Levels of the layout's top whose two subtrees are laid out side by side (4 parts: a
/// fixed number, so that the sums of the statistics, taken part by part, do not depend
/// on the machine).
const LAYOUT_SPLIT_LEVELS: u32 = 2;

/// The tree renumbered depth first: each node's subtrees right after it, the subtree of
/// its child a as the build left it first (after the larger_first order of the
/// rotations), then the other; with child a the likelier occluder (`NodeInfo::swap`,
/// [`occluder_first`]), which may make child b's subtree the one right after the node.
/// Returns the sum of the interior nodes' half areas below the root and the deepest
/// leaf's depth (the root has depth 0), for the SAH cost. The subtree sizes in
/// [`NodeInfo`] place every node at once, so the top subtrees are laid out on separate
/// threads: on the conference room the one walk it replaced took 3.9-10 ms of the 2-core
/// machine, and the ordering pass after it 7.5-9 ms (docs/PERFORMANCE.md attempt 111).
fn depth_first_layout(
    nodes: &Places<BvhNode>,
    info: &Places<NodeInfo>,
    references: Vec<PrimRef>,
) -> (Vec<BvhNode>, f64, u32) {
    // SAFETY: the root's place is written (see Places).
    let interior = unsafe { written(info, 0) }.interior as usize;
    // In the finished references' allocation (see build_impl); written once by the walks,
    // not zeroed first (1 ms of the 2-core machine).
    let mut out: Vec<BvhNode> = reuse_vec(references, interior);
    let (area, deepest) = lay_out(
        nodes,
        info,
        0,
        &mut out.spare_capacity_mut()[..interior],
        0,
        0,
    );
    // SAFETY: lay_out wrote every one of the places: it numbers the subtree of each node
    // of interior count m (the root's is `interior`) from its own place on, over m
    // places, which it checks node by node (m = 1 + its children's counts).
    unsafe { out.set_len(interior) };
    // Gives back the pages beyond the nodes (glibc shrinks in place, no copy).
    out.shrink_to_fit();
    (out, area, deepest)
}

/// Lays out the subtree of node `root` (at `depth`) into `out`, whose first place has the
/// global index `at`; returns its statistics (see [`depth_first_layout`]).
fn lay_out(
    nodes: &Places<BvhNode>,
    info: &Places<NodeInfo>,
    root: u32,
    out: &mut [MaybeUninit<BvhNode>],
    at: u32,
    depth: u32,
) -> (f64, u32) {
    let (mut area, mut deepest) = (0.0f64, 0u32);
    // The node at its new place, and where its children's subtrees go.
    let mut place = |i: u32, k: u32, depth: u32, out: &mut [MaybeUninit<BvhNode>]| {
        // SAFETY: i is the root or a child's node, a written place (see Places); so are
        // the interior children's below.
        let (n, node_info) = unsafe { (written(nodes, i as usize), written(info, i as usize)) };
        debug_assert!(node_info.interior > 0, "node {i} laid out but never set");
        let (a, b) = (n.a(), n.b());
        // The children's nodes are read next (child a at once, b after a's subtree), and
        // a node's first read was where the walk waited (a child's order differs from
        // the build's wherever the rotations or larger_first turned it): asked for now,
        // they load beside the children's infos read below (docs/PERFORMANCE.md
        // attempt 132: the layout 9.2 -> 8.2 ms on one thread, the same tree).
        for c in [&a, &b] {
            if is_node(c) {
                prefetch(&nodes[c.index as usize]);
            }
        }
        let interior = |c: &BvhChild| {
            if is_node(c) {
                // SAFETY: see above.
                unsafe { written(info, c.index as usize).interior }
            } else {
                0
            }
        };
        let (ka, kb) = (k + 1, k + 1 + interior(&a));
        // What makes the numbering cover the places once each (see depth_first_layout).
        assert_eq!(
            node_info.interior,
            1 + interior(&a) + interior(&b),
            "interior count of node {i}"
        );
        // Areas in child order, node by node in the new order.
        for c in [a, b] {
            if is_node(&c) {
                area += c.half_area() as f64;
            } else if c.min.x <= c.max.x {
                deepest = deepest.max(depth + 1);
            }
        }
        let mut m = n;
        if is_node(&a) {
            m.a_index = ka;
        }
        if is_node(&b) {
            m.b_index = kb;
        }
        if node_info.swap != 0 {
            m = BvhNode::new(m.b(), m.a());
        }
        out[(k - at) as usize].write(m);
        [(a, ka), (b, kb)]
    };
    if depth < LAYOUT_SPLIT_LEVELS {
        let [(a, ka), (b, kb)] = place(root, at, depth, out);
        let (_, rest) = out.split_at_mut(1);
        let (out_a, out_b) = rest.split_at_mut((kb - ka) as usize);
        let part = |c: BvhChild, k: u32, out: &mut [MaybeUninit<BvhNode>]| {
            if is_node(&c) {
                lay_out(nodes, info, c.index, out, k, depth + 1)
            } else {
                (0.0, 0)
            }
        };
        let (pa, pb) = rayon_core::join(|| part(a, ka, out_a), || part(b, kb, out_b));
        return (area + pa.0 + pb.0, deepest.max(pa.1).max(pb.1));
    }
    // (node, its new index, its depth); a's subtree next.
    let mut stack = vec![(root, at, depth)];
    while let Some((i, k, depth)) = stack.pop() {
        let [(a, ka), (b, kb)] = place(i, k, depth, out);
        for (c, kc) in [(b, kb), (a, ka)] {
            if is_node(&c) {
                stack.push((c.index, kc, depth + 1));
            }
        }
    }
    (area, deepest)
}

/// The node of two children, the one of larger surface area first. This was the order of
/// the any-hit walks (attempt 41: 9-15% faster than the split's order) until the layout
/// put the likelier occluder first ([`occluder_first`], attempts 80 and 84); it
/// stays the order in which the rotations compare children while the tree is built, so
/// that they make the trees they were measured with.
fn larger_first(a: BvhChild, b: BvhChild) -> BvhNode {
    if b.half_area() > a.half_area() {
        BvhNode::new(b, a)
    } else {
        BvhNode::new(a, b)
    }
}

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

/// Exact SAH sweep of a small range (2..=SMALL_RANGE primitives): for each axis the
/// primitives sorted by centroid, every split between neighbours in that order.
struct SmallSweep {
    n: usize,
    axis: usize,
    /// Split after `at` + 1 primitives of `order[axis]`.
    at: usize,
    cost: f32,
    order: [[u8; SMALL_RANGE]; 3],
}

impl SmallSweep {
    /// The sweep of a range of 2..=SMALL_RANGE primitives: one copy of the code per size,
    /// so that every loop has a fixed count and unrolls, and the best split is picked
    /// without branches (948 -> 918 M instructions a build, the same trees;
    /// docs/PERFORMANCE.md attempt 118).
    fn new(prims: &[PrimRef]) -> SmallSweep {
        const _: () = assert!(SMALL_RANGE == 12, "one arm per size below");
        match prims.len() {
            2 => Self::pair(prims),
            3 => Self::of::<3>(prims),
            4 => Self::of::<4>(prims),
            5 => Self::of::<5>(prims),
            6 => Self::of::<6>(prims),
            7 => Self::of::<7>(prims),
            8 => Self::of::<8>(prims),
            9 => Self::of::<9>(prims),
            10 => Self::of::<10>(prims),
            11 => Self::of::<11>(prims),
            _ => Self::of::<12>(prims),
        }
    }

    /// Two primitives: one per side whatever the axis.
    fn pair(prims: &[PrimRef]) -> SmallSweep {
        let half_area = |p: &PrimRef| Aabb { lo: p.lo, hi: p.hi }.half_area();
        let mut order = [[0; SMALL_RANGE]; 3];
        order[0][1] = 1;
        SmallSweep {
            n: 2,
            axis: 0,
            at: 0,
            cost: half_area(&prims[0]) + half_area(&prims[1]),
            order,
        }
    }

    /// The sweep of `N` primitives (3..=SMALL_RANGE).
    #[inline(always)]
    fn of<const N: usize>(prims: &[PrimRef]) -> SmallSweep {
        let prims: &[PrimRef; N] = prims.try_into().expect("N primitives");
        let mut order = [[0u8; SMALL_RANGE]; 3];
        let c: [Vec3A; N] = std::array::from_fn(|i| prims[i].centroid2());
        // Rank of each primitive along each axis (ties by index, so equal centroids are
        // split by index): branch-free, all three axes at once. Those before i in index
        // order count when not greater, those after when less.
        for i in 0..N {
            let mut r = Vec3A::ZERO;
            for cj in &c[..i] {
                r += Vec3A::select(cj.cmple(c[i]), Vec3A::ONE, Vec3A::ZERO);
            }
            for cj in &c[i + 1..] {
                r += Vec3A::select(cj.cmplt(c[i]), Vec3A::ONE, Vec3A::ZERO);
            }
            // The ranks (< 16) as integers by ROUND_MAGIC, not a saturating cast; the lanes
            // through an array, not glam's Vec3A indexing (which goes through memory).
            let ranks: [u32; 4] = bytemuck::cast(r + Vec3A::splat(ROUND_MAGIC));
            for (order, r) in order.iter_mut().zip(ranks) {
                order[(r & 15) as usize] = i as u8;
            }
        }
        // The three axes' sweeps side by side: step i grows each axis's box by its i-th
        // primitive, and the three half areas are taken at once from the boxes' extents
        // transposed into lanes (x, y and z of the three boxes), with the operations of
        // `Aabb::half_area` in its order, so the costs are the same bits.
        let mut right = [Vec3A::ZERO; N];
        let mut sweep3 = Sweep3::default();
        for i in (1..N).rev() {
            right[i - 1] = sweep3.grow(prims, &order, i) * (N - i) as f32;
        }
        // Per axis the first lowest cost in split order (lanes take a cost only when
        // strictly lower), then the first lowest in axis order: what the sweeps one axis
        // after another found.
        let mut best = Vec3A::INFINITY;
        let mut best_at = Vec3A::ZERO;
        let mut sweep3 = Sweep3::default();
        for (i, right) in right[..N - 1].iter().enumerate() {
            let cost = sweep3.grow(prims, &order, i) * (i + 1) as f32 + *right;
            let lower = cost.cmplt(best);
            best = Vec3A::select(lower, cost, best);
            best_at = Vec3A::select(lower, Vec3A::splat(i as f32), best_at);
        }
        let (mut axis, mut cost) = (0, f32::INFINITY);
        for k in 0..3 {
            if best[k] < cost {
                (axis, cost) = (k, best[k]);
            }
        }
        SmallSweep {
            n: N,
            axis,
            at: if cost < f32::INFINITY {
                best_at[axis] as usize
            } else {
                0
            },
            cost,
            order,
        }
    }

    /// Reorders the range by the chosen axis; returns the left count and the bounds and
    /// centroid bounds of both sides.
    fn apply(&self, prims: &mut [PrimRef], ids: &mut [u32]) -> (usize, Aabb, Aabb, Aabb, Aabb) {
        let (n, k) = (self.n, self.at + 1);
        let order = &self.order[self.axis][..n];
        // The primitives in their new order, with the bounds of each side taken on the
        // way; left unwritten beyond n (filling the 12 places first cost more than the
        // rest of the reordering).
        let mut p = [MaybeUninit::<PrimRef>::uninit(); SMALL_RANGE];
        let mut d = [0u32; SMALL_RANGE];
        let mut gather = |places: std::ops::Range<usize>| {
            let (mut b, mut c) = (Aabb::EMPTY, Aabb::EMPTY);
            for i in places {
                let o = order[i] as usize;
                let q = prims[o];
                b.lo = b.lo.min(q.lo);
                b.hi = b.hi.max(q.hi);
                c.grow_point(q.centroid2());
                p[i].write(q);
                d[i] = ids[o];
            }
            (b, c)
        };
        let (lb, lc) = gather(0..k);
        let (rb, rc) = gather(k..n);
        for (to, from) in prims.iter_mut().zip(&p) {
            // SAFETY: the two gathers wrote places 0..n, and prims has n.
            *to = unsafe { from.assume_init() };
        }
        ids.copy_from_slice(&d[..n]);
        (k, lb, lc, rb, rc)
    }
}

/// Three boxes grown side by side, one per axis: the sweeps over the three axes' orders
/// of a small range ([`SmallSweep::new`]) or over their bins ([`find_split`]) run in
/// step, and each step takes the three half areas at once (docs/PERFORMANCE.md attempt
/// 116: 998 -> 949 M instructions a build for the same trees).
struct Sweep3 {
    lo: [Vec3A; 3],
    hi: [Vec3A; 3],
}

impl Default for Sweep3 {
    fn default() -> Sweep3 {
        Sweep3 {
            lo: [Vec3A::INFINITY; 3],
            hi: [Vec3A::NEG_INFINITY; 3],
        }
    }
}

impl Sweep3 {
    /// Grows box k by the primitive at place i of axis k's order, and returns the three
    /// half areas (lane k: box k's), computed as [`Aabb::half_area`] computes them.
    #[inline]
    fn grow(&mut self, prims: &[PrimRef], order: &[[u8; SMALL_RANGE]; 3], i: usize) -> Vec3A {
        for k in 0..3 {
            let p = &prims[order[k][i] as usize];
            self.lo[k] = self.lo[k].min(p.lo);
            self.hi[k] = self.hi[k].max(p.hi);
        }
        self.half_areas()
    }

    /// Grows box k by `boxes[k]` (see [`Sweep3::grow`]). Not one generic method for
    /// both: with the primitives' indexing outside the loop, or through a closure, the
    /// build took 956-958 M instructions against 948 M.
    #[inline]
    fn grow_boxes(&mut self, boxes: [&Aabb; 3]) -> Vec3A {
        for (k, b) in boxes.iter().enumerate() {
            self.lo[k] = self.lo[k].min(b.lo);
            self.hi[k] = self.hi[k].max(b.hi);
        }
        self.half_areas()
    }

    /// The three boxes' half areas (lane k: box k's), computed as [`Aabb::half_area`]
    /// computes them.
    #[inline]
    fn half_areas(&self) -> Vec3A {
        let e = |k: usize| (self.hi[k] - self.lo[k]).max(Vec3A::ZERO);
        let t = glam::Mat3A::from_cols(e(0), e(1), e(2)).transpose();
        let (ex, ey, ez) = (t.x_axis, t.y_axis, t.z_axis);
        ex * ey + ey * ez + ez * ex
    }
}

/// Bounds and primitive counts of the bins, per axis.
type Bins = ([[Aabb; SAH_BINS]; 3], [[u32; SAH_BINS]; 3]);

/// Empty bins: every box [`Aabb::EMPTY`], every count 0.
const NO_BINS: Bins = ([[Aabb::EMPTY; SAH_BINS]; 3], [[0; SAH_BINS]; 3]);

/// Ranges of at least this many primitives are binned into two sets of bins, see
/// [`bin_range`].
const TWO_BIN_SETS_FROM: usize = 64;

/// Adds the primitives of a range to `bins` (in place: bins returned by value were copied
/// out, 2 M instructions of a build). Neighbouring primitives of a range are near each
/// other, so they often fall into the same bin: each one's update then waits for the one
/// before it to be stored (a chain of load, min/max and store per primitive). A large
/// range is therefore binned into two sets, even and odd primitives, merged at the end
/// (docs/PERFORMANCE.md attempt 122). Min, max and sums do not depend on the order of
/// finite bounds without -0 ([`PrimRef::new`]), so the bins are the same to the bit.
fn bin_range(prims: &[PrimRef], binner: &Binner, bins: &mut Bins, nb: usize) {
    if prims.len() < TWO_BIN_SETS_FROM {
        bin_into(prims.iter(), binner, bins);
        return;
    }
    let mut odd = NO_BINS;
    let (pairs, rest) = prims.as_chunks::<2>();
    for [a, b] in pairs {
        bin_into(std::iter::once(a), binner, bins);
        bin_into(std::iter::once(b), binner, &mut odd);
    }
    bin_into(rest.iter(), binner, bins);
    merge_bins(bins, &odd, nb);
}

/// Adds `from`'s first `nb` bins of each axis to `bins`.
fn merge_bins((bins, counts): &mut Bins, (from, from_counts): &Bins, nb: usize) {
    for axis in 0..3 {
        for k in 0..nb {
            bins[axis][k].grow(&from[axis][k]);
            counts[axis][k] += from_counts[axis][k];
        }
    }
}

/// The binning loop of [`bin_range`], into one set of bins.
#[inline(always)]
fn bin_into<'a>(
    prims: impl Iterator<Item = &'a PrimRef>,
    binner: &Binner,
    (bins, counts): &mut Bins,
) {
    for p in prims {
        let b = binner.bins(p.centroid2());
        for axis in 0..3 {
            let k = b[axis];
            let bin = &mut bins[axis][k];
            bin.lo = bin.lo.min(p.lo);
            bin.hi = bin.hi.max(p.hi);
            counts[axis][k] += 1;
        }
    }
}

/// Best SAH split of a range over [`SAH_BINS`] bins per axis, or None when all
/// centroids are equal.
fn find_split(prims: &[PrimRef], cbounds: &Aabb, parallel: bool) -> Option<Split> {
    let nb = bin_count(prims.len());
    let binner = Binner::new(cbounds, nb);
    let mut bins = NO_BINS;
    if parallel && threads() > 1 {
        let chunk = prims.len().div_ceil(threads());
        let mut parts: Vec<Bins> = prims.chunks(chunk).map(|_| NO_BINS).collect();
        let binner = &binner;
        rayon_core::scope(|s| {
            for (c, part) in prims.chunks(chunk).zip(&mut parts) {
                s.spawn(move |_| bin_range(c, binner, part, nb));
            }
        });
        for part in &parts {
            merge_bins(&mut bins, part, nb);
        }
    } else {
        bin_range(prims, &binner, &mut bins, nb);
    }
    let (bins, counts) = (&bins.0, &bins.1);
    // The three axes' sweeps side by side (Sweep3), with the same costs to the bit as one
    // axis after another. A split with nothing on one side, or on an axis without
    // extent, costs infinity: it is never taken, as it was never considered.
    let lanes = |k: [u32; 3]| Vec3A::new(k[0] as f32, k[1] as f32, k[2] as f32);
    let no_extent = binner.scale.cmpeq(Vec3A::ZERO);
    // right_cost[i]: bins i+1.. as the right child.
    let mut right_cost = [Vec3A::ZERO; SAH_BINS];
    let mut sweep = Sweep3::default();
    let mut count = [0u32; 3];
    for i in (1..nb).rev() {
        let area = sweep.grow_boxes([0, 1, 2].map(|axis| &bins[axis][i]));
        count = [0, 1, 2].map(|axis| count[axis] + counts[axis][i]);
        let n = lanes(count);
        right_cost[i - 1] = Vec3A::select(n.cmpeq(Vec3A::ZERO), Vec3A::INFINITY, area * n);
    }
    let mut cost = [Vec3A::ZERO; SAH_BINS];
    let mut sweep = Sweep3::default();
    let mut count = [0u32; 3];
    for i in 0..nb - 1 {
        let area = sweep.grow_boxes([0, 1, 2].map(|axis| &bins[axis][i]));
        count = [0, 1, 2].map(|axis| count[axis] + counts[axis][i]);
        let n = lanes(count);
        let skip = n.cmpeq(Vec3A::ZERO) | no_extent;
        cost[i] = Vec3A::select(skip, Vec3A::INFINITY, area * n + right_cost[i]);
    }
    // The first lowest cost in axis order, then bin order.
    let mut best: Option<(usize, u32, f32)> = None;
    for axis in 0..3 {
        for (i, c) in cost[..nb - 1].iter().enumerate() {
            let c: [f32; 4] = bytemuck::cast(*c);
            if c[axis] < best.map_or(f32::INFINITY, |b| b.2) {
                best = Some((axis, i as u32 + 1, c[axis]));
            }
        }
    }
    let (axis, bin, cost) = best?;
    let mut left = Aabb::EMPTY;
    let mut right = Aabb::EMPTY;
    for (i, b) in bins[axis][..nb].iter().enumerate() {
        if (i as u32) < bin {
            left.grow(b);
        } else {
            right.grow(b);
        }
    }
    Some(Split {
        axis,
        bin,
        cost,
        left,
        right,
    })
}

/// Moves the primitives of bins `< split.bin` to the front (Hoare's scheme: only
/// misplaced pairs are swapped); returns their count and the centroid bounds of both sides.
fn partition(
    prims: &mut [PrimRef],
    ids: &mut [u32],
    cbounds: &Aabb,
    split: &Split,
) -> (usize, Aabb, Aabb) {
    let binner = Binner::new(cbounds, bin_count(prims.len()));
    // One loop per axis, so that the lane is picked at compile time.
    match split.axis {
        0 => partition_on::<0>(prims, ids, &binner, split.bin),
        1 => partition_on::<1>(prims, ids, &binner, split.bin),
        _ => partition_on::<2>(prims, ids, &binner, split.bin),
    }
}

fn partition_on<const AXIS: usize>(
    prims: &mut [PrimRef],
    ids: &mut [u32],
    binner: &Binner,
    bin: u32,
) -> (usize, Aabb, Aabb) {
    // The same bin as `Binner::bins` gives (same operations on the same lanes).
    let left = |c: Vec3A| (binner.bins(c)[AXIS] as u32) < bin;
    let mut lc = Aabb::EMPTY;
    let mut rc = Aabb::EMPTY;
    let mut i = 0;
    let mut j = prims.len();
    loop {
        // prims[..i] are left, prims[j..] right.
        let ci = loop {
            if i == j {
                return (i, lc, rc);
            }
            let c = prims[i].centroid2();
            if !left(c) {
                break c;
            }
            lc.grow_point(c);
            i += 1;
        };
        let cj = loop {
            let c = prims[j - 1].centroid2();
            if left(c) {
                break c;
            }
            rc.grow_point(c);
            j -= 1;
            if i == j {
                // prims[i] (= the one just moved past) was right: all classified.
                return (i, lc, rc);
            }
        };
        // prims[i] belongs right, prims[j - 1] left, and i < j - 1.
        prims.swap(i, j - 1);
        ids.swap(i, j - 1);
        lc.grow_point(cj);
        rc.grow_point(ci);
        i += 1;
        j -= 1;
    }
}

fn stats(
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
pub(super) fn stats_by_walk(bvh: &Bvh) -> BuildStats {
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

#[cfg(test)]
mod sweep_tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64;

    /// The sweep as written first: one axis after another, the primitives sorted by
    /// centroid (ties by index), every split scored with `Aabb::half_area`.
    fn reference(prims: &[PrimRef]) -> (usize, usize, f32, [Vec<usize>; 3]) {
        let n = prims.len();
        let mut best = (0, 0, f32::INFINITY);
        let orders = [0, 1, 2].map(|axis| {
            let mut order: Vec<usize> = (0..n).collect();
            order.sort_by(|&a, &b| {
                let (ca, cb) = (prims[a].centroid2()[axis], prims[b].centroid2()[axis]);
                ca.partial_cmp(&cb).unwrap().then(a.cmp(&b))
            });
            order
        });
        for (axis, order) in orders.iter().enumerate() {
            let boxes = |k: usize| Aabb {
                lo: prims[order[k]].lo,
                hi: prims[order[k]].hi,
            };
            let mut right = vec![0.0f32; n];
            let mut acc = Aabb::EMPTY;
            for i in (1..n).rev() {
                acc.grow(&boxes(i));
                right[i - 1] = acc.half_area() * (n - i) as f32;
            }
            let mut acc = Aabb::EMPTY;
            for (i, right) in right[..n - 1].iter().enumerate() {
                acc.grow(&boxes(i));
                let cost = acc.half_area() * (i + 1) as f32 + right;
                if cost < best.2 {
                    best = (axis, i, cost);
                }
            }
        }
        (best.0, best.1, best.2, orders)
    }

    /// `find_split`'s sweep over the bins as written first: one axis after another.
    fn reference_split(prims: &[PrimRef], cbounds: &Aabb) -> Option<(usize, u32, f32)> {
        let nb = bin_count(prims.len());
        let binner = Binner::new(cbounds, nb);
        let mut bins = NO_BINS;
        bin_into(prims.iter(), &binner, &mut bins);
        let (bins, counts) = bins;
        let mut best: Option<(usize, u32, f32)> = None;
        for axis in 0..3 {
            if binner.scale[axis] == 0.0 {
                continue;
            }
            let mut right_cost = [0.0f32; SAH_BINS];
            let mut acc = Aabb::EMPTY;
            let mut count = 0u32;
            for i in (1..nb).rev() {
                acc.grow(&bins[axis][i]);
                count += counts[axis][i];
                right_cost[i - 1] = if count > 0 {
                    acc.half_area() * count as f32
                } else {
                    f32::INFINITY
                };
            }
            let mut acc = Aabb::EMPTY;
            let mut count = 0u32;
            for (i, right) in right_cost[..nb - 1].iter().enumerate() {
                acc.grow(&bins[axis][i]);
                count += counts[axis][i];
                if count == 0 {
                    continue;
                }
                let cost = acc.half_area() * count as f32 + right;
                if cost < best.map_or(f32::INFINITY, |b| b.2) {
                    best = Some((axis, i as u32 + 1, cost));
                }
            }
        }
        best
    }

    /// Random boxes on a grid (coarse grids make equal centroids), some flat.
    fn random_prims(r: &mut Pcg64, n: usize, grid: f32) -> Vec<PrimRef> {
        (0..n)
            .map(|_| {
                let mut v = || r.random_range(0.0..grid).floor();
                let lo = Vec3A::new(v(), v(), v());
                let size = Vec3A::new(v(), v(), v()) * r.random_range(0.0..2.0f32);
                let flat = r.random_range(0..4);
                let size = if flat < 3 {
                    Vec3A::select(Vec3A::AXES[flat].cmpeq(Vec3A::ONE), Vec3A::ZERO, size)
                } else {
                    size
                };
                PrimRef { lo, hi: lo + size }
            })
            .collect()
    }

    /// `find_split` with the three axes' bins swept side by side picks the split of the
    /// one-axis-at-a-time sweep, with the same cost to the bit, for both bin counts,
    /// with empty bins, axes without extent, and ranges whose centroids are all equal.
    #[test]
    fn bin_sweep_matches_the_one_axis_sweep() {
        let mut r = Pcg64::seed_from_u64(12);
        for case in 0..3_000 {
            let n = [13, 40, 63, 64, 65, 255, 256, 701][case % 8];
            let grid = [1.0, 3.0, 50.0, 1e4][case % 4];
            let mut prims = random_prims(&mut r, n, grid);
            if case % 7 == 0 {
                // One axis without extent: every centroid at the same x.
                for p in &mut prims {
                    let w = p.hi.x - p.lo.x;
                    (p.lo.x, p.hi.x) = (-w, w);
                }
            }
            if case % 3 == 1 {
                // Every other one mirrored in y, made as references are made: bounds of
                // -0 beside those of 0.
                for p in prims.iter_mut().step_by(2) {
                    let (lo, hi) = (
                        p.lo * Vec3A::new(1.0, -1.0, 1.0),
                        p.hi * Vec3A::new(1.0, -1.0, 1.0),
                    );
                    *p = PrimRef::new(lo.min(hi), lo.max(hi));
                }
            }
            let (_, cbounds) = range_bounds(&prims);
            let split = find_split(&prims, &cbounds, false);
            let got = split.as_ref().map(|s| (s.axis, s.bin, s.cost.to_bits()));
            let want = reference_split(&prims, &cbounds).map(|(a, b, c)| (a, b, c.to_bits()));
            assert_eq!(got, want, "case {case}");
            // The sides' boxes (merged from two sets of bins for 64 primitives and more)
            // are those of the primitives on each side.
            if let Some(s) = split {
                let binner = Binner::new(&cbounds, bin_count(n));
                let (mut left, mut right) = (Aabb::EMPTY, Aabb::EMPTY);
                for p in &prims {
                    let side = if (binner.bins(p.centroid2())[s.axis] as u32) < s.bin {
                        &mut left
                    } else {
                        &mut right
                    };
                    side.grow(&Aabb { lo: p.lo, hi: p.hi });
                }
                let bits =
                    |b: &Aabb| [b.lo.to_array(), b.hi.to_array()].map(|v| v.map(f32::to_bits));
                assert_eq!(bits(&s.left), bits(&left), "case {case}: left box");
                assert_eq!(bits(&s.right), bits(&right), "case {case}: right box");
            }
        }
    }

    /// The three-axes-at-once sweep (`Sweep3`) picks the split the one-axis-at-a-time
    /// sweep picks, with the same cost to the bit, on ranges of every small size, with
    /// equal centroids, flat and point-like boxes among them.
    #[test]
    fn small_sweep_matches_the_one_axis_sweep() {
        let mut r = Pcg64::seed_from_u64(11);
        for case in 0..20_000 {
            let n = 3 + case % (SMALL_RANGE - 2);
            let grid = [1.0, 4.0, 1000.0][case % 3]; // coarse grids make equal centroids
            let prims = random_prims(&mut r, n, grid);
            let sweep = SmallSweep::new(&prims);
            let (axis, at, cost, orders) = reference(&prims);
            assert_eq!(
                (sweep.axis, sweep.at, sweep.cost.to_bits()),
                (axis, at, cost.to_bits()),
                "case {case}: {prims:?}"
            );
            let order: Vec<usize> = sweep.order[axis][..n].iter().map(|&o| o as usize).collect();
            assert_eq!(order, orders[axis], "case {case}");
        }
    }
}
