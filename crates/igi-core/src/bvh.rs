//! The ray-tracing layer of igi: a binary BVH built on the CPU with a binned SAH, its GPU
//! layout, and a CPU traversal that is the exact twin of `crates/igi-gpu/src/shaders/traverse.wgsl`.
//!
//! Marques and Santos ("Instant Global Illumination on the GPU using OptiX") traced every
//! ray with OptiX; igi replaces OptiX with this layer. It answers the two queries of the
//! paper's frame: closest hit (camera, mirror and particle rays) and any hit (shadow rays).
//!
//! * `build`: binned SAH (Wald 2007 style) over triangle centroids, built in parallel.
//! * `split`: early split clipping (Ernst and Greiner 2007) of the triangles whose boxes
//!   waste the most area, before the binned build ([`BvhBuilder::Split`]).
//! * `traverse`: ray setup, the robust ray-box slab test (Ize, "Robust BVH Ray
//!   Traversal", JCGT 2013), the watertight ray-triangle test (Woop, Benthin and Wald,
//!   JCGT 2013), closest-hit and any-hit traversal, brute-force references, and the ray
//!   origin offset of Wächter and Binder (Ray Tracing Gems, ch. 6).
//! * `timing`: the build timed (`igi bench build`, the `bvh_build` example).
//!
//! The WGSL twin must run the same algorithm in the same order: any change here is a
//! change there (the GPU test `crates/igi-gpu/tests/traverse_gpu.rs` compares them).

mod build;
mod split;
pub mod timing;
mod traverse;

#[cfg(test)]
mod tests;

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use crate::scene::Triangle;

pub use traverse::{
    brute_force_any, brute_force_closest, offset_floor, offset_ray_origin, shadow_segment, Hit,
    NO_HIT, OFFSET_FLOOR_ULPS,
};

/// Deepest level at which the builder still makes an interior node; a node range that
/// reaches this depth becomes one leaf whatever its size. The root node has depth 0.
///
/// The traversal stack (`STACK_SIZE` in `traverse.wgsl`, equal to this value) holds only
/// far *interior* children, at most one per interior ancestor of the node being visited:
/// an entry is pushed at an interior node of depth d <= MAX_DEPTH - 1 while the stack
/// holds at most d entries (one per ancestor), so it never holds more than MAX_DEPTH
/// entries. SAH trees stay far below (the conference room's 331K triangles: depth 37);
/// the cap matters only for pathological inputs (a chain-like tree needs triangle areas
/// growing by a factor ~n from one level to the next), which then get one big leaf at
/// the bottom instead of overflowing the stack.
pub const MAX_DEPTH: u32 = 60;

/// Largest leaf the SAH may choose; larger ranges are always split (unless they reach
/// [`MAX_DEPTH`]). Small leaves keep the work of neighbouring GPU threads similar, and a
/// triangle test costs the walks more than its share of the SAH. Measured on the H200
/// (conference room, split BVH): 3 instead of 4 made every ray query and the frames
/// faster, for a few percent more nodes and no measurable build time; 2 did about as
/// well on the rays and slightly worse on the frames, for many more nodes and a longer
/// build; 1 was slower everywhere.
pub const MAX_LEAF_SIZE: usize = 3;

/// Number of bins per axis for the SAH split search.
pub const SAH_BINS: usize = 16;

/// SAH cost of visiting one interior node, relative to [`SAH_INTERSECT_COST`].
pub const SAH_TRAVERSAL_COST: f32 = 1.0;
/// SAH cost of one ray-triangle test.
pub const SAH_INTERSECT_COST: f32 = 1.0;

