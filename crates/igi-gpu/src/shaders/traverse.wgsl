// traverse.wgsl: the ray-tracing layer of igi, which replaces OptiX in the system of
// Marques and Santos ("Instant Global Illumination on the GPU using OptiX"): closest-hit
// and any-hit traversal of the BVH of scene.wgsl (bvh_nodes, tri_rows), the watertight
// ray-triangle test (Woop, Benthin, Wald, JCGT 2013), the robust slab test (Ize, JCGT
// 2013) and the ray origin offset of Wächter and Binder (Ray Tracing Gems, ch. 6).
//
// CPU twin: crates/igi-core/src/bvh/traverse.rs, the same algorithm in the same order;
// the reasons behind each choice are written there. Change both together:
// crates/igi-gpu/tests/traverse_gpu.rs compares them ray by ray.
//
// Results can differ from the CPU only by rounding: WGSL allows division to be 2.5 ulp,
// and GPU compilers may fuse a * b + c into one fma. Neither can break watertightness:
// the inside test compares rounded products and never looks at a fused difference.

#import scene
#import texture

// Hit.tri of a miss.
const NO_HIT: u32 = 0xffffffffu;

// Entries of the traversal stack; equals igi_core::bvh::MAX_DEPTH (a test checks it).
// Only far interior children are pushed, at most one per interior ancestor of the node
// being visited; the builder makes no interior node at depth >= MAX_DEPTH (root: depth
// 0), so a push happens at depth d <= MAX_DEPTH - 1 onto at most d entries: the stack
// never holds more than MAX_DEPTH entries and cannot overflow.
const STACK_SIZE: u32 = 60u;

// The traversal stack. The walks take it by pointer from their caller, which declares
// one per invocation, outside its loops over rays: WGSL zero-initialises a function's
// variables where they are declared (naga writes a null initializer, which the NVIDIA
// driver did not remove), so a stack declared in the walk cost every walk 240 bytes
// of stores, a visible share of a frame. A walk never reads an entry it did not push,
// so one stack serves any number of walks.
alias WalkStack = array<u32, STACK_SIZE>;

// Direction components below this count as zero for the slab test (parallel axes).
const DIR_EPS: f32 = 1e-30;
// Reciprocal of a parallel axis: finite, since WGSL makes inf and NaN indeterminate.
const PARALLEL_INV: f32 = 1e30;
// The slab of an axis the ray is parallel to is widened by (|o| + 1) x PARALLEL_SLACK
// (2^-20) on both sides, so that an origin on its plane is inside (igi_core's DIR_EPS
// says why and what it costs).
const PARALLEL_SLACK: f32 = 0.00000095367431640625;
// Relative pad of box_span's per-ray plane offsets (2^-21; igi_core's SLAB_PAD).
const SLAB_PAD: f32 = 0.000000476837158203125;
// 1 + 2 gamma(3), rounded to f32 (1 + 3 ulp): conservative far end of a slab, for rays
// of any length (trace_closest, trace_any).
const BOX_TFAR_SCALE: f32 = 1.0000003576278687;
// Absolute pad of a segment walk's planes (2^-21 of its length; igi_core's SEGMENT_PAD):
// in place of BOX_TFAR_SCALE where tmax = 1 (trace_segment).
const SEGMENT_PAD: f32 = 0.000000476837158203125;

// Whether walks report being cut short. llvmpipe (the software adapter) ends every loop
// of a shader invocation once the invocation has run 65,535 loop iterations in all, and
// the code after the loop runs on: a walk cut so would answer "no hit", and light would
// pass through a shadow in silence (a few tens of thousands of overlapping triangles are
// enough). A cut walk adds one to ray_counters[CUT_WALKS], and the renderer refuses the
// frame (Renderer::check_walks). The software adapters' composition sets this true
// (shader::try_compose); on GPUs, which have no such limit, the checks fold away. The
// CPU twin has no limit and no such check.
const LOOP_CUTS_COUNTED: bool = false;

fn walk_cut() {
    if (LOOP_CUTS_COUNTED) {
        atomicAdd(&ray_counters[CUT_WALKS], 1u);
    }
}

// Wächter-Binder offset constants: near-origin threshold, absolute offset, ulp count.
const OFFSET_ORIGIN: f32 = 0.03125;
const OFFSET_FLOAT_SCALE: f32 = 0.0000152587890625;
const OFFSET_INT_SCALE: f32 = 256.0;

