//! On the software adapter, a walk that llvmpipe's loop limit cuts short is an error, not
//! a wrong image: a floor seen through the box of a triangle repeated N times (every walk
//! tests all N; 65,535 loop iterations are all an invocation gets there).

mod common;

use common::{flat_triangle, material};
use glam::Vec3;
use igi_core::bvh::Bvh;
use igi_core::scene::{Camera, PointLight};
use igi_core::settings::RenderSettings;
use igi_gpu::Renderer;

fn scene_with_copies(copies: usize) -> igi_core::scene::Scene {
    let mut tris = common::floor_square(1.0, 0);
    // Half of the plane y = 0.5 over the floor, the same triangle `copies` times: camera
    // rays cross its box everywhere, and hit it over half the floor.
    let t = flat_triangle(
        [
            Vec3::new(-1.0, 0.5, -1.0),
            Vec3::new(-1.0, 0.5, 1.0),
            Vec3::new(1.0, 0.5, -1.0),
        ],
        0,
    );
    tris.extend(std::iter::repeat_n(t, copies));
    common::scene(
        Camera {
            eye: Vec3::new(0.0, 1.5, 0.01),
            target: Vec3::ZERO,
            up: Vec3::Y,
            fov_y_deg: 60.0,
        },
        tris,
        vec![material("white", Vec3::splat(0.5), Vec3::ZERO)],
        vec![PointLight {
            position: Vec3::new(0.3, 1.2, 0.2),
            intensity: Vec3::splat(1.0),
        }],
    )
}

#[test]
fn walks_cut_short_by_the_software_adapter_are_an_error() {
    let Some(ctx) = common::gpu() else { return };
    if !ctx.is_software() {
        eprintln!("skipped: {} has no loop limit", ctx.describe());
        return;
    }
    let settings = RenderSettings {
        width: 8,
        height: 8,
        vpls: 4,
        ..RenderSettings::default()
    };
    let render = |copies: usize| {
        let scene = scene_with_copies(copies);
        let bvh = Bvh::build(&scene.triangles);
        let mut renderer = Renderer::new(&ctx, &scene, &bvh).expect("renderer");
        renderer.render(&ctx, &settings)
    };
    // A few thousand copies: every walk ends.
    let small = render(2_000).expect("2,000 copies render");
    assert!(small.image.mean()[0] > 0.0);
    // 70,000: every walk would be cut.
    let e = match render(70_000) {
        Ok(_) => panic!("70,000 copies must be refused"),
        Err(e) => e.to_string(),
    };
    assert!(
        e.contains("software adapter ended") && e.contains("65,535"),
        "{e}"
    );
}
