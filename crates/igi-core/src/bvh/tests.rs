//! Tests of the BVH: layout, structure, traversal against brute force, watertightness,
//! depth cap, ray offsets.

use glam::Vec3;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use super::*;

fn rng(seed: u64) -> Pcg64 {
    Pcg64::seed_from_u64(seed)
}

fn rand_vec(r: &mut Pcg64, lo: f32, hi: f32) -> Vec3 {
    Vec3::new(
        r.random_range(lo..hi),
        r.random_range(lo..hi),
        r.random_range(lo..hi),
    )
}

fn rand_dir(r: &mut Pcg64) -> Vec3 {
    loop {
        let v = rand_vec(r, -1.0, 1.0);
        let l = v.length_squared();
        if l > 1e-4 && l <= 1.0 {
            return v / l.sqrt();
        }
    }
}

/// `n` random triangles of size up to `size` with vertices in [-extent, extent]^3.
fn random_triangles(r: &mut Pcg64, n: usize, extent: f32, size: f32) -> Vec<[Vec3; 3]> {
    (0..n)
        .map(|_| {
            let c = rand_vec(r, -extent, extent);
            [
                c + rand_vec(r, -size, size),
                c + rand_vec(r, -size, size),
                c + rand_vec(r, -size, size),
            ]
        })
        .collect()
}

/// Checks the structure: tri_order is a permutation, tri_rows follow it, every box
/// contains what it holds, depth and stack bounds hold.
fn check_structure(bvh: &Bvh, tris: &[[Vec3; 3]]) {
    check_structure_of(bvh, tris, BvhBuilder::Binned);
}

/// The same for either builder: with early split clipping (`Split`) a triangle may fill
/// several slots, and a leaf's box holds the pieces of its triangles, so it lies inside
/// the box of its triangles instead of around them.
fn check_structure_of(bvh: &Bvh, tris: &[[Vec3; 3]], builder: BvhBuilder) {
    let n = tris.len();
    let refs = bvh.tri_order.len();
    assert_eq!(bvh.build_stats.references, refs);
    assert_eq!(bvh.build_stats.triangles, n);
    if builder == BvhBuilder::Binned {
        assert_eq!(refs, n);
    }
    // Every phase of the build timed once, in order (a build of no triangles has none).
    let phases: Vec<&str> = bvh.build_stats.phases.iter().map(|p| p.0).collect();
    let expected: &[&str] = match (n, builder) {
        (0, _) => &[],
        (_, BvhBuilder::Binned) => &["references", "node arrays", "tree", "layout", "rows"],
        (_, BvhBuilder::Split) => &[
            "references",
            "split clipping",
            "node arrays",
            "tree",
            "layout",
            "rows",
        ],
    };
    assert_eq!(phases, expected);
    assert!(bvh.build_stats.phases.iter().all(|p| p.1 >= 0.0));
    assert_eq!(bvh.tri_rows.len(), 3 * refs);
    let mut seen = vec![false; n];
    for (slot, &i) in bvh.tri_order.iter().enumerate() {
        assert!(
            builder == BvhBuilder::Split || !seen[i as usize],
            "triangle {i} twice"
        );
        seen[i as usize] = true;
        // By bits: a non-finite vertex may be NaN.
        let bits = |t: [Vec3; 3]| t.map(|v| v.to_array().map(f32::to_bits));
        assert_eq!(bits(bvh.triangle(slot as u32)), bits(tris[i as usize]));
    }
    assert!(seen.iter().all(|&s| s), "a triangle in no slot");
    let mut leaf_slots = vec![false; refs];
    let mut node_seen = vec![false; bvh.nodes.len()];
    // (node, depth, its box)
    let mut stack = vec![(0u32, 0u32, None::<(Vec3, Vec3)>)];
    while let Some((node, depth, parent)) = stack.pop() {
        assert!(depth < MAX_DEPTH, "interior node at depth {depth}");
        assert!(!node_seen[node as usize], "node {node} reached twice");
        node_seen[node as usize] = true;
        let nd = bvh.nodes[node as usize];
        // Any-hit walks visit child a first: the one of larger triangle area per unit of
        // the interior nodes' SAH cost below it (see `occluder_first` in build/layout.rs).
        let ((area_a, cost_a), (area_b, cost_b)) = (content(bvh, &nd.a()), content(bvh, &nd.b()));
        assert!(
            area_a * cost_b >= area_b * cost_a,
            "node {node}: child a holds less triangle area per unit of SAH cost"
        );
        for c in [nd.a(), nd.b()] {
            if c.is_empty() {
                continue;
            }
            if let Some((lo, hi)) = parent {
                assert!(c.min.cmpge(lo).all() && c.max.cmple(hi).all());
            }
            if c.is_leaf() {
                let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
                for slot in c.index..c.index + c.count {
                    assert!(!leaf_slots[slot as usize]);
                    leaf_slots[slot as usize] = true;
                    for v in bvh.triangle(slot) {
                        if builder == BvhBuilder::Binned {
                            assert!(v.cmpge(c.min).all() && v.cmple(c.max).all());
                        }
                        (lo, hi) = (lo.min(v), hi.max(v));
                    }
                }
                if builder == BvhBuilder::Split && lo.is_finite() && hi.is_finite() {
                    assert!(
                        c.min.cmpge(lo).all() && c.max.cmple(hi).all(),
                        "leaf box {} {} outside its triangles' box {lo} {hi}",
                        c.min,
                        c.max
                    );
                }
            } else {
                stack.push((c.index, depth + 1, Some((c.min, c.max))));
            }
        }
    }
    assert!(leaf_slots.iter().all(|&s| s), "a slot in no leaf");
    assert!(node_seen.iter().all(|&s| s), "an unreachable node");
    // Laid out depth first: each node's two subtrees right after it, one after the other
    // (child a's first, or child b's where occluder_first swapped them): the walk that
    // takes the child of lower index first meets the nodes in index order.
    let mut order = vec![0u32];
    let mut next = 0u32;
    while let Some(node) = order.pop() {
        assert_eq!(node, next, "node {node} out of depth-first order");
        next += 1;
        let nd = bvh.nodes[node as usize];
        let mut kids: Vec<u32> = [nd.a(), nd.b()]
            .iter()
            .filter(|c| !c.is_leaf() && c.min.x <= c.max.x)
            .map(|c| c.index)
            .collect();
        kids.sort_unstable_by(|x, y| y.cmp(x));
        order.extend(kids);
    }
    assert!(bvh.build_stats.max_depth <= MAX_DEPTH);
    // The statistics gathered while building are those of the finished tree.
    let mut walked = super::build::stats_by_walk(bvh);
    let built = &bvh.build_stats;
    assert!(
        (walked.sah_cost - built.sah_cost).abs() <= 1e-5 * built.sah_cost,
        "SAH cost {} built, {} walked",
        built.sah_cost,
        walked.sah_cost
    );
    walked.sah_cost = built.sah_cost;
    assert_eq!(&walked, built);
}

