//! Tests of the two SAH sweeps (binned and exact over a small range) against the sweep as
//! written first: one axis after another over sorted centroids.

use super::binning::{bin_count, bin_into, Binner, NO_BINS};
use super::*;
use crate::bvh::SAH_BINS;
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
            let bits = |b: &Aabb| [b.lo.to_array(), b.hi.to_array()].map(|v| v.map(f32::to_bits));
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
