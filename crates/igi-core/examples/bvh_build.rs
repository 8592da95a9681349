//! Measures the BVH build (igi's replacement for the OptiX acceleration structure of
//! Marques and Santos) on a scene: median wall time of several builds, the tree's size
//! and SAH cost, and a CPU traversal sanity figure.
//!
//! `cargo run --release -p igi-core --example bvh_build -- [SCENE.toml|MESH.obj] [RUNS]
//! [--binned] [--build-only]` (default: the conference room of `shared/scenes`, 5 runs,
//! the commands' default builder `BvhBuilder::Split`; `--binned` measures
//! `BvhBuilder::Binned`; `--build-only` skips the traversal figures, for profilers). An
//! OBJ is read as bare triangles with `tobj`, every face kept (the scene loader may drop
//! degenerate ones).

use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

use igi_core::bvh::timing::time_builds;
use igi_core::bvh::BvhBuilder;
use igi_core::scene::{load_scene, Triangle};
use igi_core::Vec3;

/// println! that stops quietly when stdout is closed (`bvh_build | head -3`) instead of
/// panicking, as the `igi` command does.
macro_rules! out {
    ($($arg:tt)*) => {
        if writeln!(std::io::stdout(), $($arg)*).is_err() {
            std::process::exit(0);
        }
    };
}

fn main() {
    let builder = if std::env::args().any(|a| a == "--binned") {
        BvhBuilder::Binned
    } else {
        BvhBuilder::Split
    };
    let build_only = std::env::args().any(|a| a == "--build-only");
    let mut args = std::env::args()
        .skip(1)
        .filter(|a| a != "--binned" && a != "--build-only");
    let path = PathBuf::from(
        args.next()
            .unwrap_or_else(|| "/work/shared/scenes/conference/scene.toml".to_string()),
    );
    let runs: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(5).max(1);

    let t = Instant::now();
    let scene = if path.extension().is_some_and(|e| e == "obj") {
        None
    } else {
        match load_scene(&path) {
            Ok(s) => Some(s),
            Err(e) => {
                eprintln!("cannot load {}: {e}", path.display());
                std::process::exit(1);
            }
        }
    };
    let triangles: Vec<Triangle> = match &scene {
        Some(s) => s.triangles.clone(),
        None => load_obj(&path),
    };
    out!(
        "{}: {} triangles (loaded in {:.0} ms)",
        path.display(),
        triangles.len(),
        t.elapsed().as_secs_f64() * 1e3
    );
    let timing = time_builds(&triangles, builder, runs, |_| {});
    out!("{timing}");
    let bvh = timing.bvh;

    // Primary rays of the scene's camera, on one core: a rough figure for the CPU twin.
    let Some(scene) = scene.filter(|_| !build_only) else {
        return;
    };
    let cam = scene.camera;
    let (w, h) = (scene.film.width.min(400), scene.film.height.min(300));
    let t = Instant::now();
    let mut hit_points = vec![];
    for y in 0..h {
        for x in 0..w {
            let d = cam.pixel_dir(w, h, x, y);
            if let Some(hit) = bvh.trace_closest(cam.eye, d, f32::INFINITY) {
                hit_points.push(cam.eye + d * hit.t);
            }
        }
    }
    let secs = t.elapsed().as_secs_f64();
    out!(
        "CPU closest hit, {w}x{h} camera rays on one thread: {:.2} Mrays/s, {:.1}% hit",
        (w * h) as f64 / secs / 1e6,
        100.0 * hit_points.len() as f64 / (w * h) as f64
    );
    // Shadow rays from those hits to the lights (pulled back a little from the surface).
    let t = Instant::now();
    let (mut rays, mut occluded) = (0usize, 0usize);
    for p in &hit_points {
        for l in &scene.lights {
            let o = *p + (cam.eye - *p).normalize() * 1e-3;
            occluded += usize::from(bvh.trace_segment(o, l.position - o));
            rays += 1;
        }
    }
    out!(
        "CPU any hit, {rays} shadow rays from those hits to the lights on one thread: {:.2} Mrays/s, {:.1}% occluded",
        rays as f64 / t.elapsed().as_secs_f64() / 1e6,
        100.0 * occluded as f64 / rays as f64
    );
}

/// Every face of an OBJ as a triangle (positions only).
fn load_obj(path: &std::path::Path) -> Vec<Triangle> {
    let options = tobj::LoadOptions {
        triangulate: true,
        ..Default::default()
    };
    let (models, _) = tobj::load_obj(path, &options).unwrap_or_else(|e| {
        eprintln!("cannot read {}: {e}", path.display());
        std::process::exit(1);
    });
    let mut out = vec![];
    for m in models {
        let p = &m.mesh.positions;
        let v = |i: u32| {
            Vec3::new(
                p[3 * i as usize],
                p[3 * i as usize + 1],
                p[3 * i as usize + 2],
            )
        };
        for f in m.mesh.indices.chunks_exact(3) {
            let v = [v(f[0]), v(f[1]), v(f[2])];
            let n = (v[1] - v[0]).cross(v[2] - v[0]).normalize_or_zero();
            out.push(Triangle {
                v,
                n: [n; 3],
                material: 0,
            });
        }
    }
    out
}