/// The triangle area and the interior nodes' SAH cost (not divided by any area) below a
/// child, summed as the builder sums them (slot by slot in a leaf, a's and b's for a
/// node), so that ties compare equal.
fn content(bvh: &Bvh, c: &BvhChild) -> (f32, f32) {
    if c.is_empty() {
        return (0.0, 0.0);
    }
    if c.count == 0 {
        let n = bvh.nodes[c.index as usize];
        let ((area_a, cost_a), (area_b, cost_b)) = (content(bvh, &n.a()), content(bvh, &n.b()));
        let visit = SAH_TRAVERSAL_COST * build::union(&n.a(), &n.b()).half_area();
        return (area_a + area_b, visit + cost_a + cost_b);
    }
    let area = (c.index..c.index + c.count)
        .map(|slot| {
            let [v0, v1, v2] = bvh.triangle(slot).map(glam::Vec3A::from);
            let a = 0.5 * (v1 - v0).cross(v2 - v0).length();
            if a.is_finite() {
                a
            } else {
                0.0
            }
        })
        .sum();
    (area, 0.0)
}

/// The BVH's closest hit must be the brute force's (same triangle, or another at the
/// bit-identical distance), its any-hit the same answer. Returns the number of hits.
fn check_ray(bvh: &Bvh, tris: &[[Vec3; 3]], o: Vec3, d: Vec3, tmax: f32) -> usize {
    let bf = brute_force_closest(tris, o, d, tmax);
    let bh = bvh.trace_closest(o, d, tmax);
    match (bf, bh) {
        (None, None) => {}
        (Some((i, t)), Some(h)) => {
            let j = bvh.tri_order[h.tri as usize];
            assert_eq!(
                t.to_bits(),
                h.t.to_bits(),
                "ray {o} {d}: brute force t {t} (tri {i}), bvh t {} (tri {j})",
                h.t
            );
            let [v0, v1, v2] = bvh.triangle(h.tri);
            let p = v0 * (1.0 - h.u - h.v) + v1 * h.u + v2 * h.v;
            let q = o + d * h.t;
            let scale = 1.0 + v0.abs().max(v1.abs()).max(v2.abs()).max_element();
            assert!((p - q).length() <= 1e-4 * scale, "barycentrics: {p} vs {q}");
        }
        (bf, bh) => panic!("ray {o} {d} tmax {tmax}: brute force {bf:?}, bvh {bh:?}"),
    }
    assert_eq!(
        brute_force_any(tris, o, d, tmax),
        bvh.trace_any(o, d, tmax),
        "any-hit of ray {o} {d} tmax {tmax}"
    );
    assert_eq!(bf.is_some(), bvh.trace_any(o, d, tmax));
    if tmax == 1.0 {
        assert_eq!(
            bf.is_some(),
            bvh.trace_segment(o, d),
            "segment walk of {o} {d}"
        );
    }
    usize::from(bf.is_some())
}

#[test]
fn node_layout_matches_wgsl() {
    assert_eq!(std::mem::size_of::<BvhNode>(), 64);
    // 16, as the build's references, whose allocation it reuses; the GPU does not care.
    assert_eq!(std::mem::align_of::<BvhNode>(), 16);
    let offsets = [
        std::mem::offset_of!(BvhNode, a_min),
        std::mem::offset_of!(BvhNode, a_index),
        std::mem::offset_of!(BvhNode, a_max),
        std::mem::offset_of!(BvhNode, a_count),
        std::mem::offset_of!(BvhNode, b_min),
        std::mem::offset_of!(BvhNode, b_index),
        std::mem::offset_of!(BvhNode, b_max),
        std::mem::offset_of!(BvhNode, b_count),
    ];
    assert_eq!(offsets, [0, 12, 16, 28, 32, 44, 48, 60]);
    assert_eq!(std::mem::size_of::<Hit>(), 16);
}

#[test]
fn empty_bvh_misses_everything() {
    let bvh = Bvh::build(&[]);
    assert_eq!(bvh.nodes.len(), 1);
    assert_eq!((bvh.build_stats.leaves, bvh.build_stats.max_depth), (0, 0));
    assert!(bvh.tri_rows.is_empty() && bvh.tri_order.is_empty());
    let mut r = rng(1);
    for _ in 0..100 {
        let o = rand_vec(&mut r, -10.0, 10.0);
        let d = rand_dir(&mut r);
        assert!(bvh.trace_closest(o, d, f32::INFINITY).is_none());
        assert!(!bvh.trace_any(o, d, f32::INFINITY));
    }
    // Rays along the axes, also through the origin.
    for d in [Vec3::X, Vec3::NEG_Y, Vec3::Z] {
        assert!(bvh.trace_closest(Vec3::ZERO, d, 1e30).is_none());
    }
    // The empty children are point boxes at +inf: rays of every octant and axis, the
    // ones heading their way included, miss them with the GPU's largest tmax (3.4e38)
    // and with an infinite one (a hit would test slot 0, which does not exist).
    for i in 0..27 {
        let d = Vec3::new(
            (i % 3) as f32 - 1.0,
            (i / 3 % 3) as f32 - 1.0,
            (i / 9) as f32 - 1.0,
        );
        if d == Vec3::ZERO {
            continue;
        }
        for tmax in [1.0, 3.4e38, f32::MAX, f32::INFINITY] {
            for o in [Vec3::ZERO, Vec3::splat(-1e7), Vec3::splat(1e7)] {
                assert!(bvh.trace_closest(o, d, tmax).is_none(), "{o} {d} {tmax}");
                assert!(!bvh.trace_any(o, d, tmax), "{o} {d} {tmax}");
            }
        }
    }
}

#[test]
fn single_triangle() {
    let tri = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    ];
    let t = crate::scene::Triangle {
        v: tri,
        n: [Vec3::Z; 3],
        material: 0,
    };
    let bvh = Bvh::build(&[t]);
    assert_eq!(bvh.nodes.len(), 1);
    assert_eq!(bvh.nodes[0].a_count, 1);
    assert_eq!(bvh.nodes[0].b(), BvhChild::EMPTY);
    check_structure(&bvh, &[tri]);
    let h = bvh
        .trace_closest(Vec3::new(0.25, 0.5, 2.0), Vec3::NEG_Z, 10.0)
        .unwrap();
    assert_eq!((h.t, h.tri, h.u, h.v), (2.0, 0, 0.25, 0.5));
    // From below (two-sided), a non-normalised direction: t in units of dir.
    let h = bvh
        .trace_closest(Vec3::new(0.25, 0.25, -1.0), Vec3::new(0.0, 0.0, 4.0), 10.0)
        .unwrap();
    assert_eq!(h.t, 0.25);
    // tmax is exclusive, and so is t = 0.
    assert!(bvh
        .trace_closest(Vec3::new(0.25, 0.5, 2.0), Vec3::NEG_Z, 2.0)
        .is_none());
    assert!(!bvh.trace_any(Vec3::new(0.25, 0.5, 0.0), Vec3::Z, 10.0));
    // Edges and vertices count.
    assert!(bvh.trace_any(Vec3::new(0.5, 0.0, 1.0), Vec3::NEG_Z, 10.0));
    assert!(bvh.trace_any(Vec3::new(0.5, 0.5, 1.0), Vec3::NEG_Z, 10.0));
    assert!(bvh.trace_any(Vec3::new(1.0, 0.0, 1.0), Vec3::NEG_Z, 10.0));
    assert!(!bvh.trace_any(Vec3::new(0.5, 0.51, 1.0), Vec3::NEG_Z, 10.0));
    // A zero direction hits nothing.
    assert!(bvh
        .trace_closest(Vec3::new(0.25, 0.25, 0.0), Vec3::ZERO, 10.0)
        .is_none());
}

