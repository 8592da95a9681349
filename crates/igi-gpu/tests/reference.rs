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
/// darker corners) and the noise of 180 VPLs. Measured 0.0250 on lavapipe (2026-11-22)
/// with 191 VPLs (an independent implementation: 0.026-0.030, DESIGN.md); bound =
/// measured + 40%, room for another adapter's rounding to move VPLs.
const FULL_BOUND: f64 = 0.035;

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
