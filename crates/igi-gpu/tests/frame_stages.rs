//! The stages of each set-up, as the recorder groups the frame's passes: which run side
//! by side. A new read-write binding that made two passes share a buffer would split a
//! stage here instead of serialising the frame without a word. (The images of the
//! grouped and the separated frame are compared bit for bit in `stage_passes.rs`.)

mod common;

use common::*;
use glam::Vec3;
use igi_core::bvh::Bvh;
use igi_core::settings::{Accelerations, RenderSettings};
use igi_gpu::{Passes, Renderer};

fn stages(
    ctx: &igi_gpu::GpuContext,
    scene: &igi_core::scene::Scene,
    setup: &str,
    vpls: u32,
    mirror_depth: u32,
) -> Vec<&'static str> {
    let bvh = Bvh::build(&scene.triangles);
    let passes = Passes::with_switches(ctx, igi_gpu::switches::Switches::default());
    let mut renderer = Renderer::with_passes(ctx, passes, scene, &bvh).expect("renderer");
    let settings = RenderSettings {
        width: 48,
        height: 32,
        vpls,
        mirror_depth,
        accelerations: Accelerations::from_setup(setup).unwrap(),
        ..RenderSettings::for_scene(scene)
    };
    let stages = renderer.frame_stages(ctx, &settings).expect("stages");
    for (name, parts) in &stages {
        assert_eq!(*name, parts.join(" + "), "a stage is named by its passes");
    }
    stages.into_iter().map(|(name, _)| name).collect()
}

#[test]
fn each_set_up_runs_its_independent_passes_side_by_side() {
    let Some(ctx) = gpu() else { return };
    let mirrors = mirror_floor(Vec3::splat(0.3), Vec3::splat(0.5));
    let gathers = "mirror chains + mirror indirect + indirect";
    let cases: &[(&str, u32, u32, &[&str])] = &[
        (
            "canonical",
            60,
            2,
            &["vpl shooting + direct", gathers, "compose"],
        ),
        (
            "iv+ds+il",
            60,
            2,
            &[
                "vpl shooting + direct",
                gathers,
                "discontinuity + mirror discontinuity",
                "upsample + compose",
            ],
        ),
        (
            "iv+ds+il+fused",
            60,
            2,
            &[
                "vpl shooting + direct",
                gathers,
                "fused filter + mirror discontinuity",
                "compose",
            ],
        ),
        (
            "iv+ds",
            60,
            2,
            &["vpl shooting + direct", gathers, "upsample + compose"],
        ),
        // One reflection: no chains to walk.
        (
            "canonical",
            60,
            1,
            &[
                "vpl shooting + direct",
                "mirror indirect + indirect",
                "compose",
            ],
        ),
        // More paths than one workgroup compacts: the list is a stage of its own.
        (
            "canonical",
            3000,
            2,
            &["vpl shooting + direct", "vpl list", gathers, "compose"],
        ),
    ];
    for &(setup, vpls, depth, want) in cases {
        let got = stages(&ctx, &mirrors, setup, vpls, depth);
        assert_eq!(got, want, "{setup}, {vpls} VPLs, mirror depth {depth}");
    }
    let plain = igi_core::scene::builtin::builtin_scene("cornell-box").unwrap();
    assert_eq!(
        stages(&ctx, &plain, "canonical", 60, 6),
        ["vpl shooting + direct", "indirect", "compose"]
    );
    assert_eq!(
        stages(&ctx, &plain, "iv+ds+il", 60, 6),
        [
            "vpl shooting + direct",
            "indirect",
            "discontinuity",
            "upsample + compose"
        ]
    );
}

#[test]
fn the_switch_puts_every_pass_in_a_stage_of_its_own() {
    let Some(ctx) = gpu() else { return };
    let scene = mirror_floor(Vec3::splat(0.3), Vec3::splat(0.5));
    let bvh = Bvh::build(&scene.triangles);
    let switches = igi_gpu::switches::Switches {
        side_by_side: false,
        ..Default::default()
    };
    let mut renderer =
        Renderer::with_passes(&ctx, Passes::with_switches(&ctx, switches), &scene, &bvh)
            .expect("renderer");
    let settings = RenderSettings {
        width: 48,
        height: 32,
        vpls: 3000,
        mirror_depth: 2,
        accelerations: Accelerations::from_setup("iv+ds+il").unwrap(),
        ..RenderSettings::for_scene(&scene)
    };
    let stages = renderer.frame_stages(&ctx, &settings).expect("stages");
    let names: Vec<_> = stages.iter().map(|(name, _)| *name).collect();
    assert_eq!(
        names,
        [
            "vpl shooting",
            "direct",
            "vpl list",
            "mirror chains",
            "mirror indirect",
            "indirect",
            "discontinuity",
            "mirror discontinuity",
            "upsample + compose"
        ]
    );
    assert_eq!(names.len() as u32, igi_gpu::frame::MAX_STAGES);
}
