//! A long run of frames holds its memory. On lavapipe, shaders whose branches or loops
//! depended on uniform values alone were compiled again every time their pipeline was
//! bound, and every copy was kept, more than a megabyte a frame
//! (`igi_gpu::shader::ParamsBinding`). A test binary of its own, so that no other
//! test allocates while this one reads the process's resident memory.

mod common;

use common::{gpu, mirror_floor};
use glam::Vec3;
use igi_core::bvh::Bvh;
use igi_core::settings::{Accelerations, RenderSettings};
use igi_gpu::Renderer;

/// The process's resident memory in bytes (Linux), or `None`.
fn resident_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmRSS:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

#[test]
fn frames_do_not_grow_the_process() {
    let Some(ctx) = gpu() else { return };
    if resident_bytes().is_none() {
        eprintln!("skipped: no /proc/self/status to read the resident memory from");
        return;
    }
    // Mirrors, so that the mirror passes run too.
    let scene = mirror_floor(Vec3::splat(0.3), Vec3::splat(0.5));
    let bvh = Bvh::build(&scene.triangles);
    let mut renderer = Renderer::new(&ctx, &scene, &bvh).expect("renderer");
    const FRAMES: u32 = 150;
    for setup in ["canonical", "iv+ds+il"] {
        let settings = |accumulate| RenderSettings {
            width: 32,
            height: 24,
            vpls: 8,
            mirror_depth: 2,
            accumulate,
            accelerations: Accelerations::from_setup(setup).expect("set-up"),
            ..RenderSettings::default()
        };
        // The first frames make the buffers and fill the driver's caches.
        renderer.render(&ctx, &settings(10)).expect("frames");
        let before = resident_bytes().expect("resident memory");
        renderer.render(&ctx, &settings(FRAMES)).expect("frames");
        let after = resident_bytes().expect("resident memory");
        let growth = after.saturating_sub(before);
        eprintln!(
            "{setup}: {FRAMES} frames on {} grew the process by {:.1} MB",
            ctx.info.name,
            growth as f64 / 1e6
        );
        // 1.35 MB a frame would be 200 MB; a frame allocates nothing that it keeps.
        assert!(
            growth < 30_000_000,
            "{setup}: {FRAMES} frames grew the process by {:.1} MB",
            growth as f64 / 1e6
        );
    }
}