// A hit: origin + t dir lies on triangle `tri` (BVH slot; tri_order maps it to the scene's
// index), with barycentric weights u of vertex 1 and v of vertex 2. 16 bytes, like
// igi_core::bvh::Hit: t 0..4, tri 4..8, u 8..12, v 12..16.
struct Hit {
    t: f32,
    tri: u32,
    u: f32,
    v: f32,
}

// Per-ray constants, computed once by make_ray.
struct TraceRay {
    // The origin in the Woop axes: (origin[kx], origin[ky], origin[kz]).
    origin_k: vec3<f32>,
    inv_dir: vec3<f32>,
    // Woop et al. shear (dir[kx] / dir[kz], dir[ky] / dir[kz], 1 / dir[kz]).
    shear: vec3<f32>,
    kx: u32,
    ky: u32,
    kz: u32,
    // box_span's offsets for the planes of a box's min corner and of its max corner: a
    // plane b is crossed at t = fma(b, inv_dir, c), c being -origin inv_dir moved outward
    // by SLAB_PAD (and by SEGMENT_PAD for segments), from the origin moved by the slack
    // along parallel axes.
    c_min: vec3<f32>,
    c_max: vec3<f32>,
}

// The shadow ray of a segment between two surface points (see shadow_segment).
struct ShadowSegment {
    origin: vec3<f32>,
    dir: vec3<f32>,
}

// t_pad: an absolute pad of every plane (SEGMENT_PAD for segment walks, else 0).
fn make_ray(origin: vec3<f32>, dir: vec3<f32>, t_pad: f32) -> TraceRay {
    let parallel = abs(dir) < vec3<f32>(DIR_EPS);
    // Divide by 1 in parallel lanes so that no lane ever computes 1 / 0.
    let inv_dir = select(vec3<f32>(1.0) / select(dir, vec3<f32>(1.0), parallel), vec3<f32>(PARALLEL_INV), parallel);
    let a = abs(dir);
    // Ties go to the lower axis (as on the CPU).
    var kz = 0u;
    if (a.y > a.x) {
        kz = 1u;
    }
    if (a.z > a[kz]) {
        kz = 2u;
    }
    var kx = (kz + 1u) % 3u;
    var ky = (kx + 1u) % 3u;
    if (dir[kz] < 0.0) {
        let k = kx;
        kx = ky;
        ky = k;
    }
    let shear = vec3<f32>(dir[kx] / dir[kz], dir[ky] / dir[kz], 1.0 / dir[kz]);
    let slack = select(vec3<f32>(0.0), (abs(origin) + 1.0) * PARALLEL_SLACK, parallel);
    let oi = origin * inv_dir;
    let pad = select(abs(oi) * SLAB_PAD + t_pad, vec3<f32>(0.0), parallel);
    // The min corner's planes are entry planes where inv_dir > 0 (parallel axes
    // included: measured from the origin moved up by the slack, and moved down by the
    // pad), exit planes where it is < 0 (moved up by the pad); the max corner's the
    // other way. Written otherwise, as selects between -(origin -+ slack) inv_dir -+ pad
    // computed first (the same values), the NVIDIA driver made the gathers slower.
    let positive = inv_dir > vec3<f32>(0.0);
    let c_min = select(pad - oi, -(origin + slack) * inv_dir - pad, positive);
    let c_max = select(-oi - pad, -(origin - slack) * inv_dir + pad, positive);
    let origin_k = woop_axes(origin, vec3<u32>(kx, ky, kz));
    return TraceRay(origin_k, inv_dir, shear, kx, ky, kz, c_min, c_max);
}

// The distances at which the ray crosses the planes of a box's min corner (t0) and of its
// max corner (t1), each one fused multiply-add with the ray's padded offsets (box_span
// says why): the twin of igi_core's TraceRay::plane_distances. box_span orders them on
// integer bits for the walks, slab_spans as floats for box_crossed.
struct PlaneDistances {
    t0: vec3<f32>,
    t1: vec3<f32>,
}

fn plane_distances(bmin: vec3<f32>, bmax: vec3<f32>, r: TraceRay) -> PlaneDistances {
    return PlaneDistances(fma(bmin, r.inv_dir, r.c_min), fma(bmax, r.inv_dir, r.c_max));
}

// Where the ray crosses a box's slabs: per axis the nearer and the farther plane's
// distance, as float minima and maxima for box_crossed (imperfect visibility).
struct SlabSpans {
    near: vec3<f32>,
    far: vec3<f32>,
}

