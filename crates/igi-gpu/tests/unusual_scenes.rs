//! Valid but unusual scenes render without NaN: lights of zero power (light choice
//! divided by their power), a triangle too large for the f32 cross product (the
//! geometric normal), geometry far away (the scene's diagonal).

mod common;

use common::*;
use glam::Vec3;
use igi_core::scene::builtin;
use igi_core::scene::{Camera, PointLight};
use igi_core::settings::RenderSettings;

fn small(scene: &igi_core::scene::Scene) -> RenderSettings {
    RenderSettings {
        width: 12,
        height: 12,
        vpls: 60,
        ..RenderSettings::for_scene(scene)
    }
}

fn all_finite(image: &igi_core::image::Image) -> bool {
    image.data.iter().flatten().all(|x| x.is_finite())
}

#[test]
fn lights_of_zero_power_render_black_or_their_share() {
    let Some(ctx) = gpu() else { return };
    let mut scene = builtin::builtin_scene("cornell-box").unwrap();
    let light = scene.lights[0];
    let dark = PointLight {
        intensity: Vec3::ZERO,
        ..light
    };
    // The only light emits nothing: a black image (it was NaN everywhere).
    scene.lights = vec![dark];
    let frame = render(&ctx, &scene, &small(&scene));
    assert!(
        frame.image.data.iter().flatten().all(|&x| x == 0.0),
        "mean {:?}",
        frame.image.mean()
    );
    assert_eq!(frame.vpl_count, 0);
    // Beside lights that emit, a dark one changes nothing, wherever it stands in the list.
    scene.lights = vec![light];
    let alone = render(&ctx, &scene, &small(&scene)).image.mean();
    for lights in [
        vec![dark, light],
        vec![light, dark],
        vec![dark, light, dark],
    ] {
        scene.lights = lights;
        let frame = render(&ctx, &scene, &small(&scene));
        assert!(all_finite(&frame.image));
        let mean = frame.image.mean();
        for c in 0..3 {
            assert!(
                (mean[c] / alone[c] - 1.0).abs() < 1e-4,
                "{mean:?} against {alone:?}"
            );
        }
    }
}

#[test]
fn large_triangle_is_lit() {
    let Some(ctx) = gpu() else { return };
    let e = 1e10;
    let v = [
        Vec3::new(-e, -e, 0.0),
        Vec3::new(e, -e, 0.0),
        Vec3::new(0.0, e, 0.0),
    ];
    let n = igi_core::scene::geometric_normal(&v).unwrap();
    let camera = Camera {
        eye: Vec3::new(0.0, 0.0, 3.0),
        target: Vec3::ZERO,
        up: Vec3::Y,
        fov_y_deg: 40.0,
    };
    let scene = scene(
        camera,
        vec![igi_core::scene::Triangle {
            v,
            n: [n; 3],
            material: 0,
        }],
        vec![material("grey", Vec3::splat(0.5), Vec3::ZERO)],
        vec![PointLight {
            position: Vec3::new(0.0, 0.0, 2.0),
            intensity: Vec3::ONE,
        }],
    );
    let frame = render(
        &ctx,
        &scene,
        &RenderSettings {
            min_dist: Some(0.1),
            ..small(&scene)
        },
    );
    assert!(all_finite(&frame.image));
    // The centre pixel looks straight at the plane 2 below the light: E = I / 4,
    // radiance rho / pi * E.
    let centre = frame.image.pixel(6, 6)[0];
    let expected = 0.5 / std::f32::consts::PI * 0.25;
    assert!(
        (centre / expected - 1.0).abs() < 0.02,
        "centre {centre}, expected {expected}"
    );
}

#[test]
fn far_geometry_keeps_min_dist_finite() {
    let Some(ctx) = gpu() else { return };
    let mut scene = builtin::builtin_scene("cornell-box").unwrap();
    let far = [
        Vec3::new(1e20, 0.0, 0.0),
        Vec3::new(1e20, 1.0, 0.0),
        Vec3::new(1e20, 0.0, 1.0),
    ];
    let n = igi_core::scene::geometric_normal(&far).unwrap();
    scene.triangles.push(igi_core::scene::Triangle {
        v: far,
        n: [n; 3],
        material: 0,
    });
    // The depth buffer is distance / diagonal: 0 everywhere with an infinite diagonal.
    let settings = RenderSettings {
        output: igi_core::settings::OutputBuffer::Depth,
        ..small(&scene)
    };
    let frame = render(&ctx, &scene, &settings);
    assert!(all_finite(&frame.image));
    let mean = frame.image.mean()[0];
    assert!(mean > 0.0, "depth mean {mean}");
}
