//! The frame recorded as one compute pass (stage timestamps written between its
//! dispatches, where the adapter can), as one compute pass per stage
//! (`IGI_STAGE_PASSES=1`) and with every pass in a stage of its own
//! (`IGI_SIDE_BY_SIDE=0`: no gathers or filters side by side) must give the same image,
//! bit for bit: the barriers wgpu puts between the dispatches of one pass must be all the
//! frame needs, VPL shooting beside the direct pass, the chain walks and the two gathers
//! side by side, the two filters side by side and the gathers over the direct pass's lists
//! included, and the state a stage leaves bound (bind groups 2 and 3) must not leak into
//! the next. lavapipe runs dispatches one after another, so there a missing barrier
//! cannot show; on a GPU it would. (Its own test binary: it sets IGI_STAGE_PASSES and
//! IGI_SIDE_BY_SIDE for the whole process.)

mod common;

use common::*;
use glam::Vec3;
use igi_core::settings::{Accelerations, OutputBuffer, RenderSettings};

#[test]
fn one_pass_equals_a_pass_per_stage_and_a_stage_per_pass() {
    let Some(ctx) = gpu() else { return };
    let one_pass = igi_gpu::profiler::Profiler::new(&ctx, 1).writes_inside_passes();
    eprintln!(
        "{}: the default frame is {}",
        ctx.describe(),
        if one_pass {
            "one compute pass"
        } else {
            "a pass per stage too (no timestamps inside passes): both sides are the same path"
        }
    );
    let scene = mirror_floor(Vec3::splat(0.3), Vec3::splat(0.5));
    for setup in ["canonical", "iv+ds+il", "iv+ds+il+fused"] {
        let settings = RenderSettings {
            width: 64,
            height: 48,
            vpls: 60,
            mirror_depth: 2,
            output: OutputBuffer::Final,
            accelerations: Accelerations::from_setup(setup).unwrap(),
            ..RenderSettings::for_scene(&scene)
        };
        std::env::remove_var("IGI_STAGE_PASSES");
        std::env::remove_var("IGI_SIDE_BY_SIDE");
        let together = render(&ctx, &scene, &settings);
        assert!(
            together.image.data.iter().any(|p| p[0] > 0.0),
            "{setup}: a black image proves nothing"
        );
        for (var, value) in [("IGI_STAGE_PASSES", "1"), ("IGI_SIDE_BY_SIDE", "0")] {
            std::env::set_var(var, value);
            let apart = render(&ctx, &scene, &settings);
            std::env::remove_var(var);
            let differ = together
                .image
                .data
                .iter()
                .zip(&apart.image.data)
                .filter(|(a, b)| a.map(f32::to_bits) != b.map(f32::to_bits))
                .count();
            assert_eq!(differ, 0, "{setup}, {var}={value}: {differ} pixels differ");
        }
    }
}
