//! What the viewer (`igi view`) relies on, without a window: the normals and depth
//! buffers, moving lights and the camera between frames, and the display pass drawing the
//! frame exactly as a PNG file of it would look (plus the VPL dots where the VPLs are);
//! and what `igi bench` relies on: a renderer's passes handed to the next scene's.

mod common;

use common::*;
use glam::Vec3;
use igi_core::bvh::Bvh;
use igi_core::image::Image;
use igi_core::scene::builtin::builtin_scene;
use igi_core::scene::{Camera, PointLight, Scene};
use igi_core::settings::{OutputBuffer, RenderSettings};
use igi_gpu::passes::display::{DisplayOptions, DisplayPass};
use igi_gpu::{GpuContext, Renderer};

fn plane_scene() -> (Scene, Camera) {
    let scene = lit_floor(
        10.0,
        material("plane", Vec3::splat(0.5), Vec3::ZERO),
        PointLight {
            position: Vec3::new(0.0, 1.0, 0.0),
            intensity: Vec3::ONE,
        },
    );
    (scene, floor_camera())
}

/// A plane seen from above: every normal is +y (shown as 0.5 + 0.5 n) and the depth
/// buffer is the primary ray's distance to the plane over the scene's diagonal.
#[test]
fn normals_and_depth_of_a_plane() {
    let Some(ctx) = gpu() else { return };
    let (scene, camera) = plane_scene();
    let settings = RenderSettings {
        width: 24,
        height: 20,
        output: OutputBuffer::Normals,
        ..RenderSettings::default()
    };
    let normals = render(&ctx, &scene, &settings).image;
    let depth = render(
        &ctx,
        &scene,
        &RenderSettings {
            output: OutputBuffer::Depth,
            ..settings.clone()
        },
    )
    .image;
    let diagonal = scene.diagonal();
    for y in 0..settings.height {
        for x in 0..settings.width {
            assert_eq!(normals.pixel(x, y), [0.5, 1.0, 0.5], "pixel ({x}, {y})");
            let d = camera.pixel_dir(settings.width, settings.height, x, y);
            let expected = -camera.eye.y / d.y / diagonal;
            let got = depth.pixel(x, y);
            assert!(
                (got[0] - expected).abs() < 1e-5 && got[0] == got[1] && got[1] == got[2],
                "pixel ({x}, {y}): depth {got:?}, expected {expected}"
            );
        }
    }
}

/// Moving the light or the camera of a renderer gives the very frame a renderer made for
/// the moved scene gives: the VPLs (and the path count) follow the light at once.
#[test]
fn moved_light_and_camera_match_a_fresh_renderer() {
    let Some(ctx) = gpu() else { return };
    let scene = builtin_scene("cornell-box").expect("built-in");
    let settings = RenderSettings {
        width: 40,
        height: 40,
        vpls: 24,
        ..RenderSettings::default()
    };
    let mut moved = scene.clone();
    moved.lights[0].position += Vec3::new(-0.2, -0.3, 0.1);
    moved.lights[0].intensity *= 0.5;
    moved.camera.eye += Vec3::new(0.1, 0.05, -0.3);
    moved.camera.fov_y_deg += 5.0;
    let bvh = Bvh::build(&scene.triangles);
    let mut renderer = Renderer::new(&ctx, &scene, &bvh).expect("renderer");
    let before = renderer.render(&ctx, &settings).expect("frame");
    renderer
        .set_lights(&ctx, &moved.lights)
        .expect("same light count");
    renderer.set_camera(moved.camera);
    let after = renderer.render(&ctx, &settings).expect("frame");
    let fresh = render(&ctx, &moved, &settings);
    assert_ne!(before.image.data, after.image.data);
    assert_eq!(after.path_count, fresh.path_count);
    assert_eq!(after.vpl_count, fresh.vpl_count);
    assert_eq!(after.image.data, fresh.image.data);
    // A different number of lights is refused with a message.
    let e = renderer.set_lights(&ctx, &[]).unwrap_err().to_string();
    assert!(e.contains("0 lights given") && e.contains("has 1"), "{e}");
}