#[test]
fn random_rays_match_brute_force() {
    for (seed, n) in [(2u64, 2usize), (3, 5), (4, 37), (5, 500), (6, 3000)] {
        let mut r = rng(seed);
        let tris = random_triangles(&mut r, n, 10.0, 2.0);
        let bvh = Bvh::build_from_vertices(&tris);
        check_structure(&bvh, &tris);
        let mut hits = 0;
        let rays = 2000;
        for k in 0..rays {
            let o = rand_vec(&mut r, -14.0, 14.0);
            let mut d = rand_dir(&mut r);
            if k % 7 == 0 {
                // Zero direction components: the finite-reciprocal slab path.
                d[k % 3] = 0.0;
                if k % 2 == 0 {
                    d[(k + 1) % 3] = -0.0;
                }
                if d == Vec3::ZERO {
                    d = Vec3::X;
                }
            }
            // Unnormalised directions and finite tmax (segments) too.
            let (d, tmax) = match k % 3 {
                0 => (d, f32::INFINITY),
                1 => (d * 3.7, 2.0),
                _ => (rand_vec(&mut r, -14.0, 14.0) - o, 1.0),
            };
            hits += check_ray(&bvh, &tris, o, d, tmax);
        }
        assert!(
            n < 500 || hits > rays / 20,
            "too few hits ({hits}) to mean anything"
        );
    }
}

#[test]
fn degenerate_and_identical_triangles() {
    let mut r = rng(7);
    let mut tris = random_triangles(&mut r, 200, 5.0, 1.0);
    // Zero-area triangles: a point, collinear vertices, a repeated vertex.
    let p = Vec3::new(0.5, 0.5, 0.5);
    tris.push([p, p, p]);
    tris.push([p, p + Vec3::X, p + 2.0 * Vec3::X]);
    tris.push([p, p, p + Vec3::Y]);
    // 50 copies of one triangle (identical centroids: split by index), and 50 different
    // triangles sharing one centroid.
    let t = [
        Vec3::new(-1.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 2.0, 0.0),
    ];
    tris.extend(std::iter::repeat_n(t, 50));
    let c = Vec3::new(2.0, -1.0, 3.0);
    for k in 0..50 {
        let a = k as f32 * 0.1;
        let (s, co) = a.sin_cos();
        let u = Vec3::new(co, s, 0.3) * 0.5;
        let v = Vec3::new(-s, co, -0.2) * 0.5;
        tris.push([c + u, c + v, c - u - v]);
    }
    let bvh = Bvh::build_from_vertices(&tris);
    check_structure(&bvh, &tris);
    for _ in 0..3000 {
        let o = rand_vec(&mut r, -7.0, 7.0);
        let d = rand_dir(&mut r);
        check_ray(&bvh, &tris, o, d, f32::INFINITY);
    }
    // Only identical triangles: the whole tree is index splits.
    let same = vec![t; 1000];
    let bvh = Bvh::build_from_vertices(&same);
    check_structure(&bvh, &same);
    assert!(bvh.build_stats.max_leaf_size as usize <= MAX_LEAF_SIZE);
    let h = bvh
        .trace_closest(Vec3::new(0.0, 0.5, -3.0), Vec3::Z, 10.0)
        .unwrap();
    assert_eq!(h.t, 3.0);
    assert!(bvh.trace_any(Vec3::new(0.0, 0.5, -3.0), Vec3::Z, 10.0));
    // Only degenerate triangles: built, never hit.
    let flat = vec![[p, p + Vec3::X, p + 2.0 * Vec3::X]; 10];
    let bvh = Bvh::build_from_vertices(&flat);
    check_structure(&bvh, &flat);
    assert!(!bvh.trace_any(p + Vec3::new(0.5, 0.0, -1.0), Vec3::Z, 10.0));
}

#[test]
fn depth_cap_makes_a_leaf_and_stays_correct() {
    let mut r = rng(8);
    let tris = random_triangles(&mut r, 3000, 10.0, 1.0);
    let full = Bvh::build_from_vertices(&tris);
    assert!(full.build_stats.max_depth > 8, "{:?}", full.build_stats);
    let bvh = super::build::build_with_max_depth(&tris, 8);
    check_structure(&bvh, &tris);
    let s = &bvh.build_stats;
    assert_eq!(s.max_depth, 8, "{s:?}");
    assert!(s.oversized_leaves >= 1 && s.max_leaf_size > 10, "{s:?}");
    assert!(s.leaves <= 1 << 8);
    for _ in 0..3000 {
        let o = rand_vec(&mut r, -12.0, 12.0);
        let d = rand_dir(&mut r);
        check_ray(&bvh, &tris, o, d, f32::INFINITY);
    }
    assert!(full.build_stats.sah_cost < s.sah_cost);
}

#[test]
fn rotations_lower_the_sah_cost_within_the_depth_cap() {
    let mut r = rng(21);
    // Clustered triangles of mixed sizes, where greedy binned splits leave room.
    let mut tris = random_triangles(&mut r, 3000, 40.0, 0.5);
    tris.extend(random_triangles(&mut r, 300, 40.0, 12.0));
    let split_only = super::build::build_with_rotations(&tris, MAX_DEPTH, 0);
    let rotated = Bvh::build_from_vertices(&tris);
    check_structure(&split_only, &tris);
    check_structure(&rotated, &tris);
    let (before, after) = (&split_only.build_stats, &rotated.build_stats);
    assert!(
        after.sah_cost < 0.99 * before.sah_cost,
        "{before:?} -> {after:?}"
    );
    assert_eq!((after.nodes, after.leaves), (before.nodes, before.leaves));
    for _ in 0..2000 {
        let o = rand_vec(&mut r, -45.0, 45.0);
        let d = rand_dir(&mut r);
        check_ray(&rotated, &tris, o, d, f32::INFINITY);
        check_ray(&rotated, &tris, o, d * 20.0, 1.0);
    }
    // Rotations deepen some subtrees; none may take an interior node to the cap, but the
    // others still pay.
    let cap = before.max_depth;
    assert!(
        after.max_depth > cap,
        "the test needs rotations that deepen the tree"
    );
    let capped = super::build::build_with_max_depth(&tris, cap);
    check_structure(&capped, &tris);
    let c = &capped.build_stats;
    assert!(c.max_depth <= cap, "{c:?}");
    assert!(c.sah_cost < 0.99 * before.sah_cost, "{before:?} -> {c:?}");
    for _ in 0..500 {
        let o = rand_vec(&mut r, -45.0, 45.0);
        let d = rand_dir(&mut r);
        check_ray(&capped, &tris, o, d, f32::INFINITY);
    }
}