fn slab_spans(bmin: vec3<f32>, bmax: vec3<f32>, r: TraceRay) -> SlabSpans {
    let d = plane_distances(bmin, bmax, r);
    return SlabSpans(min(d.t0, d.t1), max(d.t0, d.t1));
}

// Slab test: (entry, exit) distances of a box clipped to [0, tmax]; the box is hit when
// entry <= exit. Each axis enters at the nearer plane and leaves at the farther (min and
// max; with selects by the direction's sign instead, the NVIDIA driver spilled registers
// of the gather to shared memory and the gathers ran slower). So the child no ray may hit
// is a point box at +inf, not an inverted one (igi_core's BvhChild::EMPTY); tmax is
// always finite here (WGSL has no infinity). Each plane's distance is one fused
// multiply-add with the ray's padded offsets (igi_core's SLAB_PAD says why that stays
// conservative; it is one subtraction fewer per plane than (b - o) * inv, which made
// frames faster). Parallel axes need no case of their own: their offsets hold the moved
// origins (the select this replaced slowed every walk). The far end is scaled by
// far_scale: BOX_TFAR_SCALE, or 1 on a segment walk, whose planes are padded instead
// (SEGMENT_PAD).
// The minima and maxima are taken on the distances' bits as signed integers, which order
// like the floats they are wherever the answer depends on it (igi_core's box_span says
// why): with float min and max, the walks ran slower on NVIDIA's driver, with the same
// answers.
fn box_span(bmin: vec3<f32>, bmax: vec3<f32>, r: TraceRay, tmax: f32, far_scale: f32) -> vec2<f32> {
    let d = plane_distances(bmin, bmax, r);
    let t0 = bitcast<vec3<i32>>(d.t0);
    let t1 = bitcast<vec3<i32>>(d.t1);
    let tn = min(t0, t1);
    let tf = max(t0, t1);
    let near = max(max(tn.x, tn.y), max(tn.z, 0));
    let far = min(bitcast<f32>(min(min(tf.x, tf.y), tf.z)) * far_scale, tmax);
    return vec2<f32>(bitcast<f32>(near), far);
}

// The entry distance (>= 0) of a box hit within [0, tmax], or -1 (closest hits order
// and prune children by it).
fn box_near(bmin: vec3<f32>, bmax: vec3<f32>, r: TraceRay, tmax: f32) -> f32 {
    let span = box_span(bmin, bmax, r, tmax, BOX_TFAR_SCALE);
    return select(-1.0, span.x, span.x <= span.y);
}

// Whether a box is hit within [0, tmax] (any hit needs no distance: without the select
// and the compare that box_near's -1 costs, the walks are faster).
fn box_hit(bmin: vec3<f32>, bmax: vec3<f32>, r: TraceRay, tmax: f32, far_scale: f32) -> bool {
    let span = box_span(bmin, bmax, r, tmax, far_scale);
    return span.x <= span.y;
}

// (v[k.x], v[k.y], v[k.z]), by selects: the ray's origin in its Woop axes (make_ray).
// Indexing a vector with a run-time index (v[r.kx]) compiled to something much slower on
// NVIDIA's Vulkan driver; the values are the same.
fn woop_axes(v: vec3<f32>, k: vec3<u32>) -> vec3<f32> {
    return select(select(vec3<f32>(v.x), vec3<f32>(v.y), k == vec3<u32>(1u)), vec3<f32>(v.z), k == vec3<u32>(2u));
}

