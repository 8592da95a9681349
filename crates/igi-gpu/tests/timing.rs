//! The frame's stage times (GPU timestamps): where the stages follow each other inside one
//! compute pass they share a timestamp between two stages (`Profiler::set_chained`), so
//! the stage times must add up to the frame time, every stage of the frame must be named
//! once, and none may be negative. (Adapters without timestamps, or without timestamps
//! inside passes, skip with a printed reason.)

mod common;

use common::*;
use glam::Vec3;
use igi_core::settings::{Accelerations, RenderSettings};

#[test]
fn chained_stage_times_add_up_to_the_frame() {
    let Some(ctx) = gpu() else { return };
    if !igi_gpu::profiler::Profiler::new(&ctx, 1).writes_inside_passes() || !ctx.timestamps {
        eprintln!(
            "skipped: {} has no timestamps inside passes",
            ctx.describe()
        );
        return;
    }
    let scene = mirror_floor(Vec3::splat(0.3), Vec3::splat(0.5));
    for setup in ["canonical", "iv+ds+il"] {
        let settings = RenderSettings {
            width: 64,
            height: 48,
            vpls: 60,
            mirror_depth: 2,
            accelerations: Accelerations::from_setup(setup).unwrap(),
            ..RenderSettings::for_scene(&scene)
        };
        let frame = render(&ctx, &scene, &settings);
        let frame_ms = frame.frame_ms.expect("a frame time with timestamps");
        assert!(frame.stages.len() >= 3, "{setup}: {:?}", frame.stages);
        assert!(
            frame.stages.iter().all(|s| s.ms >= 0.0),
            "{setup}: {:?}",
            frame.stages
        );
        let sum: f64 = frame.stages.iter().map(|s| s.ms).sum();
        eprintln!(
            "{setup}: {} stages, {sum} ms of {frame_ms} ms",
            frame.stages.len()
        );
        assert!(
            (sum - frame_ms).abs() <= 1e-9 * frame_ms.max(1.0),
            "{setup}: stages add up to {sum} ms, the frame took {frame_ms} ms"
        );
    }
}
