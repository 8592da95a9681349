//! The tree while it is built: the node places left unwritten until set, the region of
//! them that each subtree writes, the per-node [`NodeInfo`], and Kensler's rotations made
//! as each node's subtree is finished.

use std::mem::MaybeUninit;

use super::layout::{larger_first, occluder_first};
use super::union;
use crate::bvh::{BvhChild, BvhNode, SAH_TRAVERSAL_COST};

/// What the build keeps per interior node besides the node itself: its height for the
/// rotations' depth cap ([`rotate_locally`]), and what [`occluder_first`] orders its
/// children by, so that the layout can place them without a pass of its own.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, bytemuck::Pod, bytemuck::Zeroable)]
pub(super) struct NodeInfo {
    /// Triangle area below the node (see [`occluder_first`]).
    pub(super) area: f32,
    /// SAH cost of the interior nodes below the node and of the node itself, not divided
    /// by any area (see [`occluder_first`]).
    pub(super) cost: f32,
    /// Interior nodes in the node's subtree, itself included (where the layout puts its
    /// second subtree).
    pub(super) interior: u32,
    /// Levels below the node: 1 for a node whose children are leaves.
    pub(super) height: u8,
    /// 1 where child b is the likelier occluder and the layout makes it child a.
    pub(super) swap: u8,
    pub(super) _pad: [u8; 2],
}

/// Places of the node array (or of the [`NodeInfo`] array) while the tree is built, left
/// unwritten until a node is stored there: a subtree of n references gets the n - 1
/// places it might need ([`Region`]) and uses about half of them, and zeroing them all
/// was a noticeable share of a build wherever the allocator reused memory. A place is
/// read only where a child refers to it
/// (and the root, place 0, which is always written), and a child refers to a node only
/// once [`Region::set`] has stored it: `build_node` hands out a node's reference after
/// setting it, and the rotations only store nodes that were set before. So no unwritten
/// place is read ([`written`]).
pub(in crate::bvh) type Places<T> = [MaybeUninit<T>];

/// The node (or [`NodeInfo`]) at place `i`.
///
/// # Safety
/// Place `i` must have been written: the root's place, or one a child refers to (see
/// [`Places`]).
#[inline]
pub(super) unsafe fn written<T: Copy>(places: &Places<T>, i: usize) -> T {
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
/// built in a vector of its own and copied behind the left one: copies that took a
/// large share of the build, mostly after joins, where no other work overlapped them.)
pub(super) struct Region<'a> {
    pub(super) nodes: &'a mut Places<BvhNode>,
    pub(super) info: &'a mut Places<NodeInfo>,
    pub(super) base: usize,
    pub(super) used: usize,
    /// Per slot the area of its triangle (0 for a non-finite one).
    pub(super) slot_area: &'a mut [f32],
    pub(super) slot_base: usize,
}

impl Region<'_> {
    /// A new node's global index.
    pub(super) fn push(&mut self) -> usize {
        self.used += 1;
        self.base + self.used - 1
    }

    /// Node `i`, which must have been set: node `i` being built or rotated, or a child's.
    pub(super) fn node(&self, i: usize) -> BvhNode {
        debug_assert!(self.info(i).interior > 0, "node {i} read before it was set");
        // SAFETY: every caller passes such an index (see Places).
        unsafe { written(self.nodes, i - self.base) }
    }

    /// Node `i`'s info, as for [`Region::node`].
    pub(super) fn info(&self, i: usize) -> NodeInfo {
        // SAFETY: as in Region::node.
        let info = unsafe { written(self.info, i - self.base) };
        debug_assert!(info.interior > 0, "node {i}'s info read before it was set");
        info
    }

    /// Stores node `i`, whose children are final, with its [`NodeInfo`].
    pub(super) fn set(&mut self, i: usize, node: BvhNode) {
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
    pub(super) fn height(&self, c: &BvhChild) -> u8 {
        if is_node(c) {
            self.info(c.index as usize).height
        } else {
            0
        }
    }

    /// Interior nodes of a child's subtree (0 for a leaf).
    pub(super) fn interior(&self, c: &BvhChild) -> u32 {
        if is_node(c) {
            self.info(c.index as usize).interior
        } else {
            0
        }
    }

    /// The triangle area and the interior nodes' SAH cost below a child (see
    /// [`occluder_first`]); a leaf's area summed slot by slot.
    pub(super) fn content(&self, c: &BvhChild) -> (f32, f32) {
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
    pub(super) fn write_leaf(&mut self, first: u32, ids: &[u32], tri_area: &[f32]) {
        let first = first as usize - self.slot_base;
        for (area, &id) in self.slot_area[first..first + ids.len()].iter_mut().zip(ids) {
            *area = tri_area[id as usize];
        }
    }

    /// The rest of the region split for a node's two subtrees built side by side: the
    /// left one (k triangles from slot `first`) gets k - 1 places, the right one the
    /// rest; the slots split after the left one's.
    pub(super) fn split(&mut self, k: usize, first: u32) -> (Region<'_>, Region<'_>) {
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
pub(super) fn is_node(c: &BvhChild) -> bool {
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
/// parent looks at it. On the conference room it lowers the SAH cost as much as three
/// separate passes over the finished tree did, in less build time.
pub(super) fn rotate_locally(
    tree: &mut Region,
    i: usize,
    depth: u32,
    max_depth: u32,
    budget: &mut u32,
) {
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
pub(super) fn rotate_node(
    tree: &mut Region,
    i: usize,
    depth: u32,
    max_depth: u32,
) -> Option<usize> {
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