/// A closed triangulated sphere with shared vertices (UV sphere).
fn sphere(center: Vec3, radius: f32, rings: usize, segments: usize) -> Vec<[Vec3; 3]> {
    let pole_n = center + Vec3::Y * radius;
    let pole_s = center - Vec3::Y * radius;
    let vert = |i: usize, j: usize| {
        let th = std::f32::consts::PI * i as f32 / rings as f32;
        let ph = 2.0 * std::f32::consts::PI * (j % segments) as f32 / segments as f32;
        center + radius * Vec3::new(th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin())
    };
    let mut tris = vec![];
    for j in 0..segments {
        tris.push([pole_n, vert(1, j + 1), vert(1, j)]);
        tris.push([pole_s, vert(rings - 1, j), vert(rings - 1, j + 1)]);
        for i in 1..rings - 1 {
            let (a, b, c, d) = (
                vert(i, j),
                vert(i, j + 1),
                vert(i + 1, j),
                vert(i + 1, j + 1),
            );
            tris.push([a, b, d]);
            tris.push([a, d, c]);
        }
    }
    tris
}

#[test]
fn closed_meshes_are_watertight() {
    let mut r = rng(9);
    for (center, radius) in [
        (Vec3::ZERO, 1.0),
        (Vec3::new(700.0, 300.0, -200.0), 250.0),
        (Vec3::new(0.01, -0.02, 0.0), 0.003),
    ] {
        let tris = sphere(center, radius, 24, 48);
        let bvh = Bvh::build_from_vertices(&tris);
        check_structure(&bvh, &tris);
        let mut aimed = 0;
        for k in 0..20_000 {
            let o = center + rand_vec(&mut r, -0.5, 0.5) * radius;
            // Aim at vertices and edges of the mesh, where a leaky test lets rays out.
            let d = match k % 3 {
                0 => rand_dir(&mut r),
                1 => {
                    let t = tris[r.random_range(0..tris.len())];
                    aimed += 1;
                    t[r.random_range(0..3)] - o
                }
                _ => {
                    let t = tris[r.random_range(0..tris.len())];
                    let s: f32 = r.random_range(0.0..1.0);
                    let e = r.random_range(0..3);
                    aimed += 1;
                    t[e] + s * (t[(e + 1) % 3] - t[e]) - o
                }
            };
            assert!(
                bvh.trace_any(o, d, f32::INFINITY),
                "ray from {o} along {d} escaped the sphere at {center}"
            );
            assert!(bvh.trace_closest(o, d, f32::INFINITY).is_some());
        }
        assert!(aimed > 10_000);
    }
}

#[test]
fn axis_aligned_rays_in_a_box_room() {
    // A closed axis-aligned box: rays along the axes (two zero direction components)
    // from inside, also starting on the box's planes extended, must all hit a wall.
    let (lo, hi) = (Vec3::new(-3.0, 0.0, -1.0), Vec3::new(5.0, 2.0, 4.0));
    let c = |i: usize| {
        Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        )
    };
    let quads = [
        [0, 1, 3, 2],
        [4, 6, 7, 5],
        [0, 4, 5, 1],
        [2, 3, 7, 6],
        [0, 2, 6, 4],
        [1, 5, 7, 3],
    ];
    let mut tris = vec![];
    for q in quads {
        tris.push([c(q[0]), c(q[1]), c(q[2])]);
        tris.push([c(q[0]), c(q[2]), c(q[3])]);
    }
    let bvh = Bvh::build_from_vertices(&tris);
    let mut r = rng(10);
    for k in 0..3000 {
        let mut o = lo + (hi - lo) * rand_vec(&mut r, 0.0, 1.0);
        if k % 4 == 0 {
            o.x = 1.0; // a plane through a diagonal of no wall, and the box's middle
        }
        for d in [
            Vec3::X,
            Vec3::NEG_X,
            Vec3::Y,
            Vec3::NEG_Y,
            Vec3::Z,
            Vec3::NEG_Z,
        ] {
            assert!(bvh.trace_any(o, d, f32::INFINITY), "{o} {d}");
            check_ray(&bvh, &tris, o, d, f32::INFINITY);
        }
        // Origins on a wall's plane, rays running inside that plane: the wall itself is
        // parallel (no hit), so only the edges of the walls across can stop them. The
        // walls' boxes are flat and the origin lies on their planes: the parallel-axis
        // case of the slab test.
        let axis = k % 3;
        o[axis] = if k % 2 == 0 { lo[axis] } else { hi[axis] };
        for d in [
            Vec3::X,
            Vec3::NEG_X,
            Vec3::Y,
            Vec3::NEG_Y,
            Vec3::Z,
            Vec3::NEG_Z,
        ] {
            if d[axis] != 0.0 {
                continue;
            }
            assert!(bvh.trace_any(o, d, f32::INFINITY), "in-plane {o} {d}");
            check_ray(&bvh, &tris, o, d, f32::INFINITY);
        }
    }
}

/// A random point on a triangle by barycentrics, as a renderer computes hit points.
fn point_on(r: &mut Pcg64, t: &[Vec3; 3]) -> Vec3 {
    let mut u: f32 = r.random_range(0.0..1.0);
    let mut v: f32 = r.random_range(0.0..1.0);
    if u + v > 1.0 {
        (u, v) = (1.0 - u, 1.0 - v);
    }
    t[0] * (1.0 - u - v) + t[1] * u + t[2] * v
}

/// A direction in the hemisphere around n, cosine at least `min_cos`.
fn hemisphere(r: &mut Pcg64, n: Vec3, min_cos: f32) -> Vec3 {
    loop {
        let d = rand_dir(r);
        let c = d.dot(n);
        if c >= min_cos {
            return d;
        }
        if -c >= min_cos {
            return -d;
        }
    }
}

#[test]
fn offset_origin_never_hits_its_own_triangle() {
    let mut r = rng(11);
    let mut grazing = 0;
    // (where the triangles are, how big they are): tiny near the origin, unit, the
    // conference room (~1000 units, triangles up to a wall's size), far from the origin.
    for (extent, size) in [
        (1e-3f32, 1e-3f32),
        (0.02, 0.01),
        (1.0, 0.5),
        (1000.0, 1.0),
        (1000.0, 300.0),
        (1.0e5, 50.0),
    ] {
        for _ in 0..2000 {
            let c = rand_vec(&mut r, -extent, extent);
            let t = [
                c + rand_vec(&mut r, -size, size),
                c + rand_vec(&mut r, -size, size),
                c + rand_vec(&mut r, -size, size),
            ];
            let n = (t[1] - t[0]).cross(t[2] - t[0]);
            if n.length() < 1e-3 * size * size {
                continue; // a sliver: its normal is meaningless
            }
            let n = n.normalize();
            for _ in 0..10 {
                let p = point_on(&mut r, &t);
                for side in [n, -n] {
                    let o = offset_ray_origin(p, side, floor_of(&[t]));
                    // Directions down to 1 degree above the surface.
                    let d = hemisphere(&mut r, side, 0.02);
                    grazing += usize::from(d.dot(side) < 0.1);
                    assert!(
                        brute_force_closest(&[t], o, d, f32::INFINITY).is_none(),
                        "self-hit: triangle {t:?}, p {p}, n {side}, o {o}, d {d}"
                    );
                }
            }
        }
    }
    assert!(grazing > 1000);
}

