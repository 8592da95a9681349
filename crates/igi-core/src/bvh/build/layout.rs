//! The finished tree laid out for the GPU: nodes renumbered depth first with the likelier
//! occluder as child a, the node of two children ordered while building, and the
//! triangles' vertex rows in the order of the BVH slots.

use std::mem::MaybeUninit;

use super::parallel::{par_chunks_zip, reuse_vec};
use super::tree::{is_node, written, NodeInfo, Places};
use super::{prefetch, PrimRef, Vertices};
use crate::bvh::{BvhChild, BvhNode, TriRow};

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
/// and the less they weighed the faster they were. On the H200 this order made canonical
/// frames, the frame's shadow rays and random segments faster than child a holding more
/// triangle area. A triangle with a non-finite vertex counts 0; one cut by early split
/// clipping counts in full in each leaf that holds one of its pieces. Where the children
/// are swapped, child b's subtree is the one right after the node: laying the tree out
/// again so that child a's came first measured the same on the H200 and lengthened the
/// build.
pub(super) fn occluder_first((area_a, cost_a): (f32, f32), (area_b, cost_b): (f32, f32)) -> bool {
    // area_b / cost_b > area_a / cost_a without dividing (two leaves, or a leaf and the
    // empty child: 0 > 0).
    area_b * cost_a > area_a * cost_b
}

/// Levels of the layout's top whose two subtrees are laid out side by side (4 parts: a
/// fixed number, so that the sums of the statistics, taken part by part, do not depend
/// on the machine).
pub(super) const LAYOUT_SPLIT_LEVELS: u32 = 2;

/// The tree renumbered depth first: each node's subtrees right after it, the subtree of
/// its child a as the build left it first (after the larger_first order of the
/// rotations), then the other; with child a the likelier occluder (`NodeInfo::swap`,
/// [`occluder_first`]), which may make child b's subtree the one right after the node.
/// Returns the sum of the interior nodes' half areas below the root and the deepest
/// leaf's depth (the root has depth 0), for the SAH cost. The subtree sizes in
/// [`NodeInfo`] place every node at once, so the top subtrees are laid out on separate
/// threads, instead of one walk on one thread followed by an ordering pass of its own.
pub(super) fn depth_first_layout(
    nodes: &Places<BvhNode>,
    info: &Places<NodeInfo>,
    references: Vec<PrimRef>,
) -> (Vec<BvhNode>, f64, u32) {
    // SAFETY: the root's place is written (see Places).
    let interior = unsafe { written(info, 0) }.interior as usize;
    // In the finished references' allocation (see build_impl); written once by the walks,
    // not zeroed first (zeroing is a pass of its own over the whole array).
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
pub(super) fn lay_out(
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
        // they load beside the children's infos read below (a faster layout, the same
        // tree).
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
/// the any-hit walks (faster than the split's order) until the layout put the likelier
/// occluder first ([`occluder_first`]); it
/// stays the order in which the rotations compare children while the tree is built, so
/// that they make the trees they were measured with.
pub(super) fn larger_first(a: BvhChild, b: BvhChild) -> BvhNode {
    if b.half_area() > a.half_area() {
        BvhNode::new(b, a)
    } else {
        BvhNode::new(a, b)
    }
}

/// The allocation of the node places as an empty vector of rows: a [`BvhNode`] is four
/// [`TriRow`]s in size and alignment.
pub(in crate::bvh) fn places_as_rows(places: Box<Places<BvhNode>>) -> Vec<TriRow> {
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

/// Writes the three rows of each slot (see [`Bvh::tri_rows`](crate::bvh::Bvh::tri_rows)) of the triangles `ids`
/// into `rows` (empty; grown where it is too small), on all threads (`ids` is only read;
/// it is split alike by `par_chunks_zip`, which takes two mutable slices).
pub(super) fn triangle_rows<T: Vertices>(
    mut rows: Vec<TriRow>,
    tri: &[T],
    ids: &mut [u32],
) -> Vec<TriRow> {
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
            // which halved this pass on the conference room.
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
/// 32 measured alike, 8 and 64 less well.
pub(super) const ROWS_PREFETCH_AHEAD: usize = 24;