/// One node of the binary BVH as the GPU reads it: the boxes of both children, so that one
/// 64-byte fetch decides which children a ray visits and in which order.
///
/// Mirrors `struct BvhNode` of `scene.wgsl` (each `vec3<f32>` followed by a `u32` packs
/// into 16 bytes, so the WGSL struct has no padding):
///
/// | bytes  | field     | meaning                                                      |
/// |--------|-----------|--------------------------------------------------------------|
/// | 0..12  | `a_min`   | child a: box minimum (x, y, z)                               |
/// | 12..16 | `a_index` | child a: node index (interior) or first triangle (leaf)      |
/// | 16..28 | `a_max`   | child a: box maximum (x, y, z)                               |
/// | 28..32 | `a_count` | child a: 0 = interior node, n > 0 = leaf of n triangles      |
/// | 32..44 | `b_min`   | child b: box minimum                                         |
/// | 44..48 | `b_index` | child b: node index or first triangle                        |
/// | 48..60 | `b_max`   | child b: box maximum                                         |
/// | 60..64 | `b_count` | child b: 0 = interior node, n > 0 = leaf                     |
///
/// Child a is the likelier occluder per unit of work: the larger ratio of triangle area
/// below it to the SAH cost of the interior nodes below it (any-hit walks visit it first,
/// see `build`). Leaf triangles are BVH slots `index .. index + count` of
/// [`Bvh::tri_rows`]. An empty child (the second child of a root that is a single leaf,
/// both children of the BVH of no triangles) has min = max = +inf, count 1, index 0:
/// [`BvhChild::EMPTY`], a box no ray with a finite tmax hits.
///
/// Aligned to 16 bytes (the WGSL layout does not change: its size is 64) so that the build
/// can lay the nodes out in the allocation of its 16-byte-aligned references, whose pages
/// are mapped already (see `build`).
#[repr(C, align(16))]
#[derive(Clone, Copy, Pod, Zeroable, Debug, PartialEq)]
pub struct BvhNode {
    pub a_min: [f32; 3],
    pub a_index: u32,
    pub a_max: [f32; 3],
    pub a_count: u32,
    pub b_min: [f32; 3],
    pub b_index: u32,
    pub b_max: [f32; 3],
    pub b_count: u32,
}

/// One child of a [`BvhNode`], unpacked.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BvhChild {
    pub min: Vec3,
    pub max: Vec3,
    /// Node index (interior) or first BVH slot (leaf).
    pub index: u32,
    /// 0 for an interior node, the number of triangles for a leaf.
    pub count: u32,
}

impl BvhChild {
    /// The child that no ray hits: a point box at +inf (every slab distance of an axis is
    /// +inf, so the box is entered at +inf, or -inf, so it is left at -inf), a leaf of one
    /// triangle. Not an inverted box: the slab test takes the nearer and farther planes by
    /// min and max, which would make an inverted box span every axis.
    pub const EMPTY: BvhChild = BvhChild {
        min: Vec3::INFINITY,
        max: Vec3::INFINITY,
        index: 0,
        count: 1,
    };

    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }

    /// Whether this is [`BvhChild::EMPTY`] (the second child of a root leaf, or both
    /// children of the root of no triangles).
    pub fn is_empty(&self) -> bool {
        *self == BvhChild::EMPTY
    }

    /// Half the surface area of the child's box (0 for an empty or inverted one).
    pub fn half_area(&self) -> f32 {
        let e = (self.max - self.min).max(Vec3::ZERO);
        e.x * e.y + e.y * e.z + e.z * e.x
    }
}

impl BvhNode {
    pub fn new(a: BvhChild, b: BvhChild) -> BvhNode {
        BvhNode {
            a_min: a.min.to_array(),
            a_index: a.index,
            a_max: a.max.to_array(),
            a_count: a.count,
            b_min: b.min.to_array(),
            b_index: b.index,
            b_max: b.max.to_array(),
            b_count: b.count,
        }
    }

    pub fn a(&self) -> BvhChild {
        BvhChild {
            min: Vec3::from(self.a_min),
            max: Vec3::from(self.a_max),
            index: self.a_index,
            count: self.a_count,
        }
    }

    pub fn b(&self) -> BvhChild {
        BvhChild {
            min: Vec3::from(self.b_min),
            max: Vec3::from(self.b_max),
            index: self.b_index,
            count: self.b_count,
        }
    }
}