/// A floor of two huge triangles near y = 0 (the conference room's: 2,600 x 1,700 units
/// at y = -1.57), so that a point on it has a small y but far vertices: Wächter and
/// Binder's offset (256 ulps of each coordinate, 3e-5 here) is smaller than the triangle
/// test's error from across the room (~1e-4). With the scene's offset floor, segments
/// between the floor and points above it are not occluded by the floor at either end,
/// and real occluders near an end still occlude.
#[test]
fn segments_ending_on_a_huge_floor_are_not_occluded_by_it() {
    let y = -1.57216f32;
    let (x0, x1, z0, z1) = (-946.888f32, 1653.25f32, -1016.1f32, 668.489f32);
    let floor = [
        [
            Vec3::new(x0, y, z0),
            Vec3::new(x0, y, z1),
            Vec3::new(x1, y, z0),
        ],
        [
            Vec3::new(x0, y, z1),
            Vec3::new(x1, y, z1),
            Vec3::new(x1, y, z0),
        ],
    ];
    let mut r = rng(13);
    let mut tris: Vec<[Vec3; 3]> = floor.to_vec();
    // Small occluders 0.5 above the floor (a table top's corner).
    let mut plates = vec![];
    for _ in 0..64 {
        let c = Vec3::new(r.random_range(x0..x1), y + 0.5, r.random_range(z0..z1));
        tris.push([
            c + Vec3::new(-1.0, 0.0, -1.0),
            c + Vec3::new(1.0, 0.0, -1.0),
            c + Vec3::new(0.0, 0.0, 1.5),
        ]);
        plates.push(c);
    }
    let offset = floor_of(&tris);
    assert_eq!(
        offset,
        1.0 / 256.0,
        "32 ulps of 1,653 (0.0032), up to a power of two"
    );
    let up = Vec3::Y;
    // Ends of the two segments the CPU check of the conference room found occluded by
    // the floor before the offset floor existed: at the origin, and at the far end.
    let x = Vec3::new(676.25275, y, 182.99976);
    let d = Vec3::new(-0.85514784, 0.4653153, 0.22848178);
    let mut pairs = vec![(x, up, x + 1400.8771 * d, -d)];
    let o = Vec3::new(-46.592667, 415.80115, 591.5684);
    let d = Vec3::new(-0.16887122, -0.25045708, -0.95328575);
    let e = o + 1666.4464 * d;
    pairs.push((o, d, Vec3::new(e.x, y, e.z), up));
    // And random ones: a floor point and a point in the room above it.
    for i in 0..4000 {
        let p = point_on(&mut r, &floor[i % 2]);
        let h = Vec3::new(
            r.random_range(x0..x1),
            r.random_range(1.0..700.0),
            r.random_range(z0..z1),
        );
        pairs.push((Vec3::new(p.x, y, p.z), up, h, -up));
    }
    let floor_bvh = Bvh::build_from_vertices(&floor);
    for &(a, na, b, nb) in &pairs {
        for (a, na, b, nb) in [(a, na, b, nb), (b, nb, a, na)] {
            let (o, d) = shadow_segment(a, na, b, nb, offset);
            assert!(
                !brute_force_any(&floor, o, d, 1.0) && !floor_bvh.trace_segment(o, d),
                "segment {a} -> {b} occluded by the floor it ends on"
            );
        }
    }
    // Real occluders near an end stay occluders: segments from the floor up through a
    // plate 0.5 above it (1/1000 of the 500-unit segment).
    let bvh = Bvh::build_from_vertices(&tris);
    for c in &plates {
        let x = Vec3::new(c.x, y, c.z + 0.25);
        let h = Vec3::new(c.x + 1.0, 500.0, c.z + 0.3);
        for (a, na, b, nb) in [(x, up, h, -up), (h, -up, x, up)] {
            let (o, d) = shadow_segment(a, na, b, nb, offset);
            assert!(
                bvh.trace_segment(o, d),
                "segment {a} -> {b} missed the plate at {c}"
            );
        }
    }
}

#[test]
fn offset_floor_is_a_power_of_two_above_32_ulps_of_the_largest_coordinate() {
    let f = |m: f32| offset_floor(Vec3::new(-m, 0.0, 0.0), Vec3::new(0.5 * m, 0.0, 0.0));
    assert_eq!(f(1.0), 1.0 / 524_288.0, "32 x 2^-24 = 2^-19 exactly");
    for m in [1e-6f32, 3e-3, 0.7, 1.0, 1653.25, 12_345.0, 3e7] {
        let x = f(m);
        assert_eq!(x.to_bits() & 0x007f_ffff, 0, "{x} is a power of two");
        let least = OFFSET_FLOOR_ULPS * f32::EPSILON * 0.5 * m;
        assert!(x >= least && x < 2.0 * least, "{x} for m = {m}");
    }
    let empty = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    assert_eq!(offset_floor(empty.0, empty.1), 0.0);
    assert_eq!(offset_floor(Vec3::ZERO, Vec3::ZERO), 0.0);
}

/// The bounds of a triangle list, and the offset floor of that "scene".
fn floor_of(tris: &[[Vec3; 3]]) -> f32 {
    let (lo, hi) = tris.iter().flatten().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), &v| (lo.min(v), hi.max(v)),
    );
    offset_floor(lo, hi)
}