// Watertight two-sided ray-triangle test: (t, u, v) of a hit with 0 < t < tmax, else
// t = -1. Edge and vertex hits count: a ray through a shared edge or vertex never leaks.
// The triangle comes as its rows in the ray's Woop axes: xr = (v0, v1, v2)[kx], yr the
// [ky] and zr the [kz] coordinates, read from tri_rows by index (slot_rows),
// so that the test permutes nothing: stored as vertices, the coordinates took 18 selects
// a test to pick, which slowed every kind of walk. The values are the same:
// (v - o)[kx] = v[kx] - o[kx].
fn intersect_triangle(r: TraceRay, xr: vec3<f32>, yr: vec3<f32>, zr: vec3<f32>, tmax: f32) -> vec3<f32> {
    let miss = vec3<f32>(-1.0, 0.0, 0.0);
    // Per row the three vertices moved to the origin: dx = (a.x, b.x, c.x) of the
    // translated, permuted vertices a, b, c; then sheared so that the ray runs along +z.
    let dx = xr - vec3<f32>(r.origin_k.x);
    let dy = yr - vec3<f32>(r.origin_k.y);
    let dz = zr - vec3<f32>(r.origin_k.z);
    let sx = dx - r.shear.x * dz;
    let sy = dy - r.shear.y * dz;
    let ax = sx.x;
    let ay = sy.x;
    let bx = sx.y;
    let by = sy.y;
    let cx = sx.z;
    let cy = sy.z;
    // Edge functions U (weight of v0), V (v1), W (v2) as pairs of rounded products: the
    // signs come from comparing them, never from a (possibly fused) difference.
    let pu1 = cx * by;
    let pu2 = cy * bx;
    let pv1 = ax * cy;
    let pv2 = ay * cx;
    let pw1 = bx * ay;
    let pw2 = by * ax;
    let inside = (pu1 >= pu2 && pv1 >= pv2 && pw1 >= pw2) || (pu1 <= pu2 && pv1 <= pv2 && pw1 <= pw2);
    if (!inside) {
        return miss;
    }
    let eu = pu1 - pu2;
    let ev = pv1 - pv2;
    let ew = pw1 - pw2;
    let det = eu + ev + ew;
    if (det == 0.0) {
        return miss;
    }
    let az = r.shear.z * dz.x;
    let bz = r.shear.z * dz.y;
    let cz = r.shear.z * dz.z;
    let tt = eu * az + ev * bz + ew * cz;
    let rcp = 1.0 / det;
    let t = tt * rcp;
    if (t > 0.0 && t < tmax) {
        return vec3<f32>(t, ev * rcp, ew * rcp);
    }
    return miss;
}

// The rows of BVH slot `slot` in the ray's Woop axes (the test's xr, yr, zr), read by
// index: the twin of igi_core's slot_rows.
// `tested`: the rows' w is not 0 where the slot's material is alpha-tested (every row of
// the slot says so: the ray reads them in its own order).
struct WoopRows {
    x: vec3<f32>,
    y: vec3<f32>,
    z: vec3<f32>,
    tested: bool,
}

fn slot_rows(slot: u32, r: TraceRay) -> WoopRows {
    let i = 3u * slot;
    let x = tri_rows[i + r.kx];
    return WoopRows(x.xyz, tri_rows[i + r.ky].xyz, tri_rows[i + r.kz].xyz, x.w != 0.0);
}

// Whether a hit at barycentrics (u, v) of a slot is a hit: not where an alpha mask cuts
// the surface out (texture.wgsl).
fn solid_at(rows: WoopRows, slot: u32, u: f32, v: f32) -> bool {
    return !ALPHA_MASKS || !rows.tested || !cut_out(slot, u, v);
}

// The triangles of a leaf in slot order; equal distances keep the first hit.
fn leaf_closest(first: u32, count: u32, r: TraceRay, hit_in: Hit) -> Hit {
    var hit = hit_in;
    var slot = first;
    for (; slot < first + count; slot++) {
        let rows = slot_rows(slot, r);
        let h = intersect_triangle(r, rows.x, rows.y, rows.z, hit.t);
        if (h.x > 0.0 && solid_at(rows, slot, h.y, h.z)) {
            hit = Hit(h.x, slot, h.y, h.z);
        }
    }
    if (LOOP_CUTS_COUNTED && slot < first + count) {
        walk_cut();
    }
    return hit;
}

fn leaf_any(first: u32, count: u32, r: TraceRay, tmax: f32, boxes: bool) -> bool {
    var slot = first;
    for (; slot < first + count; slot++) {
        let i = 3u * slot;
        if (boxes) {
            // The triangle's box: per axis the extremes of that axis's row.
            // Not for alpha-tested slots (w != 0): a leaf's cut-out shape is not its box,
            // so they are tested by their triangle and texels below.
            let row_x = tri_rows[i];
            let x = row_x.xyz;
            let y = tri_rows[i + 1u].xyz;
            let z = tri_rows[i + 2u].xyz;
            let lo = vec3<f32>(min(x.x, min(x.y, x.z)), min(y.x, min(y.y, y.z)), min(z.x, min(z.y, z.z)));
            let hi = vec3<f32>(max(x.x, max(x.y, x.z)), max(y.x, max(y.y, y.z)), max(z.x, max(z.y, z.z)));
            if ((!ALPHA_MASKS || row_x.w == 0.0) && box_crossed(lo, hi, r, tmax)) {
                return true;
            }
        }
        let rows = slot_rows(slot, r);
        let h = intersect_triangle(r, rows.x, rows.y, rows.z, tmax);
        if (h.x > 0.0 && solid_at(rows, slot, h.y, h.z)) {
            return true;
        }
    }
    if (LOOP_CUTS_COUNTED && slot < first + count) {
        walk_cut();
    }
    return false;
}

