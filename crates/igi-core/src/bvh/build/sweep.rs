//! The exact SAH sweep of a small range over its centroids sorted on each axis, and the
//! three boxes grown side by side that it and the binned sweep score planes with.

use std::mem::MaybeUninit;

use glam::Vec3A;

use super::binning::ROUND_MAGIC;
use super::{Aabb, PrimRef, SMALL_RANGE};

/// Exact SAH sweep of a small range (2..=SMALL_RANGE primitives): for each axis the
/// primitives sorted by centroid, every split between neighbours in that order.
pub(super) struct SmallSweep {
    pub(super) n: usize,
    pub(super) axis: usize,
    /// Split after `at` + 1 primitives of `order[axis]`.
    pub(super) at: usize,
    pub(super) cost: f32,
    pub(super) order: [[u8; SMALL_RANGE]; 3],
}

impl SmallSweep {
    /// The sweep of a range of 2..=SMALL_RANGE primitives: one copy of the code per size,
    /// so that every loop has a fixed count and unrolls, and the best split is picked
    /// without branches (fewer instructions a build, the same trees).
    pub(super) fn new(prims: &[PrimRef]) -> SmallSweep {
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
    pub(super) fn pair(prims: &[PrimRef]) -> SmallSweep {
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
    pub(super) fn of<const N: usize>(prims: &[PrimRef]) -> SmallSweep {
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
    pub(super) fn apply(
        &self,
        prims: &mut [PrimRef],
        ids: &mut [u32],
    ) -> (usize, Aabb, Aabb, Aabb, Aabb) {
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
/// of a small range ([`SmallSweep::new`]) or over their bins ([`find_split`](super::binning::find_split)) run in
/// step, and each step takes the three half areas at once (fewer instructions a build
/// for the same trees).
pub(super) struct Sweep3 {
    pub(super) lo: [Vec3A; 3],
    pub(super) hi: [Vec3A; 3],
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
    pub(super) fn grow(
        &mut self,
        prims: &[PrimRef],
        order: &[[u8; SMALL_RANGE]; 3],
        i: usize,
    ) -> Vec3A {
        for k in 0..3 {
            let p = &prims[order[k][i] as usize];
            self.lo[k] = self.lo[k].min(p.lo);
            self.hi[k] = self.hi[k].max(p.hi);
        }
        self.half_areas()
    }

    /// Grows box k by `boxes[k]` (see [`Sweep3::grow`]). Not one generic method for
    /// both: with the primitives' indexing outside the loop, or through a closure, the
    /// build took more instructions.
    #[inline]
    pub(super) fn grow_boxes(&mut self, boxes: [&Aabb; 3]) -> Vec3A {
        for (k, b) in boxes.iter().enumerate() {
            self.lo[k] = self.lo[k].min(b.lo);
            self.hi[k] = self.hi[k].max(b.hi);
        }
        self.half_areas()
    }

    /// The three boxes' half areas (lane k: box k's), computed as [`Aabb::half_area`]
    /// computes them.
    #[inline]
    pub(super) fn half_areas(&self) -> Vec3A {
        let e = |k: usize| (self.hi[k] - self.lo[k]).max(Vec3A::ZERO);
        let t = glam::Mat3A::from_cols(e(0), e(1), e(2)).transpose();
        let (ex, ey, ez) = (t.x_axis, t.y_axis, t.z_axis);
        ex * ey + ey * ez + ez * ex
    }
}
