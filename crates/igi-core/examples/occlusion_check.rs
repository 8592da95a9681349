//! Checks the BVH's shadow-ray answers against an f64 test of every triangle: how many
//! segments the f32 walk calls occluded that no triangle crosses ("false occlusions"),
//! and how many it calls free that one does ("missed"). The measurement behind the ray
//! offset floor (`igi_core::bvh::offset_floor`).
//!
//! `cargo run --release -p igi-core --example occlusion_check -- [SCENE.toml] [COUNT] [FLOOR]`
//! (defaults: the conference room of `shared/scenes`, 3,000 segments of each kind, the
//! scene's offset floor; FLOOR 0 gives Wächter and Binder's offset alone). Two kinds of
//! segments: a frame's VPL shadow rays (camera hits to VPLs shot by the CPU twin, every
//! 97th pair) and segments between area-uniform random surface points. The f64 test is
//! Möller-Trumbore on the f32 vertices and the f32 segment, with t in (0, 1).

use std::path::PathBuf;

use igi_core::bvh::{offset_ray_origin, shadow_segment, Bvh};
use igi_core::sampling::DigitPermutations;
use igi_core::scene::{load_scene, Scene};
use igi_core::vpl::{shoot_vpls, surface_at};
use igi_core::Vec3;
use rand::{Rng, SeedableRng};

type V64 = [f64; 3];

fn v64(v: Vec3) -> V64 {
    [v.x as f64, v.y as f64, v.z as f64]
}
fn sub(a: V64, b: V64) -> V64 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn cross(a: V64, b: V64) -> V64 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn dot(a: V64, b: V64) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Whether the open segment o + t d, 0 < t < 1, crosses the triangle (f64).
fn crosses(o: V64, d: V64, t: &[Vec3; 3]) -> bool {
    let (a, b, c) = (v64(t[0]), v64(t[1]), v64(t[2]));
    let (e1, e2) = (sub(b, a), sub(c, a));
    let p = cross(d, e2);
    let det = dot(e1, p);
    if det == 0.0 {
        return false;
    }
    let s = sub(o, a);
    let u = dot(s, p) / det;
    let q = cross(s, e1);
    let v = dot(d, q) / det;
    let t = dot(e2, q) / det;
    u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 0.0 && t < 1.0
}

#[derive(Default)]
struct Tally {
    segments: u32,
    occluded: u32,
    false_occlusions: u32,
    missed: u32,
}

impl Tally {
    fn add(&mut self, bvh: &Bvh, tris: &[[Vec3; 3]], (o, d): (Vec3, Vec3)) {
        let f32_answer = bvh.trace_segment(o, d);
        let exact = tris.iter().any(|t| crosses(v64(o), v64(d), t));
        self.segments += 1;
        self.occluded += u32::from(exact);
        self.false_occlusions += u32::from(f32_answer && !exact);
        self.missed += u32::from(!f32_answer && exact);
    }

    fn print(&self, what: &str) {
        println!(
            "{what}: {} segments, {} occluded (f64); the BVH: {} falsely occluded ({:.2}%), {} missed ({:.2}%)",
            self.segments,
            self.occluded,
            self.false_occlusions,
            100.0 * self.false_occlusions as f64 / self.segments.max(1) as f64,
            self.missed,
            100.0 * self.missed as f64 / self.segments.max(1) as f64,
        );
    }
}

/// Camera hits to VPLs, every 97th traced pair, as the indirect pass makes them.
fn frame_segments(scene: &Scene, bvh: &Bvh, floor: f32, count: u32) -> Vec<(Vec3, Vec3)> {
    let vpls = shoot_vpls(scene, bvh, &DigitPermutations::new(0), 60, 3, 0, 0);
    let cam = scene.camera;
    let (w, h) = (scene.film.width, scene.film.height);
    let mut out = vec![];
    let mut pair = 0u64;
    for y in (0..h).step_by(3) {
        for x in (0..w).step_by(3) {
            let dir = cam.pixel_dir(w, h, x, y);
            let Some(hit) = bvh.trace_closest(cam.eye, dir, f32::INFINITY) else {
                continue;
            };
            let s = surface_at(scene, bvh, dir, hit.tri, hit.u, hit.v);
            let origin = offset_ray_origin(s.position, s.geometric_normal, floor);
            for v in &vpls {
                let d = v.position - s.position;
                if s.shading_normal.dot(d) <= 0.0
                    || v.normal.dot(d) >= 0.0
                    || s.geometric_normal.dot(d) <= 0.0
                {
                    continue;
                }
                pair += 1;
                if pair.is_multiple_of(97) {
                    let end = offset_ray_origin(v.position, v.normal, floor);
                    out.push((origin, end - origin));
                    if out.len() as u32 == count {
                        return out;
                    }
                }
            }
        }
    }
    out
}

/// Segments between area-uniform random surface points.
fn random_segments(scene: &Scene, floor: f32, count: u32) -> Vec<(Vec3, Vec3)> {
    let mut cdf = vec![];
    let mut total = 0.0f64;
    for t in &scene.triangles {
        total += t.area() as f64;
        cdf.push(total);
    }
    let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
    let mut point = || {
        let x = rng.random_range(0.0..total);
        let t = &scene.triangles[cdf.partition_point(|&c| c < x).min(cdf.len() - 1)];
        let (mut u, mut v): (f32, f32) = (rng.random_range(0.0..1.0), rng.random_range(0.0..1.0));
        if u + v > 1.0 {
            (u, v) = (1.0 - u, 1.0 - v);
        }
        (
            t.v[0] + u * (t.v[1] - t.v[0]) + v * (t.v[2] - t.v[0]),
            t.cross().normalize(),
        )
    };
    (0..count)
        .map(|_| {
            let (a, na) = point();
            let (b, nb) = point();
            shadow_segment(a, na, b, nb, floor)
        })
        .collect()
}

fn main() {
    let mut args = std::env::args().skip(1);
    let path = PathBuf::from(
        args.next()
            .unwrap_or_else(|| "../shared/scenes/conference/scene.toml".to_string()),
    );
    let count: u32 = args.next().and_then(|s| s.parse().ok()).unwrap_or(3000);
    let scene = match load_scene(&path) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("cannot load {}: {e}", path.display());
            std::process::exit(1);
        }
    };
    let floor: f32 = args
        .next()
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| scene.ray_offset_floor());
    println!(
        "{}: {} triangles, offset floor {floor} (the scene's: {})",
        path.display(),
        scene.triangles.len(),
        scene.ray_offset_floor()
    );
    let bvh = Bvh::build(&scene.triangles);
    let tris: Vec<[Vec3; 3]> = scene.triangles.iter().map(|t| t.v).collect();
    for (what, segments) in [
        (
            "frame (camera hits to VPLs)",
            frame_segments(&scene, &bvh, floor, count),
        ),
        (
            "random surface-to-surface",
            random_segments(&scene, floor, count),
        ),
    ] {
        let mut tally = Tally::default();
        for s in segments {
            tally.add(&bvh, &tris, s);
        }
        tally.print(what);
    }
}