// Parametric margin of imperfect visibility, in units of the segment: a box blocks only
// where the segment enters it after BOX_MARGIN and leaves it before tmax - BOX_MARGIN.
const BOX_MARGIN: f32 = 1e-4;

// Imperfect visibility (paper section 4.1): whether the segment passes right through a
// triangle's bounding box. A box that holds (or nearly holds) either end is not counted:
// every shadow ray starts on a surface, inside the boxes of the triangles around its
// origin, and ends inside those around the VPL, so counting them would make every
// oblique (or axis-aligned, whose box is flat) surface shadow itself. Such triangles get
// the exact test instead, so boxes only ever add occlusion to the exact answer.
// The distances are box_span's, unclipped: a parallel axis's planes are measured from
// the origin moved by its slack, so that inside the slab they lie beyond +-9.5e23 and
// the other axes decide, and outside it the box is missed (igi_core's DIR_EPS); the
// pads widen the box by a few ulps of the origin, far below BOX_MARGIN.
fn box_crossed(bmin: vec3<f32>, bmax: vec3<f32>, r: TraceRay, tmax: f32) -> bool {
    let slabs = slab_spans(bmin, bmax, r);
    let enter = max(max(slabs.near.x, slabs.near.y), slabs.near.z);
    let leave = min(min(slabs.far.x, slabs.far.y), slabs.far.z);
    return enter <= leave && enter > BOX_MARGIN && leave < tmax - BOX_MARGIN;
}

// Closest hit with 0 < t < tmax; Hit.tri == NO_HIT (and t = tmax) on a miss. `dir` need
// not be normalised: t is in units of dir. Nearer child first; leaf children are tested
// as soon as their box is hit, interior ones descended into (the nearer) or pushed.
fn trace_closest(stack: ptr<function, WalkStack>, origin: vec3<f32>, dir: vec3<f32>, tmax: f32) -> Hit {
    var hit = Hit(tmax, NO_HIT, 0.0, 0.0);
    if (all(dir == vec3<f32>(0.0))) {
        return hit;
    }
    let r = make_ray(origin, dir, 0.0);
    var sp = 0u;
    var node = 0u;
    // Set where the walk ends by itself (see LOOP_CUTS_COUNTED).
    var walked = false;
    loop {
        let n = bvh_nodes[node];
        let ta = box_near(n.a_min, n.a_max, r, hit.t);
        let tb = box_near(n.b_min, n.b_max, r, hit.t);
        // Nearer child first; ties and misses of b: a first.
        let b_first = tb >= 0.0 && (ta < 0.0 || tb < ta);
        let t0 = select(ta, tb, b_first);
        let i0 = select(n.a_index, n.b_index, b_first);
        let c0 = select(n.a_count, n.b_count, b_first);
        let t1 = select(tb, ta, b_first);
        let i1 = select(n.b_index, n.a_index, b_first);
        let c1 = select(n.b_count, n.a_count, b_first);
        var next = NO_HIT;
        if (t0 >= 0.0) {
            if (c0 > 0u) {
                hit = leaf_closest(i0, c0, r, hit);
            } else {
                next = i0;
            }
        }
        // Re-check the far child: a leaf of the near one may have moved hit.t closer.
        if (t1 >= 0.0 && t1 <= hit.t) {
            if (c1 > 0u) {
                hit = leaf_closest(i1, c1, r, hit);
            } else if (next == NO_HIT) {
                next = i1;
            } else {
                (*stack)[sp] = i1;
                sp += 1u;
            }
        }
        if (next == NO_HIT) {
            if (sp == 0u) {
                walked = true;
                break;
            }
            sp -= 1u;
            next = (*stack)[sp];
        }
        node = next;
    }
    if (LOOP_CUTS_COUNTED && !walked) {
        walk_cut();
    }
    return hit;
}