/// An accumulation reports each frame as it runs, 1 to N in order (at most
/// FRAMES_IN_FLIGHT submitted ahead), and gives the image `render` gives, bit for bit.
#[test]
fn accumulation_reports_its_frames_in_order() {
    let Some(ctx) = gpu() else { return };
    let scene = builtin_scene("cornell-box").expect("built-in");
    let bvh = Bvh::build(&scene.triangles);
    let mut renderer = Renderer::new(&ctx, &scene, &bvh).expect("renderer");
    for frames in [1, 3, igi_gpu::frame::FRAMES_IN_FLIGHT as u32 + 3] {
        let settings = RenderSettings {
            width: 24,
            height: 20,
            vpls: 12,
            accumulate: frames,
            ..RenderSettings::default()
        };
        let mut reported = vec![];
        let with_progress = renderer
            .render_with_progress(&ctx, &settings, |k| reported.push(k))
            .expect("frames");
        assert_eq!(reported, (1..=frames).collect::<Vec<_>>());
        let plain = renderer.render(&ctx, &settings).expect("frames");
        assert_eq!(
            with_progress.image.data, plain.image.data,
            "{frames} frames"
        );
    }
}

/// The passes of a renderer that drew one scene, handed to a renderer of another scene
/// (as `igi bench` does with several scenes), give that scene's frame bit for bit as a
/// renderer with passes of its own does: the passes keep nothing of the first scene.
#[test]
fn passes_handed_on_render_the_next_scene_as_new_ones() {
    let Some(ctx) = gpu() else { return };
    let first = mirror_floor(Vec3::splat(0.3), Vec3::splat(0.5));
    let first_settings = RenderSettings {
        width: 36,
        height: 28,
        vpls: 40,
        mirror_depth: 2,
        ..RenderSettings::default()
    };
    let bvh = Bvh::build(&first.triangles);
    let mut renderer = Renderer::new(&ctx, &first, &bvh).expect("renderer");
    let first_frame = renderer.render(&ctx, &first_settings).expect("frame");
    let mut passes = Some(renderer.into_passes());
    let next = builtin_scene("cornell-box").expect("built-in");
    for setup in ["canonical", "iv+ds+il"] {
        let settings = RenderSettings {
            width: 40,
            height: 32,
            vpls: 24,
            accelerations: igi_core::settings::Accelerations::from_setup(setup).unwrap(),
            ..RenderSettings::default()
        };
        let fresh = render(&ctx, &next, &settings);
        assert_ne!(fresh.image.data.len(), first_frame.image.data.len());
        let bvh = Bvh::build(&next.triangles);
        let handed = passes.take().expect("handed back");
        let mut renderer = Renderer::with_passes(&ctx, handed, &next, &bvh).expect("renderer");
        let handed_on = renderer.render(&ctx, &settings).expect("frame");
        assert_eq!(handed_on.vpl_count, fresh.vpl_count, "{setup}");
        assert_eq!(handed_on.image.data, fresh.image.data, "{setup}");
        passes = Some(renderer.into_passes());
    }
}

/// Draw the renderer's last frame with the display pass into a `width` x `height` texture
/// of `format` and read it back as RGBA8 rows.
fn draw(
    ctx: &GpuContext,
    renderer: &Renderer,
    format: wgpu::TextureFormat,
    (width, height): (u32, u32),
    options: &DisplayOptions,
) -> Vec<[u8; 4]> {
    let texture = ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("display target"),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let view = texture.create_view(&Default::default());
    let pass = DisplayPass::new(&ctx.device, format);
    let row = (width * 4).div_ceil(256) * 256;
    let buffer = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("display readback"),
        size: (row * height) as u64,
        usage: wgpu::BufferUsages::COPY_DST
            | wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    let inputs = renderer.display_inputs().expect("a frame was rendered");
    pass.draw(
        &ctx.device,
        &ctx.queue,
        &mut encoder,
        &view,
        &inputs,
        options,
    );
    encoder.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row),
                rows_per_image: None,
            },
        },
        wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
    );
    ctx.queue.submit([encoder.finish()]);
    let words: Vec<u32> = ctx.read_buffer(&buffer).expect("readback");
    let bytes: &[u8] = bytemuck::cast_slice(&words);
    (0..height)
        .flat_map(|y| {
            (0..width).map(move |x| {
                let i = (y * row + x * 4) as usize;
                [bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]]
            })
        })
        .collect()
}

fn cornell_frame(ctx: &GpuContext) -> (Renderer, Image, Scene, RenderSettings) {
    let scene = builtin_scene("cornell-box").expect("built-in");
    let settings = RenderSettings {
        width: 40,
        height: 30,
        vpls: 64,
        ..RenderSettings::default()
    };
    let bvh = Bvh::build(&scene.triangles);
    let mut renderer = Renderer::new(ctx, &scene, &bvh).expect("renderer");
    let image = renderer.render(ctx, &settings).expect("frame").image;
    (renderer, image, scene, settings)
}

