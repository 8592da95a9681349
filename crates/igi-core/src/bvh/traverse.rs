//! CPU traversal, the twin of `traverse.wgsl`: same ray setup, same box and triangle tests,
//! same visiting order, so that the CPU answers what the GPU answers (up to the rounding of
//! division, which WGSL allows to be 2.5 ulp, and of fused multiply-adds, which GPU
//! compilers may form; see the notes on each test).

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use super::{Bvh, MAX_DEPTH};

/// `Hit::tri` of a miss on the GPU (the CPU returns `None`).
pub const NO_HIT: u32 = 0xffff_ffff;

/// Direction components smaller than this in magnitude count as zero for the box test:
/// the ray is parallel to that slab ("parallel axis").
///
/// WGSL leaves the result of operations on infinities and NaNs indeterminate, so the IEEE
/// trick of an infinite reciprocal (and the 0 * inf = NaN it gives for an origin on a
/// slab plane, which pbrt's comparison order ignores) cannot be relied on in the shader.
/// A parallel axis gets the finite reciprocal [`PARALLEL_INV`] instead. Its slab
/// distances (min - o) * 1e30 and (max - o) * 1e30 are right for an origin clearly inside
/// or outside the slab, but an origin on a plane (the ray runs inside the closed slab, as
/// rays along a wall do) gives an exit distance of 0: the box would be missed. So the
/// planes of a parallel axis are measured from an origin moved by the slack
/// s = (|o| + 1) [`PARALLEL_SLACK`] (a relative 2^-20, far above the rounding of o + s
/// and of (o + s) 1e30): entry planes from o + s, exit planes from o - s (folded into
/// [`TraceRay::c_min`] and `c_max`). The ray then tests the slab [min - s, max + s]:
/// inside it the entry distance is <= -s 1e30 and the exit distance >= s 1e30 >= 9.5e23,
/// beyond every box a ray can reach unless its direction is shorter than 1e-24 x the
/// scene's extent and its length unbounded; outside it the box is missed, or visited for nothing when the origin
/// lies within 1e-23 of the widened slab (conservative). This costs the slab test
/// nothing per box; the select that replaced exit distances >= 0 of parallel axes by a
/// large value did, a measurable share of every walk. Boxes only get wider along
/// parallel axes, so the answers stay those of the exact test. No NaN or
/// infinity arises from finite data (coordinates up to ~1e7); the only infinities are
/// those of the empty child's point box at +inf, whose distances are +-inf and only make
/// it miss.
///
/// A component below 1e-30 that is not exactly 0 moves the ray by less than 1e-30 t along
/// its axis; treating it as 0 can only matter for an origin within 1e-23 of a box plane.
pub(crate) const DIR_EPS: f32 = 1e-30;
/// Reciprocal used for parallel axes (see [`DIR_EPS`]).
pub(crate) const PARALLEL_INV: f32 = 1e30;
/// Relative widening of the slab of a parallel axis (see [`DIR_EPS`]): 2^-20.
pub(crate) const PARALLEL_SLACK: f32 = 1.0 / 1_048_576.0;

/// Relative pad of the slab test's per-ray offsets: 2^-21.
///
/// [`box_span`] computes the distance to a plane b of axis k as one fused multiply-add,
/// t = fma(b, inv_k, c) with c = -o_k inv_k precomputed per ray, instead of
/// (b - o_k) inv_k: a subtraction fewer for each of a box's six planes (the walks are
/// bound by the arithmetic of their box tests). The
/// exact (b - o_k) inv_k needs no absolute error bound, since b - o_k is exact where b
/// and o_k are close (Sterbenz). The fma form carries absolute errors that do not shrink
/// with t: the rounding of o_k inv_k and of c's pad, each at most 2^-24 |o_k inv_k|, and
/// one more of 2^-24 (|o_k inv_k| + |t|) where a compiler evaluates the fma as a product
/// and a sum. So c moves each plane outward by 2^-21 |o_k inv_k|, 8 times 2^-24 (entry
/// planes down, exit planes up, by the sign of inv_k), and the relative errors (the
/// reciprocal, the fma's own rounding) stay covered by [`BOX_TFAR_SCALE`]. In space the
/// pad widens a box by 2^-21 |o_k| along axis k, a few ulps of the origin's coordinate:
/// in practice the walk visits the boxes the exact test would, and it can only ever
/// visit more, never fewer (the answers are the triangle tests'). Parallel axes get no pad: their
/// planes are 1e30 (b - o -+ s), whose rounding errors (2^-24 1e30 |o|) the slack
/// (2^-20 1e30 (|o| + 1)) covers at least 8 times over.
pub(crate) const SLAB_PAD: f32 = 1.0 / 2_097_152.0;