#[test]
fn segments_between_facing_planes_are_unoccluded() {
    let mut r = rng(12);
    for (extent, size, gap) in [
        (1e-3f32, 1e-2f32, 1e-3f32),
        (1.0, 2.0, 0.01),
        (1.0, 2.0, 1.0),
        (1000.0, 1000.0, 1.0),
        (1000.0, 1000.0, 500.0),
        (1.0e4, 2000.0, 10.0),
    ] {
        for _ in 0..50 {
            // Two parallel planes (quads of two triangles), at random orientation.
            let n = rand_dir(&mut r);
            let u = n.any_orthonormal_vector();
            let w = n.cross(u);
            let c = rand_vec(&mut r, -extent, extent);
            let quad = |o: Vec3| {
                let p = |a: f32, b: f32| o + size * (a * u + b * w);
                let (p00, p10, p11, p01) = (p(-1.0, -1.0), p(1.0, -1.0), p(1.0, 1.0), p(-1.0, 1.0));
                [[p00, p10, p11], [p00, p11, p01]]
            };
            let q1 = quad(c);
            let q2 = quad(c + gap * n);
            let tris: Vec<[Vec3; 3]> = q1.iter().chain(q2.iter()).copied().collect();
            let bvh = Bvh::build_from_vertices(&tris);
            let offset = floor_of(&tris);
            // The normals as a renderer has them: from the triangles' own vertices.
            let normal = |t: &[Vec3; 3]| (t[1] - t[0]).cross(t[2] - t[0]).normalize();
            for _ in 0..200 {
                let t1 = &q1[r.random_range(0..2)];
                let t2 = &q2[r.random_range(0..2)];
                let x = point_on(&mut r, t1);
                let y = point_on(&mut r, t2);
                let (o, d) = shadow_segment(x, normal(t1), y, normal(t2), offset);
                assert!(
                    !bvh.trace_segment(o, d),
                    "segment {x} -> {y} occluded (gap {gap}, size {size})"
                );
                let (o, d) = shadow_segment(y, normal(t2), x, normal(t1), offset);
                assert!(!bvh.trace_segment(o, d), "segment {y} -> {x} occluded");
                // A segment that goes on beyond the far plane must be occluded by it.
                // Aimed at the inner half of the far quad: the offset of x shifts where a
                // grazing segment crosses it by up to offset * length / gap.
                let yc = c + gap * n + 0.5 * (y - c - gap * n);
                let (o, d) = shadow_segment(x, normal(t1), yc + (yc - x), normal(t2), offset);
                assert!(
                    bvh.trace_segment(o, d),
                    "segment {x} -> {} through the far plane missed it (gap {gap}, size {size})",
                    yc + (yc - x)
                );
            }
        }
    }
}

#[test]
fn parallel_build_is_deterministic_and_correct() {
    // Large enough for the threaded top levels and the threaded binning of the root
    // (the result must not depend on the number of threads).
    let mut r = rng(13);
    let tris = random_triangles(&mut r, 70_000, 100.0, 1.5);
    let a = Bvh::build_from_vertices(&tris);
    let b = Bvh::build_from_vertices(&tris);
    assert_eq!(a.nodes, b.nodes);
    assert_eq!(a.tri_order, b.tri_order);
    // Subtrees built side by side in their own regions of the node array give the tree
    // that one thread builds.
    let one = super::build::build_on_one_thread(&tris);
    assert_eq!(a.nodes, one.nodes);
    assert_eq!(a.tri_order, one.tri_order);
    assert_eq!(a.tri_rows, one.tri_rows);
    check_structure(&a, &tris);
    for _ in 0..300 {
        let o = rand_vec(&mut r, -120.0, 120.0);
        let d = rand_dir(&mut r);
        check_ray(&a, &tris, o, d, f32::INFINITY);
    }
}

/// Long thin triangles at random orientations (the kind early split clipping cuts).
fn slivers(r: &mut Pcg64, n: usize, extent: f32) -> Vec<[Vec3; 3]> {
    (0..n)
        .map(|_| {
            let a = rand_vec(r, -extent, extent);
            let b = rand_vec(r, -extent, extent);
            let e = rand_vec(r, -0.01 * extent, 0.01 * extent);
            [a, b, a + e]
        })
        .collect()
}

#[test]
fn split_pieces_cover_their_triangle() {
    // Every point of a triangle must lie in the box of one of its pieces: otherwise a ray
    // hitting it there never reaches its leaf.
    let mut r = rng(21);
    let far = Vec3::new(1e6, -3e5, 2e5);
    let groups = [
        slivers(&mut r, 300, 50.0),
        random_triangles(&mut r, 300, 1000.0, 300.0),
        // Near the origin and far from it: the padding is relative to the coordinates.
        slivers(&mut r, 100, 1e-3),
        slivers(&mut r, 300, 10.0)
            .into_iter()
            .map(|t| t.map(|v| v + far))
            .collect(),
    ];
    for tris in &groups {
        check_pieces(tris, &mut r);
    }
}

fn check_pieces(tris: &[[Vec3; 3]], r: &mut Pcg64) {
    let (mut prims, bounds, _, areas) = super::build::whole_references(tris, 0);
    let mut ids: Vec<u32> = (0..tris.len() as u32).collect();
    super::split::split_references(&mut prims, &mut ids, &areas, &bounds, tris);
    assert_eq!(prims.len(), ids.len());
    assert!(prims.len() > tris.len(), "nothing was split");
    let mut pieces = vec![vec![]; tris.len()];
    for (p, &i) in prims.iter().zip(&ids) {
        pieces[i as usize].push(*p);
    }
    for (i, t) in tris.iter().enumerate() {
        let box_lo = t[0].min(t[1]).min(t[2]);
        let box_hi = t[0].max(t[1]).max(t[2]);
        assert!(!pieces[i].is_empty() && pieces[i].len() <= 1 << super::split::SPLIT_DEPTH);
        for p in &pieces[i] {
            let (lo, hi) = (Vec3::from(p.lo), Vec3::from(p.hi));
            assert!(
                lo.cmpge(box_lo).all() && hi.cmple(box_hi).all(),
                "piece outside its triangle's box"
            );
        }
        // In f64, exactly on the triangle: its vertices, random interior and edge
        // points, and where its edges cross every face plane of its pieces (the clip
        // points, which the builder computed in rounded f32).
        let t64 = t.map(|v| v.as_dvec3());
        let mut points = t64.to_vec();
        for _ in 0..100 {
            let (u, v): (f64, f64) = (r.random(), r.random());
            let (u, v) = if u + v > 1.0 {
                (1.0 - u, 1.0 - v)
            } else {
                (u, v)
            };
            points.push(t64[0] + (t64[1] - t64[0]) * u + (t64[2] - t64[0]) * v);
            points.push(t64[0] + (t64[2] - t64[0]) * u);
        }
        for p in &pieces[i] {
            for axis in 0..3 {
                for c in [p.lo[axis] as f64, p.hi[axis] as f64] {
                    for k in 0..3 {
                        let (a, b) = (t64[k], t64[(k + 1) % 3]);
                        if (a[axis] - c) * (b[axis] - c) < 0.0 {
                            points.push(a + (b - a) * ((c - a[axis]) / (b[axis] - a[axis])));
                        }
                    }
                }
            }
        }
        for q in points {
            assert!(
                pieces[i]
                    .iter()
                    .any(|p| q.cmpge(Vec3::from(p.lo).as_dvec3()).all()
                        && q.cmple(Vec3::from(p.hi).as_dvec3()).all()),
                "triangle {i} {t:?}: point {q} in none of its pieces {:?}",
                pieces[i]
            );
        }
    }
}

