//! A scene renders the same at any size: random rooms at scales from 1e-6 to 1e16 of their
//! unit size (geometry, camera and lights scaled, intensities by the square so that the
//! irradiance stays the same) against the unit-size image (igi_core::trace_scale).

mod common;

use common::{flat_triangle, material};
use glam::Vec3;
use igi_core::image::{rel_mse, Image};
use igi_core::scene::{Camera, PointLight, Scene, Triangle};
use igi_core::settings::{Accelerations, RenderSettings};
use rand::{Rng, SeedableRng};

/// A closed room [-1, 1]^3 (its largest coordinate 1, the bottom of the range traced
/// unscaled) holding a few random boxes, lit by one random point light and seen from
/// inside near its front wall.
fn random_room(seed: u64) -> Scene {
    let mut rng = rand_pcg::Pcg32::seed_from_u64(seed);
    let mut tris: Vec<Triangle> = Vec::new();
    let quad = |c: [Vec3; 4], m: u32, tris: &mut Vec<Triangle>| {
        tris.push(flat_triangle([c[0], c[1], c[2]], m));
        tris.push(flat_triangle([c[0], c[2], c[3]], m));
    };
    // A box from `lo` to `hi` with faces wound to face out (or in, for the room).
    let cuboid = |lo: Vec3, hi: Vec3, m: u32, inward: bool, tris: &mut Vec<Triangle>| {
        let p = |x: usize, y: usize, z: usize| {
            Vec3::new([lo.x, hi.x][x], [lo.y, hi.y][y], [lo.z, hi.z][z])
        };
        let faces = [
            [p(0, 0, 0), p(0, 0, 1), p(0, 1, 1), p(0, 1, 0)],
            [p(1, 0, 0), p(1, 1, 0), p(1, 1, 1), p(1, 0, 1)],
            [p(0, 0, 0), p(1, 0, 0), p(1, 0, 1), p(0, 0, 1)],
            [p(0, 1, 0), p(0, 1, 1), p(1, 1, 1), p(1, 1, 0)],
            [p(0, 0, 0), p(0, 1, 0), p(1, 1, 0), p(1, 0, 0)],
            [p(0, 0, 1), p(1, 0, 1), p(1, 1, 1), p(0, 1, 1)],
        ];
        for mut f in faces {
            if inward {
                f.reverse();
            }
            quad(f, m, tris);
        }
    };
    cuboid(Vec3::splat(-1.0), Vec3::splat(1.0), 0, true, &mut tris);
    for _ in 0..rng.random_range(2..5) {
        let c = Vec3::new(
            rng.random_range(-0.6..0.6),
            rng.random_range(-1.0..-0.4),
            rng.random_range(-0.7..0.3),
        );
        let h = Vec3::new(
            rng.random_range(0.05..0.3),
            rng.random_range(0.05..0.5),
            rng.random_range(0.05..0.3),
        );
        let lo = (c - h).max(Vec3::splat(-1.0));
        cuboid(lo, c + h, 1 + rng.random_range(0..2u32), false, &mut tris);
    }
    let light = PointLight {
        position: Vec3::new(
            rng.random_range(-0.7..0.7),
            rng.random_range(0.3..0.9),
            rng.random_range(-0.7..0.5),
        ),
        intensity: Vec3::new(1.0, 0.9, 0.8) * rng.random_range(0.5..2.0),
    };
    let camera = Camera {
        eye: Vec3::new(rng.random_range(-0.3..0.3), 0.0, 0.95),
        target: Vec3::new(0.0, -0.3, 0.0),
        up: Vec3::Y,
        fov_y_deg: 70.0,
    };
    common::scene(
        camera,
        tris,
        vec![
            material("walls", Vec3::splat(0.7), Vec3::ZERO),
            material("red", Vec3::new(0.7, 0.2, 0.2), Vec3::ZERO),
            material("green", Vec3::new(0.2, 0.6, 0.3), Vec3::ZERO),
        ],
        vec![light],
    )
}

