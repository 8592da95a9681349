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

use igi_core::bvh::{Bvh, BvhBuilder};
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
    out!("builder: {}", builder.name());
    out!(
        "threads: {}",
        std::thread::available_parallelism().map_or(1, |n| n.get())
    );

    let mut times = vec![];
    let mut phases: Vec<(&str, Vec<f64>)> = vec![];
    let mut bvh = None;
    let cpu_start = process_cpu_seconds();
    let mut first_faults = None;
    for _ in 0..runs {
        let faults = minor_faults();
        let t = Instant::now();
        let b = Bvh::build_with(&triangles, builder);
        times.push(t.elapsed().as_secs_f64() * 1e3);
        if first_faults.is_none() {
            first_faults = minor_faults().zip(faults).map(|(b, a)| b - a);
        }
        for (k, &(name, ms)) in b.build_stats.phases.iter().enumerate() {
            if k == phases.len() {
                phases.push((name, vec![]));
            }
            phases[k].1.push(ms);
        }
        bvh = Some(b);
    }
    let cpu = process_cpu_seconds()
        .zip(cpu_start)
        .map(|(b, a)| (b - a) / runs as f64);
    let bvh = bvh.expect("at least one run");
    times.sort_by(f64::total_cmp);
    let s = &bvh.build_stats;
    if let Some(cpu) = cpu {
        // Less sensitive than wall time to other processes on a small machine.
        out!("CPU time per build, all threads: {:.0} ms", cpu * 1e3);
    }
    out!(
        "build: median {:.1} ms of {runs} (min {:.1}, max {:.1})",
        times[runs / 2],
        times[0],
        times[runs - 1]
    );
    let medians: Vec<String> = phases
        .iter_mut()
        .map(|(name, ms)| {
            ms.sort_by(f64::total_cmp);
            format!("{name} {:.1}", ms[ms.len() / 2])
        })
        .collect();
    out!("phases, median ms: {}", medians.join(", "));
    if let Some(faults) = first_faults {
        // What the first build in a new process pays for fresh memory (about 1.7 us a
        // page on the 2-core machine; docs/PERFORMANCE.md attempt 113).
        out!("minor page faults of the first build: {faults}");
    }
    // Single builds are faster with huge pages: figures compare only where both had them.
    out!(
        "transparent huge pages offered for {:.1} MiB of the last build's buffers",
        s.huge_page_bytes as f64 / (1 << 20) as f64
    );
    // Equal hashes: the same tree, for checking that a change to the builder keeps it.
    let mut hash = 0xcbf2_9ce4_8422_2325u64;
    for byte in bytemuck::cast_slice::<_, u8>(&bvh.nodes)
        .iter()
        .chain(bytemuck::cast_slice::<_, u8>(&bvh.tri_rows))
        .chain(bytemuck::cast_slice::<_, u8>(&bvh.tri_order))
    {
        hash = (hash ^ *byte as u64).wrapping_mul(0x100_0000_01b3);
    }
    out!("tree hash (FNV-1a of nodes, rows and slot order): {hash:016x}");
    out!(
        "references {}, nodes {} ({} KiB), leaves {}, max depth {}, max leaf {}, oversized leaves {}, SAH cost {:.2}",
        s.references,
        s.nodes,
        s.nodes * std::mem::size_of::<igi_core::bvh::BvhNode>() / 1024,
        s.leaves,
        s.max_depth,
        s.max_leaf_size,
        s.oversized_leaves,
        s.sah_cost
    );

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

/// User + system time of this process so far (all threads, finished ones included), from
/// /proc/self/stat (Linux; clock ticks of 10 ms: meaningful over several builds).
/// Fields of /proc/self/stat after the command name (which ends with ')'), numbered
/// from 0 (the state); None where there is no such file (not Linux).
fn proc_stat_fields() -> Option<Vec<u64>> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    let rest = &stat[stat.rfind(')')? + 2..];
    // The state is a letter; the fields wanted here are numbers.
    Some(
        rest.split_whitespace()
            .map(|f| f.parse().unwrap_or(0))
            .collect(),
    )
}

/// Minor page faults of the process so far (minflt, field 7).
fn minor_faults() -> Option<u64> {
    proc_stat_fields()?.get(7).copied()
}

/// CPU time of the process so far, all threads (utime and stime, fields 11 and 12, in
/// ticks of 1/100 s).
fn process_cpu_seconds() -> Option<f64> {
    let fields = proc_stat_fields()?;
    Some((fields.get(11)? + fields.get(12)?) as f64 / 100.0)
}
