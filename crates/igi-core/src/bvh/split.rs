//! Early split clipping (Ernst and Greiner, "Early Split Clipping for Bounding Volume
//! Hierarchies", 2007): the references of [`BvhBuilder::Split`], igi's slower-to-build,
//! faster-to-trace alternative to the binned build of whole triangles.
//!
//! A long thin triangle (the conference room's slivers) has a box far larger than
//! itself: every ray through that box tests the triangle for nothing, and the boxes of
//! the nodes above it overlap. Before the binned build, each triangle whose box wastes
//! area (its half area exceeds [`SPLIT_RATIO`] times the triangle's area, by more than
//! [`SPLIT_MIN_WASTE`] of the scene box's half area) is cut in two at the middle of its
//! box's longest axis, each piece (the triangle clipped to one half) keeping the box of
//! that piece; pieces are cut again while they still waste that much, at most
//! [`SPLIT_DEPTH`] times. The builder then sees one reference per piece, each with its
//! triangle's index: a triangle can sit in several leaves, and [`Bvh::tri_order`]
//! repeats it.
//!
//! Answers do not change: a piece's box is padded outward by [`CLIP_PAD`] of the
//! triangle's largest coordinate on each axis (several times the rounding of a clip
//! point) and kept inside its parent's box, so every point of a triangle lies in some
//! piece's box, and the triangle test (on the whole triangle) decides as before.
//! Imperfect visibility (section 4.1 of the paper) does see a difference: it still tests
//! the whole triangle's box, but a segment reaches that test only through a leaf whose
//! piece box it enters, so it finds less false occlusion.

use glam::{Vec3, Vec3A};

use super::build::{par_chunks, Aabb, PrimRef, Vertices};
#[cfg(doc)]
use super::{Bvh, BvhBuilder};

/// A triangle's reference is split while its box's half area exceeds this many times
/// the area of the triangle's part in it. With [`SPLIT_DEPTH`], the best of the ratio
/// and depth pairs measured on the H200 (4/2, 8/3, 4/3 and 16/4; with
/// [`SPLIT_MIN_WASTE`], 4/2 against 4/3 and 4/4).
pub const SPLIT_RATIO: f32 = 4.0;

/// At most this many halvings per triangle: up to 2^SPLIT_DEPTH references.
pub const SPLIT_DEPTH: u32 = 2;

/// Only a box that wastes more than this fraction of the scene box's half area is cut:
/// small slivers are many and cost rays little. On the conference room this cuts far
/// fewer references than the ratio alone (about a sixth more than whole triangles
/// instead of three quarters), and every GPU figure was better; relative to the scene's
/// box, so that the cut does not depend on the scene's units.
pub const SPLIT_MIN_WASTE: f32 = 1e-6;

/// Outward padding of a piece's box, relative to the triangle's largest coordinate on
/// each axis: 2^-19, 16 ulps of that coordinate, several times the error of a clip point
/// p + (q - p) t.
const CLIP_PAD: f32 = 1.0 / 524_288.0;

/// Vertices a piece can have: a triangle gains at most one per cut.
const MAX_POLY: usize = 3 + SPLIT_DEPTH as usize;

/// A convex polygon: a triangle or the piece of one that a few cuts left.
#[derive(Clone, Copy)]
struct Poly {
    v: [Vec3A; MAX_POLY],
    n: usize,
}

impl Poly {
    fn area(&self) -> f32 {
        let mut s = Vec3A::ZERO;
        for i in 1..self.n.saturating_sub(1) {
            s += (self.v[i] - self.v[0]).cross(self.v[i + 1] - self.v[0]);
        }
        0.5 * s.length()
    }

    /// The parts of the polygon on either side of the plane x[axis] = at.
    fn cut(&self, axis: usize, at: f32) -> (Poly, Poly) {
        let empty = Poly {
            v: [Vec3A::ZERO; MAX_POLY],
            n: 0,
        };
        let (mut lo, mut hi) = (empty, empty);
        let push = |p: &mut Poly, x: Vec3A| {
            if p.n < MAX_POLY {
                p.v[p.n] = x;
                p.n += 1;
            }
        };
        for i in 0..self.n {
            let (p, q) = (self.v[i], self.v[(i + 1) % self.n]);
            let (dp, dq) = (p[axis] - at, q[axis] - at);
            if dp <= 0.0 {
                push(&mut lo, p);
            }
            if dp >= 0.0 {
                push(&mut hi, p);
            }
            if (dp < 0.0 && dq > 0.0) || (dp > 0.0 && dq < 0.0) {
                let mut x = p + (q - p) * (dp / (dp - dq));
                x[axis] = at;
                push(&mut lo, x);
                push(&mut hi, x);
            }
        }
        (lo, hi)
    }

    fn bounds(&self) -> Aabb {
        let mut b = Aabb::EMPTY;
        for &p in &self.v[..self.n] {
            b.grow_point(p);
        }
        b
    }
}