/// `scene` at `k` times its size, with the intensities that keep its irradiance.
fn scaled(scene: &Scene, k: f64) -> Scene {
    let p = |v: Vec3| (v.as_dvec3() * k).as_vec3();
    let mut s = scene.clone();
    for t in &mut s.triangles {
        t.v = t.v.map(p);
    }
    s.camera.eye = p(s.camera.eye);
    s.camera.target = p(s.camera.target);
    for l in &mut s.lights {
        l.position = p(l.position);
        l.intensity = (l.intensity.as_dvec3() * k * k).as_vec3();
    }
    s
}

fn settings(accelerations: Accelerations) -> RenderSettings {
    RenderSettings {
        width: 48,
        height: 36,
        vpls: 24,
        accelerations,
        ..RenderSettings::default()
    }
}

/// The share of pixels where `a` and `b` differ by more than 1% of `b` (plus 1e-3).
fn share_off(a: &Image, b: &Image) -> f64 {
    let off = a
        .data
        .iter()
        .zip(&b.data)
        .filter(|(p, q)| (0..3).any(|c| (p[c] - q[c]).abs() > 0.01 * q[c].abs() + 1e-3))
        .count();
    off as f64 / a.data.len() as f64
}

/// The bounds tested: 10^j scales round every coordinate once (k is not a power of two),
/// which moves edges by an ulp: a pixel whose ray grazes an edge may see the other side,
/// and a light path that grazes one may end elsewhere, so a few pixels may differ.
const MAX_REL_MSE: f64 = 1e-5;
const MAX_SHARE_OFF: f64 = 0.005;

#[test]
fn random_rooms_render_alike_at_every_scale() {
    let Some(ctx) = common::gpu() else { return };
    let setups = [
        ("canonical", Accelerations::default()),
        ("iv+ds+il", Accelerations::from_setup("iv+ds+il").unwrap()),
    ];
    let mut worst: (f64, f64) = (0.0, 0.0);
    for seed in 0..3 {
        let room = random_room(seed);
        for (name, a) in &setups {
            let s = settings(a.clone());
            let unit = common::render(&ctx, &room, &s).image;
            assert!(unit.mean()[0] > 1e-3, "seed {seed}: the unit room is dark");
            // Scaled by a power of two beyond the range traced unscaled, the scene is
            // traced at the range's nearer octave: the same bits as the scene made that
            // size (2^-4 and 2^19 of the unit room, whose largest coordinate is 1).
            for (far, near) in [(-30, -4), (40, 19)] {
                let at = |k: i32| common::render(&ctx, &scaled(&room, 2f64.powi(k)), &s).image;
                assert_eq!(at(far).data, at(near).data, "seed {seed} {name}: 2^{far}");
            }
            for k in [1e-6, 1e-3, 0.07, 0.1, 10.0, 1e3, 1e6, 1e9, 1e12, 1e13, 1e16] {
                let image = common::render(&ctx, &scaled(&room, k), &s).image;
                let e = rel_mse(&image, &unit).unwrap();
                let off = share_off(&image, &unit);
                eprintln!(
                    "seed {seed} {name} scale {k:e}: relMSE {e:.2e}, {:.2}% of pixels off",
                    100.0 * off
                );
                worst = (worst.0.max(e), worst.1.max(off));
                assert!(
                    e <= MAX_REL_MSE && off <= MAX_SHARE_OFF,
                    "seed {seed} {name} at scale {k:e}: relMSE {e:.3e} (at most {MAX_REL_MSE:e}), {:.2}% of pixels off by more than 1% (at most {}%)",
                    100.0 * off,
                    100.0 * MAX_SHARE_OFF
                );
            }
        }
    }
    eprintln!(
        "worst: relMSE {:.2e}, {:.2}% of pixels off",
        worst.0,
        100.0 * worst.1
    );
}