#[test]
fn split_build_answers_as_brute_force() {
    for (seed, kind) in [(31u64, 0), (32, 1), (33, 2)] {
        let mut r = rng(seed);
        let mut tris = match kind {
            0 => slivers(&mut r, 2000, 10.0),
            1 => random_triangles(&mut r, 3000, 10.0, 2.0),
            _ => {
                // A few of everything, with degenerate and non-finite triangles.
                let mut t = slivers(&mut r, 50, 10.0);
                t.extend(random_triangles(&mut r, 50, 10.0, 4.0));
                t.push([Vec3::ONE, Vec3::ONE, Vec3::ONE]);
                t.push([Vec3::ZERO, Vec3::X * 5.0, Vec3::X * 9.0]);
                t.push([Vec3::ZERO, Vec3::new(f32::NAN, 0.0, 0.0), Vec3::Y]);
                t.push([Vec3::ZERO, Vec3::new(f32::INFINITY, 1.0, 0.0), Vec3::Y]);
                t
            }
        };
        tris.push([
            Vec3::new(-9.0, -9.0, 0.5),
            Vec3::new(9.0, 9.0, 0.5),
            Vec3::new(9.0, 9.1, 0.5),
        ]);
        let bvh = Bvh::build_from_vertices_with(&tris, BvhBuilder::Split);
        check_structure_of(&bvh, &tris, BvhBuilder::Split);
        assert!(bvh.tri_order.len() > tris.len(), "nothing was split");
        let mut hits = 0;
        for k in 0..3000 {
            let o = rand_vec(&mut r, -14.0, 14.0);
            let (d, tmax) = match k % 3 {
                0 => (rand_dir(&mut r), f32::INFINITY),
                1 => (rand_dir(&mut r) * 3.7, 2.0),
                _ => (rand_vec(&mut r, -14.0, 14.0) - o, 1.0),
            };
            hits += check_ray(&bvh, &tris, o, d, tmax);
        }
        assert!(hits > 100, "too few hits ({hits}) to mean anything");
    }
}

#[test]
fn split_build_tests_fewer_triangles_on_slivers() {
    // What the builder is for: on long thin triangles, segments test fewer triangles (the
    // walk's nodes may grow a little). Counted on the CPU twin, the GPU's walk.
    let mut r = rng(41);
    let tris = slivers(&mut r, 5000, 10.0);
    let count = |bvh: &Bvh, r: &mut Pcg64| {
        let (mut nodes, mut tests) = (0u64, 0u64);
        for _ in 0..5000 {
            let o = rand_vec(r, -10.0, 10.0);
            let d = rand_vec(r, -10.0, 10.0) - o;
            let (_, n, t) = traverse::trace_segment_counted(bvh, o, d);
            (nodes, tests) = (nodes + n as u64, tests + t as u64);
        }
        (nodes, tests)
    };
    let binned = Bvh::build_from_vertices(&tris);
    let split = Bvh::build_from_vertices_with(&tris, BvhBuilder::Split);
    let (bn, bt) = count(&binned, &mut rng(42));
    let (sn, st) = count(&split, &mut rng(42));
    println!("binned: {bn} nodes, {bt} triangle tests; split: {sn} nodes, {st} triangle tests");
    assert!(st * 2 < bt, "triangle tests {bt} -> {st}");
    assert!(split.build_stats.sah_cost < binned.build_stats.sah_cost);
}

#[test]
fn rays_through_tile_corners_far_from_the_origin_hit() {
    // A floor of axis-aligned square tiles (flat leaf boxes) far from the world origin,
    // and segments from far-off origins ending beyond the floor, aimed exactly at tile
    // corners: every such point lies on the boxes' boundaries on both floor axes. The
    // slab test's distances are fma(b, inv, -o inv) (SLAB_PAD): the rounding of o inv is
    // an absolute error of the plane distances, here far above the relative margin of
    // BOX_TFAR_SCALE, so without the pad boxes are missed by an ulp and rays pass
    // between the tiles (this test fails with SLAB_PAD = 0); watertight triangle tests
    // count corner hits. The exact form (b - o) inv that the fma replaced failed it too,
    // in a closest hit: a tile's entry distance rounded one ulp above the hit found so
    // far, so the walk pruned it and returned a hit one ulp farther than brute force.
    let mut r = rng(21);
    for &(base, tile) in &[(1.0e5f32, 1.0f32), (3.0e6, 16.0), (-2.5e5, 0.25)] {
        let n = 24;
        let corner = |i: usize, j: usize| {
            Vec3::new(base + i as f32 * tile, -base * 0.5, base + j as f32 * tile)
        };
        let mut tris = vec![];
        for i in 0..n {
            for j in 0..n {
                let (a, b, c, d) = (
                    corner(i, j),
                    corner(i + 1, j),
                    corner(i + 1, j + 1),
                    corner(i, j + 1),
                );
                tris.push([a, b, c]);
                tris.push([a, c, d]);
            }
        }
        let bvh = Bvh::build_from_vertices(&tris);
        for _ in 0..4000 {
            let target = corner(r.random_range(1..n), r.random_range(1..n));
            let side = rand_vec(&mut r, -60.0, 60.0) * tile;
            let above = r.random_range(3.0..90.0) * tile;
            let o = target + Vec3::new(side.x, above, side.z);
            // tmax 2: the segment ends as far below the floor as it starts above.
            let d = target - o;
            assert!(bvh.trace_any(o, d, 2.0), "any hit: {o} -> {target}");
            check_ray(&bvh, &tris, o, d, 2.0);
        }
    }
}

/// Whether the ray meets the box at some t in (0, tmax], in f64 on the f32 data (the
/// differences b - o are exact in f64; only the division rounds, at 2^-53), by a margin of
/// 1e-12 relative: the boxes a conservative slab test must hit. No parallel axes.
fn box_met_exactly(min: [f32; 3], max: [f32; 3], o: Vec3, d: Vec3, tmax: f32) -> bool {
    let (mut near, mut far) = (0.0f64, tmax as f64);
    for k in 0..3 {
        let t0 = (min[k] as f64 - o[k] as f64) / d[k] as f64;
        let t1 = (max[k] as f64 - o[k] as f64) / d[k] as f64;
        near = near.max(t0.min(t1));
        far = far.min(t0.max(t1));
    }
    far > 0.0 && near <= far - 1e-12 * near.abs().max(far.abs())
}

/// Random rays (no parallel axes) with boxes around points of them: random ones, and
/// boxes the ray only grazes, entering one slab where it leaves another at a point of
/// the ray (a corner or an edge of the box on the ray), near t = 1 half the time.
fn grazing_boxes(r: &mut Pcg64, n: usize) -> Vec<(Vec3, Vec3, [f32; 3], [f32; 3])> {
    let mut out = vec![];
    while out.len() < n {
        let scale = [1e-2f32, 1.0, 100.0, 1e4][r.random_range(0..4)];
        let o = rand_vec(r, -1.0, 1.0) * scale;
        let d = rand_dir(r) * scale * r.random_range(0.1..3.0);
        if d.abs().min_element() < 1e-3 * d.abs().max_element() {
            continue;
        }
        let t = if r.random_bool(0.5) {
            r.random_range(0.98..1.02)
        } else {
            r.random_range(0.0..1.5)
        };
        let p = o + t * d;
        let ext = |r: &mut Pcg64| r.random_range(0.0..0.5) * d.abs().max_element();
        let (mut lo, mut hi) = ([0.0f32; 3], [0.0f32; 3]);
        for k in 0..3 {
            (lo[k], hi[k]) = (p[k] - ext(r), p[k] + ext(r));
        }
        if r.random_bool(0.8) {
            // Enter axis a and leave axis b at p.
            let a = r.random_range(0..3);
            let b = (a + r.random_range(1..3)) % 3;
            if d[a] > 0.0 {
                lo[a] = p[a];
            } else {
                hi[a] = p[a];
            }
            if d[b] > 0.0 {
                hi[b] = p[b];
            } else {
                lo[b] = p[b];
            }
        }
        out.push((o, d, lo, hi));
    }
    out
}