/// The display pass shows the frame as the PNG writer encodes it (exposure, clamp, sRGB),
/// whether the target format encodes sRGB or the shader does, scaled by nearest pixel
/// into the viewport, with the background around it.
#[test]
fn display_shows_the_frame_as_a_png_would() {
    let Some(ctx) = gpu() else { return };
    let (renderer, image, _, settings) = cornell_frame(&ctx);
    let background = wgpu::Color {
        r: 0.0,
        g: 0.0,
        b: 1.0,
        a: 1.0,
    };
    for (format, exposure) in [
        (wgpu::TextureFormat::Rgba8Unorm, 1.0),
        (wgpu::TextureFormat::Rgba8UnormSrgb, 1.0),
        (wgpu::TextureFormat::Rgba8Unorm, 3.0),
    ] {
        let expected = image.to_srgb8(exposure);
        // Twice the image's size, 5 pixels from the left: a blue column at x < 5.
        let (w, h) = (2 * settings.width + 5, 2 * settings.height);
        let options = DisplayOptions {
            viewport: [
                5.0,
                0.0,
                2.0 * settings.width as f32,
                2.0 * settings.height as f32,
            ],
            exposure,
            vpl_dots: None,
            background,
        };
        let got = draw(&ctx, &renderer, format, (w, h), &options);
        let mut worst = 0;
        for y in 0..h {
            for x in 0..w {
                let p = got[(y * w + x) as usize];
                if x < 5 {
                    assert_eq!(p, [0, 0, 255, 255], "background at ({x}, {y})");
                    continue;
                }
                let (ix, iy) = ((x - 5) / 2, y / 2);
                let i = 3 * (iy * settings.width + ix) as usize;
                for c in 0..3 {
                    worst = worst.max((p[c] as i32 - expected[i + c] as i32).abs());
                }
            }
        }
        // 8-bit rounding of the two encoders may differ by one step.
        assert!(worst <= 1, "{format:?} exposure {exposure}: off by {worst}");
    }
}

/// With dots on, the pixels that change are those around the VPLs in front of the camera.
#[test]
fn vpl_dots_are_drawn_where_the_vpls_are() {
    let Some(ctx) = gpu() else { return };
    let (renderer, _, scene, settings) = cornell_frame(&ctx);
    let (w, h) = (settings.width, settings.height);
    let format = wgpu::TextureFormat::Rgba8Unorm;
    let mut options = DisplayOptions {
        viewport: [0.0, 0.0, w as f32, h as f32],
        exposure: 1.0,
        vpl_dots: None,
        background: wgpu::Color::BLACK,
    };
    let plain = draw(&ctx, &renderer, format, (w, h), &options);
    let radius = 1.0;
    options.vpl_dots = Some(radius);
    let dotted = draw(&ctx, &renderer, format, (w, h), &options);

    let camera = scene.camera;
    let (forward, right, up) = camera.basis();
    let tan = (camera.fov_y_deg.to_radians() * 0.5).tan();
    let aspect = w as f32 / h as f32;
    let dots: Vec<(f32, f32)> = renderer
        .read_vpls(&ctx)
        .expect("vpls")
        .iter()
        .filter_map(|v| {
            let d = Vec3::from(v.position) - camera.eye;
            let z = d.dot(forward);
            (z > 0.0).then(|| {
                let nx = d.dot(right) / (z * tan * aspect);
                let ny = d.dot(up) / (z * tan);
                ((nx + 1.0) * 0.5 * w as f32, (1.0 - ny) * 0.5 * h as f32)
            })
        })
        .collect();
    assert!(!dots.is_empty(), "the Cornell box's VPLs are in view");
    let mut changed = 0;
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            if plain[i] == dotted[i] {
                continue;
            }
            changed += 1;
            let (px, py) = (x as f32 + 0.5, y as f32 + 0.5);
            let near = dots.iter().any(|&(dx, dy)| {
                (px - dx).abs() <= radius + 0.5 && (py - dy).abs() <= radius + 0.5
            });
            assert!(near, "pixel ({x}, {y}) changed far from every VPL");
        }
    }
    assert!(changed > 0, "no dot drawn");
}