/// Early split clipping of the references of whole triangles (`prims[i]`: the box of
/// triangle i, `areas[i]` its area, `bounds`: the box of them all): a triangle that is
/// cut keeps its first piece in its own slot and appends the others, with its index, to
/// `prims` and `ids`.
/// Returns the new box of the doubled centroids. The same on any number of threads:
/// the appended pieces come in triangle order.
pub(super) fn split_references<T: Vertices>(
    prims: &mut Vec<PrimRef>,
    ids: &mut Vec<u32>,
    areas: &[f32],
    bounds: &Aabb,
    tri: &[T],
) -> Aabb {
    let min_waste = SPLIT_MIN_WASTE * bounds.half_area();
    let parts = par_chunks(prims, |start, chunk| {
        let (mut more, mut more_ids) = (vec![], vec![]);
        let mut pieces = vec![];
        let mut cbounds = Aabb::EMPTY;
        for (k, p) in chunk.iter_mut().enumerate() {
            // A cheap test first, without reading the vertices: the whole triangle must
            // waste what split_piece asks of a piece (its area is the one split_piece
            // computes; most triangles stop here).
            let b = Aabb { lo: p.lo, hi: p.hi };
            let i = start + k;
            if wastes(&b, areas[i], min_waste) {
                pieces.clear();
                references_of(*tri[i].vertices(), b, min_waste, &mut pieces);
                *p = pieces[0];
                more.extend_from_slice(&pieces[1..]);
                more_ids.extend(std::iter::repeat_n(i as u32, pieces.len() - 1));
            }
            cbounds.grow_point(p.centroid2());
        }
        for p in &more {
            cbounds.grow_point(p.centroid2());
        }
        (more, more_ids, cbounds)
    });
    let mut cbounds = Aabb::EMPTY;
    for (more, more_ids, c) in parts {
        prims.extend(more);
        ids.extend(more_ids);
        cbounds.grow(&c);
    }
    cbounds
}

/// Whether a box `b` around a piece of triangle of area `area` wastes enough to be cut:
/// more than [`SPLIT_RATIO`] times the area, by more than `min_waste` (false for a NaN
/// area).
fn wastes(b: &Aabb, area: f32, min_waste: f32) -> bool {
    let waste = b.half_area() - SPLIT_RATIO * area;
    waste > 0.0 && waste > min_waste
}

/// Appends the references of one triangle whose box `b` is that of its finite vertices
/// (`min_waste`: the half area a box must waste to be cut, see [`SPLIT_MIN_WASTE`]).
fn references_of(t: [Vec3; 3], b: Aabb, min_waste: f32, out: &mut Vec<PrimRef>) {
    let v = t.map(Vec3A::from);
    // A triangle with a non-finite vertex has a point box at the origin (see `build`)
    // and is never cut.
    if !(v[0].is_finite() && v[1].is_finite() && v[2].is_finite()) {
        out.push(PrimRef::new(b.lo, b.hi));
        return;
    }
    let pad = v[0].abs().max(v[1].abs()).max(v[2].abs()) * CLIP_PAD;
    let mut poly = Poly {
        v: [Vec3A::ZERO; MAX_POLY],
        n: 3,
    };
    poly.v[..3].copy_from_slice(&v);
    split_piece(&poly, b, pad, min_waste, SPLIT_DEPTH, out);
}

/// Appends the references of one piece whose (padded) box is `b`.
fn split_piece(
    poly: &Poly,
    b: Aabb,
    pad: Vec3A,
    min_waste: f32,
    depth: u32,
    out: &mut Vec<PrimRef>,
) {
    if depth == 0 || poly.n < 3 || !wastes(&b, poly.area(), min_waste) {
        out.push(PrimRef::new(b.lo, b.hi));
        return;
    }
    let e = b.hi - b.lo;
    let axis = if e.x >= e.y && e.x >= e.z {
        0
    } else if e.y >= e.z {
        1
    } else {
        2
    };
    let at = 0.5 * (b.lo[axis] + b.hi[axis]);
    let (lo_part, hi_part) = poly.cut(axis, at);
    if lo_part.n < 3 || hi_part.n < 3 {
        // The piece only touches the plane in rounded arithmetic, but the triangle may
        // still reach past it by less than a rounding error: keep the piece whole.
        out.push(PrimRef::new(b.lo, b.hi));
        return;
    }
    for (part, below) in [(lo_part, true), (hi_part, false)] {
        let tight = part.bounds();
        let (mut plo, mut phi) = (tight.lo - pad, tight.hi + pad);
        // Never past the cut: the clip points lie on the plane itself.
        if below {
            phi[axis] = phi[axis].min(at);
        } else {
            plo[axis] = plo[axis].max(at);
        }
        let piece = Aabb {
            lo: plo.max(b.lo),
            hi: phi.min(b.hi),
        };
        split_piece(&part, piece, pad, min_waste, depth - 1, out);
    }
}