/// Which builder makes a [`Bvh`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BvhBuilder {
    /// Binned SAH over references with early split clipping (the `split` submodule:
    /// Ernst and Greiner 2007): the few long thin triangles whose boxes waste the most
    /// area are cut into pieces with tighter boxes. On the conference room about a sixth
    /// more references and a somewhat longer build than `Binned`, and every ray query
    /// and frame faster on the H200. Every exact query answers as with `Binned`
    /// (closest-hit ties between triangles at one distance aside); imperfect visibility
    /// finds less false occlusion. The commands' default.
    #[default]
    Split,
    /// Binned SAH over whole triangles (the `build` submodule, [`Bvh::build`]): the
    /// fastest build.
    Binned,
}

impl BvhBuilder {
    /// The builder's name in reports and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            BvhBuilder::Binned => "binned",
            BvhBuilder::Split => "split",
        }
    }
}

/// What the build produced and how long it took.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BuildStats {
    /// Wall time of [`Bvh::build`], in milliseconds.
    pub build_ms: f64,
    pub triangles: usize,
    /// BVH slots: the triangles, plus the repeats of a triangle that early split clipping
    /// put in more than one leaf ([`BvhBuilder::Split`]).
    pub references: usize,
    /// Interior nodes (entries of [`Bvh::nodes`]).
    pub nodes: usize,
    pub leaves: usize,
    /// Depth of the deepest leaf (children of the root have depth 1).
    pub max_depth: u32,
    pub max_leaf_size: u32,
    /// Leaves that were forced by [`MAX_DEPTH`] or by identical centroids with more than
    /// [`MAX_LEAF_SIZE`] triangles.
    pub oversized_leaves: usize,
    /// SAH cost of the tree, relative to the root box's surface area:
    /// sum over interior nodes of C_t A(n)/A(root) + sum over leaves of C_i N A(l)/A(root).
    pub sah_cost: f32,
    /// Wall time of the build's phases in milliseconds, in order: the references (and
    /// their split clipping), the node arrays' allocation, the tree, the layout, the
    /// rows.
    pub phases: Vec<(&'static str, f64)>,
}

/// One row of [`Bvh::tri_rows`]: one coordinate (x, y or z) of a slot's vertices 0, 1
/// and 2, and 0. Aligned to 16 bytes like [`BvhNode`], of which it is a quarter, so that
/// the build can write the rows into the allocation of its node places, whose pages are
/// mapped already (see `build`).
#[repr(C, align(16))]
#[derive(Clone, Copy, Pod, Zeroable, Debug, PartialEq)]
pub struct TriRow(pub [f32; 4]);

/// Vertices 0, 1 and 2 of BVH slot `slot` of [`Bvh::tri_rows`].
#[inline]
fn rows_to_vertices(tri_rows: &[TriRow], slot: usize) -> [Vec3; 3] {
    let [TriRow(x), TriRow(y), TriRow(z)] = &tri_rows[3 * slot..3 * slot + 3] else {
        unreachable!("a slot has three rows")
    };
    [0, 1, 2].map(|j| Vec3::new(x[j], y[j], z[j]))
}

/// A BVH over triangles, in the layout the GPU reads (`scene.wgsl`, bind group 0).
#[derive(Clone, Debug)]
pub struct Bvh {
    /// Interior nodes; node 0 is the root.
    pub nodes: Vec<BvhNode>,
    /// Three rows per BVH slot, in BVH order (slot i at 3i..3i+3): the x, the y and the z
    /// coordinates of its vertices 0, 1 and 2 (w = 0). The triangle test reads the rows of
    /// the ray's Woop axes (kx, ky, kz) by index; stored as vertices, the coordinates had
    /// to be permuted with 18 selects a test.
    pub tri_rows: Vec<TriRow>,
    /// BVH slot -> index of the triangle in the slice given to the build. Each triangle
    /// has one slot, or more with [`BvhBuilder::Split`] (one per piece).
    pub tri_order: Vec<u32>,
    pub build_stats: BuildStats,
}