/// Conservative rounding factor for the far end of a slab: 1 + 2 gamma(3) with
/// gamma(n) = n eps / (1 - n eps), eps = 2^-24 (pbrt-v3/v4 `Bounds3::IntersectP`, Ize
/// 2013). The slab distances fma(b, inv, c) carry at most three relative roundings (the
/// reciprocal, the product and the sum where the fma is not fused; [`SLAB_PAD`] takes the
/// absolute ones), so scaling t_far by this factor keeps every box the exact arithmetic
/// would hit. 1 + 3 ulp(1) = 1.00000035762786865234375 is the f32 nearest to
/// 1 + 2 gamma(3) = 1.0000003576...; traverse.wgsl writes the same value as a literal.
/// The bound assumes a correctly rounded reciprocal (CPU, lavapipe); WGSL allows 2.5 ulp
/// for division, which would need 1 + 2 gamma(7) to be strictly covered.
pub(crate) const BOX_TFAR_SCALE: f32 = 1.0 + 3.0 * f32::EPSILON;

/// Absolute pad of every plane of a segment walk ([`trace_segment`], tmax = 1): 2^-21, in
/// place of [`BOX_TFAR_SCALE`].
///
/// The scale covers the slab distances' relative errors, at most gamma(3) |t| on either
/// end (see [`BOX_TFAR_SCALE`]), for rays of any length; it costs a product per box. A
/// segment only asks about t in [0, 1], where those errors are at most gamma(3) < 2^-22.4:
/// moving every entry plane down and every exit plane up by 2^-21 in t (added to
/// [`SLAB_PAD`]'s per-ray offsets, so free per box) covers them. Where the exact slab meets
/// [0, 1] (entry e <= 1 and e <= exit x), the computed entry is at most e (for e <= 1 the
/// pad exceeds its error), and the computed exit at least min(x, 1) (for x <= 2.6 the pad
/// exceeds its error; beyond, the computed exit is still above 1): the box is hit. So a
/// segment walk visits every box the exact test would, as the scaled walk does, and both
/// answer what the triangle tests answer. It does not hold for long rays (a ray of tmax
/// 3.4e38 would need a pad that opens every box), which keep the scale ([`trace_any`]).
/// The renderer's shadow rays are all segments (`shadow_segment`); their walk made
/// canonical frames faster on the H200.
pub(crate) const SEGMENT_PAD: f32 = 1.0 / 2_097_152.0;

/// Wächter-Binder offset: distance below which coordinates get an absolute offset.
const OFFSET_ORIGIN: f32 = 1.0 / 32.0;
/// Wächter-Binder offset: absolute offset (times the normal) near the origin.
const OFFSET_FLOAT_SCALE: f32 = 1.0 / 65536.0;
/// Wächter-Binder offset: ulps (times the normal) added to the bits of each coordinate.
const OFFSET_INT_SCALE: f32 = 256.0;

/// A hit of the BVH traversal; `#[repr(C)]` like `struct Hit` of `traverse.wgsl`
/// (t: bytes 0..4, tri: 4..8, u: 8..12, v: 12..16).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct Hit {
    /// Ray parameter: the hit point is origin + t dir.
    pub t: f32,
    /// BVH slot of the triangle ([`Bvh::tri_order`] maps it to the input index).
    pub tri: u32,
    /// Barycentric coordinate of vertex 1 (`v[1]`) at the hit point.
    pub u: f32,
    /// Barycentric coordinate of vertex 2 (`v[2]`); vertex 0 has 1 - u - v.
    pub v: f32,
}

