//! Limits and failures of the GPU: a buffer larger than one storage binding is a clear
//! error naming the limit; a lost device ends a frame with an error, not a hang or a panic.

mod common;

use common::*;
use igi_core::scene::builtin;
use igi_core::settings::RenderSettings;
use igi_gpu::scene_buffers::storage_buffer;

#[test]
fn buffer_beyond_the_binding_limit_names_the_limit() {
    let Some(ctx) = gpu() else { return };
    let limit = ctx.max_storage_binding();
    if limit > 1 << 30 {
        eprintln!("skipped: a {limit}-byte test buffer is too large to make here");
        return;
    }
    let too_big = vec![0u8; limit as usize + 16];
    let e = storage_buffer(&ctx, "BVH nodes", &too_big)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("max_storage_buffer_binding_size") && e.contains("BVH nodes"),
        "{e}"
    );
    assert_eq!(e.lines().count(), 1);
}

#[test]
fn lost_device_is_an_error_not_a_hang() {
    let Some(ctx) = gpu() else { return };
    let scene = builtin::builtin_scene("cornell-box").unwrap();
    let bvh = igi_core::bvh::Bvh::build(&scene.triangles);
    let mut renderer = igi_gpu::Renderer::new(&ctx, &scene, &bvh).unwrap();
    let settings = RenderSettings {
        width: 16,
        height: 16,
        vpls: 10,
        ..RenderSettings::default()
    };
    renderer.render(&ctx, &settings).unwrap();
    ctx.device.destroy();
    let e = renderer
        .render(&ctx, &settings)
        .expect_err("a frame on a destroyed device fails")
        .to_string();
    eprintln!("after destroy: {e}");
    assert_eq!(e.lines().count(), 1, "{e}");
    assert!(e.contains("lost"), "{e}");
}
