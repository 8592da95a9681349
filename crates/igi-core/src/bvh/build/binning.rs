//! The binned SAH split search of a large range (Wald 2007): centroids mapped to bins,
//! the bins filled (on all threads at the root), the three axes' planes scored in one
//! sweep, and the partition of the range by the chosen plane.

use glam::Vec3A;

use super::parallel::threads;
use super::sweep::Sweep3;
use super::{Aabb, PrimRef, SMALL_RANGE};
use crate::bvh::SAH_BINS;

/// See [`bin_count`].
pub(super) const FEW_BINS_BELOW: usize = 256;

/// The chosen split: bins `< bin` of `axis` go left.
pub(super) struct Split {
    pub(super) axis: usize,
    pub(super) bin: u32,
    /// Sum of A(child) N(child) over both children (half areas).
    pub(super) cost: f32,
    pub(super) left: Aabb,
    pub(super) right: Aabb,
}

/// 2^23: for 0 <= x < 2^22, the low mantissa bits of x + 2^23 are round(x).
pub(super) const ROUND_MAGIC: f32 = 8_388_608.0;
pub(super) const BIN_MASK: u32 = SAH_BINS as u32 - 1;
const _: () = assert!(SAH_BINS.is_power_of_two() && SAH_BINS >= 4);
const _: () = assert!(SMALL_RANGE <= 16, "ranks are read back with a 4-bit mask");

/// Maps doubled centroids to bin indices for one node. Binning and partitioning must
/// agree exactly, so both go through [`Binner::bins`] (the same f32 operations).
/// Bin = round((c - cmin) (bins - 1) / extent): monotone in c, the minimum centroid in
/// bin 0 and the maximum in the last, so a split between them always exists.
/// The rounding is done with [`ROUND_MAGIC`] and a mask rather than a float-to-int
/// cast: the cast's saturation checks cost more than the rest of the binning, and the
/// mask keeps any index (even of a NaN) inside the bins.
pub(super) struct Binner {
    pub(super) cmin: Vec3A,
    pub(super) scale: Vec3A,
}

/// Bins per axis for a range of `n` primitives: [`SAH_BINS`] for large ranges, half as
/// many below [`FEW_BINS_BELOW`] primitives, where the fixed cost of clearing and
/// sweeping the bins is a large share of the work and the split matters less.
pub(super) fn bin_count(n: usize) -> usize {
    if n < FEW_BINS_BELOW {
        SAH_BINS / 2
    } else {
        SAH_BINS
    }
}

impl Binner {
    pub(super) fn new(cbounds: &Aabb, bins: usize) -> Binner {
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
    pub(super) fn bins(&self, c: Vec3A) -> [usize; 3] {
        let x = (c - self.cmin) * self.scale + Vec3A::splat(ROUND_MAGIC);
        let bits: [u32; 4] = bytemuck::cast(x);
        [0, 1, 2].map(|axis| (bits[axis] & BIN_MASK) as usize)
    }
}

/// Bounds and primitive counts of the bins, per axis.
pub(super) type Bins = ([[Aabb; SAH_BINS]; 3], [[u32; SAH_BINS]; 3]);

/// Empty bins: every box [`Aabb::EMPTY`], every count 0.
pub(super) const NO_BINS: Bins = ([[Aabb::EMPTY; SAH_BINS]; 3], [[0; SAH_BINS]; 3]);

/// Ranges of at least this many primitives are binned into two sets of bins, see
/// [`bin_range`].
pub(super) const TWO_BIN_SETS_FROM: usize = 64;

/// Adds the primitives of a range to `bins` (in place: bins returned by value were copied
/// out, a measurable cost). Neighbouring primitives of a range are near each
/// other, so they often fall into the same bin: each one's update then waits for the one
/// before it to be stored (a chain of load, min/max and store per primitive). A large
/// range is therefore binned into two sets, even and odd primitives, merged at the end,
/// so that two chains run at once. Min, max and sums do not depend on the order of
/// finite bounds without -0 ([`PrimRef::new`]), so the bins are the same to the bit.
pub(super) fn bin_range(prims: &[PrimRef], binner: &Binner, bins: &mut Bins, nb: usize) {
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
pub(super) fn merge_bins((bins, counts): &mut Bins, (from, from_counts): &Bins, nb: usize) {
    for axis in 0..3 {
        for k in 0..nb {
            bins[axis][k].grow(&from[axis][k]);
            counts[axis][k] += from_counts[axis][k];
        }
    }
}

/// The binning loop of [`bin_range`], into one set of bins.
#[inline(always)]
pub(super) fn bin_into<'a>(
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
pub(super) fn find_split(prims: &[PrimRef], cbounds: &Aabb, parallel: bool) -> Option<Split> {
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
pub(super) fn partition(
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

pub(super) fn partition_on<const AXIS: usize>(
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