impl Bvh {
    /// The nodes' boxes and the triangle rows times `factor`, a power of two (see
    /// [`crate::trace_scale`]): exactly the BVH of the scaled triangles, since only
    /// exponents change (boxes still hold their triangles, and the point box at +inf
    /// that no ray hits stays at +inf).
    pub fn scaled(&self, factor: f64) -> Bvh {
        let s = |x: f32| (x as f64 * factor) as f32;
        let s3 = |v: [f32; 3]| v.map(s);
        let nodes = self
            .nodes
            .iter()
            .map(|n| BvhNode {
                a_min: s3(n.a_min),
                a_max: s3(n.a_max),
                b_min: s3(n.b_min),
                b_max: s3(n.b_max),
                ..*n
            })
            .collect();
        let tri_rows = self
            .tri_rows
            .iter()
            .map(|TriRow(r)| TriRow([s(r[0]), s(r[1]), s(r[2]), r[3]]))
            .collect();
        Bvh {
            nodes,
            tri_rows,
            tri_order: self.tri_order.clone(),
            build_stats: self.build_stats.clone(),
        }
    }

    /// Build with a binned SAH (see the `build` submodule for the rules), on all cores
    /// for large inputs; the result does not depend on the number of cores. Handles any
    /// input: no triangles (a BVH that misses everything), degenerate triangles (their
    /// flat or point boxes are kept; the triangle test never reports a hit on them),
    /// identical centroids (split by index), non-finite vertices (the triangle keeps its
    /// slot, with a point box at the origin, and is never hit).
    pub fn build(triangles: &[Triangle]) -> Bvh {
        build::build(triangles)
    }

    /// Build with the given builder: [`BvhBuilder::Binned`] is [`Bvh::build`].
    pub fn build_with(triangles: &[Triangle], builder: BvhBuilder) -> Bvh {
        match builder {
            BvhBuilder::Binned => build::build(triangles),
            BvhBuilder::Split => build::build_split(triangles, MAX_DEPTH),
        }
    }

    /// Same as [`Bvh::build_with`], from bare vertex triples.
    pub fn build_from_vertices_with(triangles: &[[Vec3; 3]], builder: BvhBuilder) -> Bvh {
        match builder {
            BvhBuilder::Binned => build::build(triangles),
            BvhBuilder::Split => build::build_split(triangles, MAX_DEPTH),
        }
    }

    /// Same as [`Bvh::build`], from bare vertex triples.
    pub fn build_from_vertices(triangles: &[[Vec3; 3]]) -> Bvh {
        build::build(triangles)
    }

    /// Number of BVH slots: the triangles, and their repeats with [`BvhBuilder::Split`].
    pub fn triangle_count(&self) -> usize {
        self.tri_order.len()
    }

    /// Vertices of the triangle in BVH slot `slot`.
    pub fn triangle(&self, slot: u32) -> [Vec3; 3] {
        rows_to_vertices(&self.tri_rows, slot as usize)
    }

    /// Box of the whole scene (min, max); inverted-infinite for no triangles.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let n = &self.nodes[0];
        [n.a(), n.b()]
            .into_iter()
            .filter(|c| !c.is_empty())
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), c| {
                (lo.min(c.min), hi.max(c.max))
            })
    }

    /// Closest hit with 0 < t < tmax, or None. `t` is in units of `dir` (which need not
    /// be normalised); `Hit::tri` is a BVH slot ([`Bvh::tri_order`] maps it back).
    pub fn trace_closest(&self, origin: Vec3, dir: Vec3, tmax: f32) -> Option<Hit> {
        traverse::trace_closest(self, origin, dir, tmax)
    }

    /// Whether some triangle is hit with 0 < t < tmax (occlusion); stops at the first.
    pub fn trace_any(&self, origin: Vec3, dir: Vec3, tmax: f32) -> bool {
        traverse::trace_any(self, origin, dir, tmax)
    }

    /// Whether the segment from `origin` to `origin + dir` is occluded (a hit with 0 < t <
    /// 1), by the walk that the renderer's shadow rays take on the GPU (see
    /// `shadow_segment`): the answer of `trace_any(origin, dir, 1.0)` but for hits that
    /// rounding alone decides within a few ulps of either end.
    pub fn trace_segment(&self, origin: Vec3, dir: Vec3) -> bool {
        traverse::trace_segment(self, origin, dir)
    }
}