// Whether some triangle is hit with 0 < t < tmax (occlusion); returns at the first.
// Children are visited in fixed order (a, then b): nearer-first ordering, which closest
// hits need, made frames slower here (probably because a fixed order keeps the walks of
// a warp's rays, which end at one point, in step). The builder makes child a the
// likelier occluder per unit of work: the larger ratio of triangle area to the interior
// nodes' SAH cost below it, which beat the child of more triangle area, the larger box
// first and the split's order.
// With `boxes` (imperfect visibility), a triangle whose box the segment crosses counts
// as a hit (see box_crossed). The callers below pick the far end's margin: t_pad and
// far_scale are constants there, which the compiler can fold into each walk.
fn walk_any(stack: ptr<function, WalkStack>, origin: vec3<f32>, dir: vec3<f32>, tmax: f32, boxes: bool, t_pad: f32, far_scale: f32) -> bool {
    if (all(dir == vec3<f32>(0.0))) {
        return false;
    }
    let r = make_ray(origin, dir, t_pad);
    var sp = 0u;
    var node = 0u;
    loop {
        let n = bvh_nodes[node];
        let hit_a = box_hit(n.a_min, n.a_max, r, tmax, far_scale);
        let hit_b = box_hit(n.b_min, n.b_max, r, tmax, far_scale);
        var next = NO_HIT;
        if (hit_a) {
            if (n.a_count > 0u) {
                if (leaf_any(n.a_index, n.a_count, r, tmax, boxes)) {
                    return true;
                }
            } else {
                next = n.a_index;
            }
        }
        if (hit_b) {
            if (n.b_count > 0u) {
                if (leaf_any(n.b_index, n.b_count, r, tmax, boxes)) {
                    return true;
                }
            } else if (next == NO_HIT) {
                next = n.b_index;
            } else {
                (*stack)[sp] = n.b_index;
                sp += 1u;
            }
        }
        if (next == NO_HIT) {
            if (sp == 0u) {
                return false;
            }
            sp -= 1u;
            next = (*stack)[sp];
        }
        node = next;
    }
    // Reached only where the loop was cut short (every walk's own end returns above).
    walk_cut();
    return false;
}

// Exact any-hit query of a ray of any length (0 < t < tmax, tmax up to 3.4e38): the far
// end scaled by BOX_TFAR_SCALE (see walk_any).
fn trace_any(stack: ptr<function, WalkStack>, origin: vec3<f32>, dir: vec3<f32>, tmax: f32) -> bool {
    return walk_any(stack, origin, dir, tmax, false, 0.0, BOX_TFAR_SCALE);
}

// Whether the segment from origin to origin + dir is occluded (0 < t < 1; see walk_any):
// the renderer's shadow rays (shadow_segment). A segment's planes are padded by the
// constant SEGMENT_PAD instead of scaling every far end by BOX_TFAR_SCALE: one product
// fewer per box, which made frames faster (igi_core's SEGMENT_PAD says why it stays
// conservative). `boxes`: imperfect visibility.
fn trace_segment(stack: ptr<function, WalkStack>, origin: vec3<f32>, dir: vec3<f32>, boxes: bool) -> bool {
    return walk_any(stack, origin, dir, 1.0, boxes, SEGMENT_PAD, 1.0);
}

// Origin for a ray leaving a surface at p, n the unit geometric normal on the side the
// ray leaves to: each coordinate moves by 256 n_i ulps of itself (integer add on its
// bits), or by n_i / 65536 within 1/32 of 0; then the point moves `floor` further along
// n (the scene's offset floor, params.ray_offset_floor: igi_core::bvh::offset_floor says
// why; a power of two, so floor * n is exact and a fused multiply-add changes nothing).
// Bit for bit igi_core::bvh::offset_ray_origin.
fn offset_ray_origin(p: vec3<f32>, n: vec3<f32>, floor: f32) -> vec3<f32> {
    let of_i = vec3<i32>(OFFSET_INT_SCALE * n);
    let p_i = bitcast<vec3<f32>>(bitcast<vec3<i32>>(p) + select(of_i, -of_i, p < vec3<f32>(0.0)));
    return select(p_i, p + OFFSET_FLOAT_SCALE * n, abs(p) < vec3<f32>(OFFSET_ORIGIN)) + floor * n;
}

// Shadow ray from surface point x (normal nx) to surface point y (normal ny), both ends
// offset along their normals turned toward the other point. Trace it with trace_segment:
// dir is y' - x', not normalised, so t is in units of the segment.
fn shadow_segment(x: vec3<f32>, nx: vec3<f32>, y: vec3<f32>, ny: vec3<f32>, floor: f32) -> ShadowSegment {
    let d = y - x;
    let ox = offset_ray_origin(x, select(nx, -nx, dot(nx, d) < 0.0), floor);
    let oy = offset_ray_origin(y, select(ny, -ny, dot(ny, d) > 0.0), floor);
    return ShadowSegment(ox, oy - ox);
}
