//! Against the ground truth: canonical IGI on the shared Cornell box versus the Mitsuba 3
//! path-traced references (`../shared/references/`, linear radiance), and determinism.

mod common;

use common::*;
use igi_core::image::{rel_mse, Image};
use igi_core::scene::{builtin, load_scene};
use igi_core::settings::{OutputBuffer, RenderSettings};

#[test]
fn cornell_box_against_path_traced_references() {
    let Some(shared) = shared() else { return };
    let Some(ctx) = gpu() else { return };
    let scene = load_scene(&shared.join("scenes/cornell-box/scene.toml")).expect("scene");
    let direct_ref = Image::read_exr(&shared.join("references/cornell-box-direct.exr")).unwrap();
    let full_ref = Image::read_exr(&shared.join("references/cornell-box-full.exr")).unwrap();
    let settings = RenderSettings {
        width: full_ref.width,
        height: full_ref.height,
        vpls: 180,
        ..RenderSettings::for_scene(&scene)
    };
    let direct = render(
        &ctx,
        &scene,
        &RenderSettings {
            output: OutputBuffer::Direct,
            ..settings.clone()
        },
    );
    let full = render(&ctx, &scene, &settings);
    let e_direct = rel_mse(&direct.image, &direct_ref).unwrap();
    let e_full = rel_mse(&full.image, &full_ref).unwrap();
    eprintln!(
        "cornell-box: relMSE direct {e_direct:.5}, full {e_full:.5} ({} VPLs); means ours {:?} ref {:?}",
        full.vpl_count,
        full.image.mean(),
        full_ref.mean()
    );
    // Bounds: see the comments at the constants.
    assert!(e_direct < DIRECT_BOUND, "direct relMSE {e_direct}");
    assert!(e_full < FULL_BOUND, "full relMSE {e_full}");
}

/// Direct light is exact up to pixel sampling: the reference averages each pixel's square
/// (anti-aliased edges), igi shoots one ray through its centre, so only pixels on edges
/// differ. Measured 0.0027 on lavapipe (2026-11-22); bound = measured + 50%.
const DIRECT_BOUND: f64 = 0.004;
/// The full image adds the bias of the bounded G (no light from VPLs closer than 0.8 m,
/// darker corners) and the noise of 180 VPLs, which dominates: seeds 0 to 5 measured
/// 0.0349, 0.0344, 0.0292, 0.0211, 0.0314 (lavapipe and an H200 agree; 2026-11-22; an
/// independent implementation: 0.026-0.030, DESIGN.md). Bound = the worst seed + 30%.
const FULL_BOUND: f64 = 0.045;

#[test]
fn same_seed_same_image() {
    let Some(ctx) = gpu() else { return };
    let scene = builtin::builtin_scene("cornell-box").expect("built-in");
    let settings = RenderSettings {
        width: 96,
        height: 96,
        vpls: 90,
        seed: 7,
        ..RenderSettings::default()
    };
    let a = render(&ctx, &scene, &settings);
    let b = render(&ctx, &scene, &settings);
    assert!(a.vpl_count > 0);
    assert_eq!(a.vpl_count, b.vpl_count);
    let bits = |i: &Image| {
        i.data
            .iter()
            .flatten()
            .map(|v| v.to_bits())
            .collect::<Vec<_>>()
    };
    assert_eq!(bits(&a.image), bits(&b.image), "same seed, different image");
    // Another seed is another VPL set.
    let c = render(
        &ctx,
        &scene,
        &RenderSettings {
            seed: 8,
            ..settings
        },
    );
    assert_ne!(bits(&a.image), bits(&c.image));
}

/// The paper's conference room (277K non-degenerate triangles) loads, builds and
/// renders; at a small size on the software adapter to keep CI short.
#[test]
fn conference_room_renders() {
    let Some(shared) = shared() else { return };
    let Some(ctx) = gpu() else { return };
    let scene = load_scene(&shared.join("scenes/conference/scene.toml")).expect("scene");
    let settings = RenderSettings {
        width: 80,
        height: 60,
        vpls: 30,
        ..RenderSettings::for_scene(&scene)
    };
    let frame = render(&ctx, &scene, &settings);
    let reference = Image::read_exr(
        &shared
            .join("references/conference-full.png")
            .with_extension("exr"),
    )
    .unwrap();
    let (ours, theirs) = (frame.image.mean(), reference.mean());
    eprintln!(
        "conference 80x60, {} VPLs: mean {ours:?}, reference (800x600) {theirs:?}",
        frame.vpl_count
    );
    assert!(frame.vpl_count > 0);
    // A small image of the same view has about the same mean radiance.
    for c in 0..3 {
        assert!(
            (ours[c] - theirs[c]).abs() < 0.15 * theirs[c],
            "channel {c}: {} vs {}",
            ours[c],
            theirs[c]
        );
    }
}