#[test]
fn slab_tests_hit_every_box_the_exact_ray_meets() {
    // The conservative slab test (SLAB_PAD, BOX_TFAR_SCALE) and the segment walk's
    // (SEGMENT_PAD in place of the scale) on boxes a ray grazes within 1e-12: neither may
    // miss one. Without the pad and the scale the same boxes are missed by rounding.
    use traverse::{box_hit, TraceRay, BOX_TFAR_SCALE, SEGMENT_PAD};
    let mut r = rng(104);
    let cases = grazing_boxes(&mut r, 200_000);
    let (mut met, mut missed_unpadded) = (0, 0);
    for &(o, d, lo, hi) in &cases {
        let tmax = if r.random_bool(0.5) {
            1.0
        } else {
            r.random_range(0.5..2.0)
        };
        if !box_met_exactly(lo, hi, o, d, tmax) {
            continue;
        }
        met += 1;
        let ray = TraceRay::new(o, d, 0.0).unwrap();
        assert!(
            box_hit(lo, hi, &ray, tmax, BOX_TFAR_SCALE),
            "scaled walk missed {lo:?} {hi:?} from {o} along {d}, tmax {tmax}"
        );
        missed_unpadded += usize::from(!box_hit(lo, hi, &ray, tmax, 1.0));
        if tmax == 1.0 {
            let segment = TraceRay::new(o, d, SEGMENT_PAD).unwrap();
            assert!(
                box_hit(lo, hi, &segment, 1.0, 1.0),
                "segment walk missed {lo:?} {hi:?} from {o} along {d}"
            );
        }
    }
    println!(
        "{met} boxes met of {}; without the scale, {missed_unpadded} missed",
        cases.len()
    );
    assert!(met > cases.len() / 4, "too few boxes met ({met})");
    assert!(
        missed_unpadded > 0,
        "the cases do not graze: the test could not fail"
    );
}

#[test]
fn slab_minima_on_bits_agree_with_floats() {
    // box_span takes its minima and maxima on the distances' bits; where that can differ
    // from floats (negative distances, -0) the box must still be hit wherever floats hit
    // it at some t > 0, and with the floats' entry and exit.
    use traverse::{box_span, TraceRay, BOX_TFAR_SCALE};
    let float_span = |lo: [f32; 3], hi: [f32; 3], o: Vec3, d: Vec3, tmax: f32| {
        let ray = TraceRay::new(o, d, 0.0).unwrap();
        let (t0, t1) = ray.plane_distances(lo, hi);
        let (tn, tf) = (t0.min(t1), t0.max(t1));
        let near = tn.x.max(tn.y).max(tn.z.max(0.0));
        let far = (tf.x.min(tf.y).min(tf.z) * BOX_TFAR_SCALE).min(tmax);
        (near, far)
    };
    let mut r = rng(105);
    let mut cases = grazing_boxes(&mut r, 100_000);
    // Origins and planes on zero coordinates (distances of +-0), and axis-parallel rays.
    for _ in 0..100_000 {
        let o =
            rand_vec(&mut r, -2.0, 2.0)
                .to_array()
                .map(|c| if r.random_bool(0.4) { 0.0 } else { c });
        let mut d = rand_dir(&mut r);
        for k in 0..3 {
            if r.random_bool(0.2) {
                d[k] = [0.0, -0.0, 1e-31][r.random_range(0..3)];
            }
        }
        let c = |r: &mut Pcg64| {
            if r.random_bool(0.4) {
                0.0
            } else {
                r.random_range(-2.0..2.0f32)
            }
        };
        let (a, b) = (
            [c(&mut r), c(&mut r), c(&mut r)],
            [c(&mut r), c(&mut r), c(&mut r)],
        );
        let lo = std::array::from_fn(|k| a[k].min(b[k]));
        let hi = std::array::from_fn(|k| a[k].max(b[k]));
        cases.push((Vec3::from(o), d, lo, hi));
    }
    let (mut hits, mut zeros) = (0, 0);
    for &(o, d, lo, hi) in &cases {
        if d == Vec3::ZERO {
            continue;
        }
        let tmax = r.random_range(0.5..2.0);
        let (fnear, ffar) = float_span(lo, hi, o, d, tmax);
        let (near, far) = box_span(
            lo,
            hi,
            &TraceRay::new(o, d, 0.0).unwrap(),
            tmax,
            BOX_TFAR_SCALE,
        );
        if fnear <= ffar && ffar > 0.0 {
            hits += 1;
            assert!(
                near <= far && near == fnear && far == ffar,
                "bits ({near}, {far}), floats ({fnear}, {ffar}): {lo:?} {hi:?} from {o} along {d}"
            );
        } else if fnear <= ffar {
            zeros += 1;
        }
    }
    println!(
        "{hits} boxes hit of {}, {zeros} at t = 0 alone",
        cases.len()
    );
    assert!(hits > cases.len() / 4, "too few hits ({hits})");
}

/// The layout goes where the references were and the rows where the node places were
/// (their pages are mapped already); where an allocation does not fit, a new one.
#[test]
fn finished_buffers_are_reused_where_they_fit() {
    use super::build::{places_as_rows, reuse_vec, PrimRef};
    let prims: Vec<PrimRef> = Vec::with_capacity(10);
    let at = prims.as_ptr() as usize;
    let nodes: Vec<BvhNode> = reuse_vec(prims, 5);
    assert_eq!((nodes.as_ptr() as usize, nodes.capacity()), (at, 5));
    // Too small (a new one has exactly the capacity asked for), or an odd number of
    // references (half a node), which cannot be cast: new allocations.
    let nodes: Vec<BvhNode> = reuse_vec(nodes, 6);
    assert_eq!((nodes.len(), nodes.capacity()), (0, 6));
    let odd: Vec<PrimRef> = Vec::with_capacity(9);
    let nodes: Vec<BvhNode> = reuse_vec(odd, 3);
    assert_eq!((nodes.len(), nodes.capacity()), (0, 3));

    let places: Box<[std::mem::MaybeUninit<BvhNode>]> = Box::new_uninit_slice(3);
    let at = places.as_ptr() as usize;
    let rows = places_as_rows(places);
    assert_eq!(
        (rows.as_ptr() as usize, rows.capacity(), rows.len()),
        (at, 12, 0)
    );
}