/// Per-ray data, computed once (`make_ray` in WGSL).
#[derive(Clone, Copy, Debug)]
pub(crate) struct TraceRay {
    /// The origin in the Woop axes: (origin[kx], origin[ky], origin[kz]).
    origin_k: Vec3,
    inv_dir: Vec3,
    /// Woop et al.: kz is the axis of the largest |dir| component, (kx, ky) the other two
    /// in an order that keeps the triangles' winding.
    kx: usize,
    ky: usize,
    kz: usize,
    /// Shear constants (Sx, Sy, Sz) = (dir[kx] / dir[kz], dir[ky] / dir[kz], 1 / dir[kz]).
    shear: Vec3,
    /// The slab test's offset for the planes of a box's `min` corner: a plane b is
    /// crossed at t = fma(b, inv_dir, c) (see [`box_span`] and [`SLAB_PAD`]).
    c_min: Vec3,
    /// The same for the planes of the `max` corner.
    c_max: Vec3,
}

impl TraceRay {
    /// None for a zero direction (such a ray hits nothing). `t_pad` moves every plane
    /// outward by that much in t: [`SEGMENT_PAD`] for segment walks, else 0.
    pub(crate) fn new(origin: Vec3, dir: Vec3, t_pad: f32) -> Option<TraceRay> {
        if dir.x == 0.0 && dir.y == 0.0 && dir.z == 0.0 {
            return None;
        }
        let parallel = [0, 1, 2].map(|k| dir[k].abs() < DIR_EPS);
        let inv = |k: usize| {
            if parallel[k] {
                PARALLEL_INV
            } else {
                1.0 / dir[k]
            }
        };
        let inv_dir = Vec3::new(inv(0), inv(1), inv(2));
        let a = dir.abs();
        // Ties go to the lower axis; the WGSL uses the same comparisons.
        let mut kz = 0;
        if a.y > a.x {
            kz = 1;
        }
        if a.z > a[kz] {
            kz = 2;
        }
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        if dir[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let shear = Vec3::new(dir[kx] / dir[kz], dir[ky] / dir[kz], 1.0 / dir[kz]);
        let slack = Vec3::from_array([0, 1, 2].map(|k| {
            if parallel[k] {
                (origin[k].abs() + 1.0) * PARALLEL_SLACK
            } else {
                0.0
            }
        }));
        let oi = origin * inv_dir;
        let pad = Vec3::from_array([0, 1, 2].map(|k| {
            if parallel[k] {
                0.0
            } else {
                oi[k].abs() * SLAB_PAD + t_pad
            }
        }));
        // The min corner's planes are the entry planes where inv_dir > 0 (parallel axes
        // included: measured from o + s, see DIR_EPS) and move down by the pad; where
        // inv_dir < 0 they are the exit planes and move up. The max corner's the other
        // way (exit planes of parallel axes from o - s).
        let positive = inv_dir.cmpgt(Vec3::ZERO);
        Some(TraceRay {
            c_min: Vec3::select(positive, -(origin + slack) * inv_dir - pad, pad - oi),
            c_max: Vec3::select(positive, -(origin - slack) * inv_dir + pad, -oi - pad),
            origin_k: Vec3::new(origin[kx], origin[ky], origin[kz]),
            inv_dir,
            kx,
            ky,
            kz,
            shear,
        })
    }

    /// The distances to the planes of a box's min corner and of its max corner: one fused
    /// multiply-add each with the padded offsets (see [`box_span`] and [`SLAB_PAD`]).
    #[inline]
    pub(crate) fn plane_distances(&self, min: [f32; 3], max: [f32; 3]) -> (Vec3, Vec3) {
        (
            Vec3::from(min).mul_add(self.inv_dir, self.c_min),
            Vec3::from(max).mul_add(self.inv_dir, self.c_max),
        )
    }
}

/// Slab test: the (entry, exit) distances of a box clipped to [0, tmax]; the box is hit
/// when entry <= exit. Each axis enters at the nearer of its two planes and leaves at the
/// farther (min and max of the two distances; with a choice by the direction's sign
/// instead, the NVIDIA driver spilled 12 bytes a thread of the GPU's gather to shared
/// memory and the gathers ran slower). So the child
/// no ray may hit is a point box at +inf ([`super::BvhChild::EMPTY`]), not an inverted
/// one, and the walks' tmax is finite ([`finite_tmax`]). Each plane's distance is one
/// fused multiply-add with the ray's padded offsets (see [`SLAB_PAD`]). Parallel axes
/// need no case of their own: their offsets hold the moved origins (see [`DIR_EPS`]).
/// The far end is scaled by `far_scale`: [`BOX_TFAR_SCALE`], or 1 for a segment walk,
/// whose planes are padded instead ([`SEGMENT_PAD`]).
///
/// The minima and maxima are taken on the distances' bits read as signed integers (the
/// GPU's integer minimum and maximum made the walks faster on the H200 than float
/// ones). Non-negative floats order like their bits;
/// negative ones come below all of them, in reverse order among themselves, and -0 is
/// the lowest of all. The reverse order never changes an answer: an axis whose two
/// distances are both negative gives the entry a negative candidate, which the clamp to
/// 0 discards whichever it is, and the exit a negative one, which misses the box (the
/// entry is >= 0) whichever it is. -0 is the one exception: an exit of -0 (the ray leaves
/// a slab at its origin) is picked over a negative one on another axis, so the box is
/// kept where floats miss it (at worst a visit more), and a negative plane is picked over
/// -0 as a slab's farther one, so the box is missed where floats keep it for t = 0 alone
/// (no hit with t > 0 lies in it: every plane is padded outward). Wherever the box is
/// hit, the entry and the exit are the floats'.
#[inline]
pub(super) fn box_span(
    min: [f32; 3],
    max: [f32; 3],
    r: &TraceRay,
    tmax: f32,
    far_scale: f32,
) -> (f32, f32) {
    let bits = |v: Vec3| v.to_array().map(|t| t.to_bits() as i32);
    let (t0, t1) = r.plane_distances(min, max);
    let (t0, t1) = (bits(t0), bits(t1));
    let tn: [i32; 3] = std::array::from_fn(|k| t0[k].min(t1[k]));
    let tf: [i32; 3] = std::array::from_fn(|k| t0[k].max(t1[k]));
    let near = tn[0].max(tn[1]).max(tn[2].max(0));
    let far = tf[0].min(tf[1]).min(tf[2]);
    let float = |b: i32| f32::from_bits(b as u32);
    (float(near), (float(far) * far_scale).min(tmax))
}

/// The entry distance (>= 0) of a box hit within [0, tmax], -1 otherwise.
#[inline]
fn box_near(min: [f32; 3], max: [f32; 3], r: &TraceRay, tmax: f32) -> f32 {
    let (near, far) = box_span(min, max, r, tmax, BOX_TFAR_SCALE);
    if near <= far {
        near
    } else {
        -1.0
    }
}

/// Whether a box is hit within [0, tmax] (any hit needs no distance).
#[inline]
pub(super) fn box_hit(
    min: [f32; 3],
    max: [f32; 3],
    r: &TraceRay,
    tmax: f32,
    far_scale: f32,
) -> bool {
    let (near, far) = box_span(min, max, r, tmax, far_scale);
    near <= far
}

/// Watertight ray-triangle test (Woop, Benthin, Wald, JCGT 2(1), 2013), two-sided.
/// Returns (t, u, v) for a hit with 0 < t < tmax; u, v weigh v1 and v2. The triangle
/// comes as its rows in the ray's Woop axes ([`woop_rows`]): `xr` holds the kx
/// coordinates of v0, v1 and v2, `yr` the ky and `zr` the kz ones, so that the test
/// needs no permutation of its own (the GPU reads them from [`Bvh::tri_rows`] by index;
/// the values are those of the vertex form, (v - o)[kx] = v[kx] - o[kx]).
///
/// Watertight: the vertices are translated to the ray origin and sheared so that the ray
/// becomes the +z axis; a shared vertex gets the same 2D coordinates in every triangle,
/// and the edge functions of a shared edge are the same two rounded products compared in
/// opposite order. Rounding is monotone, so a product comparison never inverts the exact
/// sign; it can only turn it into a tie, and ties (edge and vertex hits) count as hits.
/// Hence a ray through a shared edge or vertex hits at least one of the triangles (it
/// may hit both: a double hit, never a leak).
///
/// The signs are taken from comparisons of the products instead of the sign of their
/// difference because a GPU compiler may fuse `p1 - p2` into fma(a, b, -p2), whose sign
/// can disagree with the neighbour's. The paper's double-precision re-test of zero edge
/// functions is omitted: it only decides exact ties, turning the possible double hit at
/// an edge into a single one; without it a ray may count as hitting a triangle it misses
/// by one rounding of the 2D products (a relative ~1e-7 of the triangle's extent seen
/// from the origin), which no pass of igi can tell apart.
#[inline]
fn intersect_triangle(r: &TraceRay, [xr, yr, zr]: [Vec3; 3], tmax: f32) -> Option<(f32, f32, f32)> {
    // Per row the three vertices moved to the origin: dx = (a[kx], b[kx], c[kx]) of the
    // translated vertices a, b, c, and so on.
    let dx = xr - r.origin_k.x;
    let dy = yr - r.origin_k.y;
    let dz = zr - r.origin_k.z;
    let (sx, sy, sz) = (r.shear.x, r.shear.y, r.shear.z);
    let ax = dx.x - sx * dz.x;
    let ay = dy.x - sy * dz.x;
    let bx = dx.y - sx * dz.y;
    let by = dy.y - sy * dz.y;
    let cx = dx.z - sx * dz.z;
    let cy = dy.z - sy * dz.z;
    // Edge functions U = cx by - cy bx (weight of v0), V (v1), W (v2), as product pairs.
    let (u1, u2) = (cx * by, cy * bx);
    let (v1_, v2_) = (ax * cy, ay * cx);
    let (w1, w2) = (bx * ay, by * ax);
    let inside = (u1 >= u2 && v1_ >= v2_ && w1 >= w2) || (u1 <= u2 && v1_ <= v2_ && w1 <= w2);
    if !inside {
        return None;
    }
    let uu = u1 - u2;
    let vv = v1_ - v2_;
    let ww = w1 - w2;
    let det = uu + vv + ww;
    if det == 0.0 {
        return None; // the ray lies in the triangle's plane, or the triangle is degenerate
    }
    let az = sz * dz.x;
    let bz = sz * dz.y;
    let cz = sz * dz.z;
    let tt = uu * az + vv * bz + ww * cz;
    let rcp = 1.0 / det;
    let t = tt * rcp;
    if t > 0.0 && t < tmax {
        Some((t, vv * rcp, ww * rcp))
    } else {
        None
    }
}

/// The rows of BVH slot `slot` in the ray's Woop axes, read by index as the GPU does.
#[inline]
fn slot_rows(bvh: &Bvh, slot: u32, r: &TraceRay) -> [Vec3; 3] {
    let i = 3 * slot as usize;
    [r.kx, r.ky, r.kz].map(|k| Vec3::from_slice(&bvh.tri_rows[i + k].0[..3]))
}

/// The rows of a triangle given by its vertices, in the ray's Woop axes.
#[inline]
fn woop_rows(r: &TraceRay, [v0, v1, v2]: &[Vec3; 3]) -> [Vec3; 3] {
    [r.kx, r.ky, r.kz].map(|k| Vec3::new(v0[k], v1[k], v2[k]))
}

/// Tests the triangles of a leaf in slot order; keeps the first of equal-distance hits.
#[inline]
fn leaf_closest(bvh: &Bvh, first: u32, count: u32, r: &TraceRay, hit: &mut Hit) {
    for slot in first..first + count {
        if let Some((t, u, v)) = intersect_triangle(r, slot_rows(bvh, slot, r), hit.t) {
            *hit = Hit { t, tri: slot, u, v };
        }
    }
}

#[inline]
fn leaf_any(
    bvh: &Bvh,
    first: u32,
    count: u32,
    r: &TraceRay,
    tmax: f32,
    counter: &mut impl WalkCounter,
) -> bool {
    (first..first + count).any(|slot| {
        counter.triangle();
        intersect_triangle(r, slot_rows(bvh, slot, r), tmax).is_some()
    })
}

/// The two children of a node as (entry distance, index, count), child a first; a
/// missed child has distance -1.
#[inline]
fn children(node: &super::BvhNode, r: &TraceRay, tmax: f32) -> [(f32, u32, u32); 2] {
    let ta = box_near(node.a_min, node.a_max, r, tmax);
    let tb = box_near(node.b_min, node.b_max, r, tmax);
    [
        (ta, node.a_index, node.a_count),
        (tb, node.b_index, node.b_count),
    ]
}

/// The walks' tmax: an infinite one becomes f32::MAX. The empty child's point box at
/// +inf ([`super::BvhChild::EMPTY`]) is entered at +inf by the rays heading its way, and
/// only a far end of +inf could reach it. The GPU walks never see an infinity (WGSL has
/// none, and their callers pass at most 3.4e38); only a hit at t = f32::MAX is lost.
#[inline]
fn finite_tmax(tmax: f32) -> f32 {
    tmax.min(f32::MAX)
}

/// [`children`], nearer first (ties: child a first; a missed child goes second).
#[inline]
fn ordered(node: &super::BvhNode, r: &TraceRay, tmax: f32) -> [(f32, u32, u32); 2] {
    let [a, b] = children(node, r, tmax);
    if b.0 >= 0.0 && (a.0 < 0.0 || b.0 < a.0) {
        [b, a]
    } else {
        [a, b]
    }
}

/// Closest hit: visits the nearer child first; leaf children are tested as soon as their
/// box is hit, interior ones are descended into (the nearer) or pushed (the farther).
/// Boxes are tested against the current closest t, so hits found prune the rest.
pub(crate) fn trace_closest(bvh: &Bvh, origin: Vec3, dir: Vec3, tmax: f32) -> Option<Hit> {
    let r = TraceRay::new(origin, dir, 0.0)?;
    let mut hit = Hit {
        t: finite_tmax(tmax),
        tri: NO_HIT,
        u: 0.0,
        v: 0.0,
    };
    let mut stack = [0u32; MAX_DEPTH as usize];
    let mut sp = 0usize;
    let mut node = 0u32;
    loop {
        let n = &bvh.nodes[node as usize];
        let [c0, c1] = ordered(n, &r, hit.t);
        let mut next = NO_HIT;
        if c0.0 >= 0.0 {
            if c0.2 > 0 {
                leaf_closest(bvh, c0.1, c0.2, &r, &mut hit);
            } else {
                next = c0.1;
            }
        }
        // Re-check the far child: a leaf of the near child may have moved hit.t closer.
        if c1.0 >= 0.0 && c1.0 <= hit.t {
            if c1.2 > 0 {
                leaf_closest(bvh, c1.1, c1.2, &r, &mut hit);
            } else if next == NO_HIT {
                next = c1.1;
            } else {
                stack[sp] = c1.1;
                sp += 1;
            }
        }
        if next == NO_HIT {
            if sp == 0 {
                break;
            }
            sp -= 1;
            next = stack[sp];
        }
        node = next;
    }
    (hit.tri != NO_HIT).then_some(hit)
}

/// Any hit: the walk of [`trace_closest`] without pruning and in fixed child order (a,
/// then b: the nearer-first order made the GPU's frames slower; the builder makes a the
/// likelier occluder per unit of work),
/// returning at the first triangle hit with 0 < t < tmax. For rays of any length: the
/// far ends are scaled by [`BOX_TFAR_SCALE`].
pub(crate) fn trace_any(bvh: &Bvh, origin: Vec3, dir: Vec3, tmax: f32) -> bool {
    walk_any(bvh, origin, dir, tmax, 0.0, BOX_TFAR_SCALE, &mut ())
}

/// Whether the segment from origin to origin + dir is occluded (a triangle hit with 0 < t
/// < 1): the walk of [`trace_any`] with the planes padded by [`SEGMENT_PAD`] instead of
/// the far ends scaled (`trace_segment` of traverse.wgsl, which every shadow ray of the
/// renderer takes). Both walks visit every box the exact segment crosses, so they answer
/// alike (and as a test of every triangle would) except for a triangle test whose
/// rounding alone decides a hit within a few ulps of t = 0 or 1 in a box that only one
/// of them visits.
pub(crate) fn trace_segment(bvh: &Bvh, origin: Vec3, dir: Vec3) -> bool {
    walk_any(bvh, origin, dir, 1.0, SEGMENT_PAD, 1.0, &mut ())
}

/// What an any-hit walk did (tests and measurements count steps with it; `()` counts
/// nothing and compiles away).
pub(crate) trait WalkCounter {
    fn node(&mut self);
    fn triangle(&mut self);
}

impl WalkCounter for () {
    #[inline(always)]
    fn node(&mut self) {}
    #[inline(always)]
    fn triangle(&mut self) {}
}

/// Nodes visited and triangles tested.
#[cfg(test)]
impl WalkCounter for (u32, u32) {
    fn node(&mut self) {
        self.0 += 1;
    }
    fn triangle(&mut self) {
        self.1 += 1;
    }
}

/// [`trace_segment`] counting its steps: (answer, nodes visited, triangles tested).
#[cfg(test)]
pub(crate) fn trace_segment_counted(bvh: &Bvh, origin: Vec3, dir: Vec3) -> (bool, u32, u32) {
    let mut steps = (0u32, 0u32);
    let hit = walk_any(bvh, origin, dir, 1.0, SEGMENT_PAD, 1.0, &mut steps);
    (hit, steps.0, steps.1)
}

/// The walk of [`trace_any`] and [`trace_segment`] (`walk_any` of traverse.wgsl), telling
/// `counter` of each node and triangle test: every plane padded by `t_pad`, every far end
/// scaled by `far_scale`.
#[inline]
fn walk_any(
    bvh: &Bvh,
    origin: Vec3,
    dir: Vec3,
    tmax: f32,
    t_pad: f32,
    far_scale: f32,
    counter: &mut impl WalkCounter,
) -> bool {
    let Some(r) = TraceRay::new(origin, dir, t_pad) else {
        return false;
    };
    let tmax = finite_tmax(tmax);
    let mut stack = [0u32; MAX_DEPTH as usize];
    let mut sp = 0usize;
    let mut node = 0u32;
    loop {
        counter.node();
        let n = &bvh.nodes[node as usize];
        let mut next = NO_HIT;
        if box_hit(n.a_min, n.a_max, &r, tmax, far_scale) {
            if n.a_count > 0 {
                if leaf_any(bvh, n.a_index, n.a_count, &r, tmax, counter) {
                    return true;
                }
            } else {
                next = n.a_index;
            }
        }
        if box_hit(n.b_min, n.b_max, &r, tmax, far_scale) {
            if n.b_count > 0 {
                if leaf_any(bvh, n.b_index, n.b_count, &r, tmax, counter) {
                    return true;
                }
            } else if next == NO_HIT {
                next = n.b_index;
            } else {
                stack[sp] = n.b_index;
                sp += 1;
            }
        }
        if next == NO_HIT {
            if sp == 0 {
                return false;
            }
            sp -= 1;
            next = stack[sp];
        }
        node = next;
    }
}

/// Closest hit over all triangles with the same triangle test as the BVH (the reference
/// of the tests): (index, t) of the first triangle, in slice order, at the smallest t in
/// (0, tmax).
pub fn brute_force_closest(
    triangles: &[[Vec3; 3]],
    origin: Vec3,
    dir: Vec3,
    tmax: f32,
) -> Option<(u32, f32)> {
    let r = TraceRay::new(origin, dir, 0.0)?;
    let mut best = None;
    let mut t_best = tmax;
    for (i, tri) in triangles.iter().enumerate() {
        if let Some((t, _, _)) = intersect_triangle(&r, woop_rows(&r, tri), t_best) {
            best = Some((i as u32, t));
            t_best = t;
        }
    }
    best
}

/// Whether any triangle is hit with 0 < t < tmax, with the BVH's triangle test.
pub fn brute_force_any(triangles: &[[Vec3; 3]], origin: Vec3, dir: Vec3, tmax: f32) -> bool {
    let Some(r) = TraceRay::new(origin, dir, 0.0) else {
        return false;
    };
    triangles
        .iter()
        .any(|tri| intersect_triangle(&r, woop_rows(&r, tri), tmax).is_some())
}

/// Origin for a ray leaving a surface at `p` (Wächter and Binder, "A Fast and Robust
/// Method for Avoiding Self-Intersection", Ray Tracing Gems, ch. 6).
///
/// `n` is the unit geometric normal on the side the ray leaves to (flip it for rays
/// going into the other side). Each coordinate moves along n by 256 n_i ulps of itself
/// (integer arithmetic on its bits), so the offset grows with the coordinate's magnitude
/// like the rounding error of the hit point does; coordinates within 1/32 of 0, whose
/// ulps are too small, move by n_i / 65536 instead. The bits match `offset_ray_origin`
/// of `traverse.wgsl` exactly (truncating f32 -> i32 conversion, wrapping i32 add).
///
/// Then the point moves `floor` further along n ([`offset_floor`] of the scene): the
/// offset above scales with the hit point, but the triangle test's error scales with the
/// distance of a triangle's vertices from the ray origin, up to the scene's size. A point
/// whose coordinates are small while its surface is huge (the conference room's floor:
/// two triangles 2,600 units wide at y = -1.57) was moved 3e-5 off a plane that a test
/// from across the room places with an error of ~1e-4: a CPU check against an f64 test
/// found a few percent of a frame's VPL shadow rays occluded by the surface at one of
/// their ends, none with the floor.
pub fn offset_ray_origin(p: Vec3, n: Vec3, floor: f32) -> Vec3 {
    let f = |p: f32, n: f32| {
        if p.abs() < OFFSET_ORIGIN {
            p + OFFSET_FLOAT_SCALE * n
        } else {
            let of = (OFFSET_INT_SCALE * n) as i32;
            let of = if p < 0.0 { of.wrapping_neg() } else { of };
            f32::from_bits((p.to_bits() as i32).wrapping_add(of) as u32)
        }
    };
    Vec3::new(f(p.x, n.x), f(p.y, n.y), f(p.z, n.z)) + floor * n
}

/// The floor's size in ulps of the scene's largest coordinate magnitude (see
/// [`offset_floor`]).
pub const OFFSET_FLOOR_ULPS: f32 = 32.0;

/// The least distance a ray origin moves off its surface ([`offset_ray_origin`]) in a
/// scene whose coordinates lie in [lo, hi]: [`OFFSET_FLOOR_ULPS`] ulps (2^-24 each) of
/// the largest coordinate magnitude M, which bounds the translated vertices' magnitude
/// the triangle test's rounding scales with (|v - o| <= 2 M; its error bound, pbrt-v4's
/// after Woop et al., is a few gamma(5) of that). Rounded up to a power of two, so that
/// floor x n is exact and a GPU that fuses the multiply-add gives the CPU's bits. For the
/// conference room (M = 1,653) it is 2^-8 = 0.0039 units; 0 for an empty scene.
pub fn offset_floor(lo: Vec3, hi: Vec3) -> f32 {
    let m = lo.abs().max(hi.abs()).max_element();
    let x = OFFSET_FLOOR_ULPS * (f32::EPSILON * 0.5) * m;
    if !(x.is_finite() && x > 0.0) {
        return 0.0;
    }
    f32::from_bits((x.to_bits() + 0x007f_ffff) & 0xff80_0000)
}

/// The shadow ray of the segment from surface point `x` (geometric normal `nx`) to
/// surface point `y` (normal `ny`): returns (origin, dir) to trace with tmax = 1.
///
/// Both ends are offset with [`offset_ray_origin`] (and the scene's `floor`), each along
/// its normal flipped to face the other point, so that neither surface occludes the
/// segment. The direction is y' - x', not normalised: t is in units of the segment (t = 1
/// at y'), which is why tmax = 1 and why the caller needs no distance. Normals need not
/// be oriented.
pub fn shadow_segment(x: Vec3, nx: Vec3, y: Vec3, ny: Vec3, floor: f32) -> (Vec3, Vec3) {
    let d = y - x;
    let nx = if nx.dot(d) < 0.0 { -nx } else { nx };
    let ny = if ny.dot(d) > 0.0 { -ny } else { ny };
    let o = offset_ray_origin(x, nx, floor);
    let e = offset_ray_origin(y, ny, floor);
    (o, e - o)
}
