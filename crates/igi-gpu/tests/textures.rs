//! Textures, vertex colours and alpha masks in the frame, against exact answers: a
//! textured plane under a point light gives at each pixel the texel's albedo times the
//! irradiance over pi, for each filter and wrap mode; an alpha-masked quad casts the
//! mask's shadow and is seen through where cut out; VPLs carry the albedo of the texel
//! they land on; distant texels are filtered, not aliased.

mod common;

use common::*;
use glam::{Vec2, Vec3, Vec4};
use igi_core::bvh::Bvh;
use igi_core::scene::{Alpha, AlphaMode, Material, PointLight, Scene, TriAttributes, Triangle};
use igi_core::settings::{OutputBuffer, RenderSettings};
use igi_core::texture::{self, Filter, Sampler, Texture, TextureRef, UvTransform, Wrap};
use igi_gpu::Renderer;
use std::f32::consts::PI;

/// A small image of distinct, irregular colours (a fixed hash: no two neighbours alike).
fn noise_texture(w: u32, h: u32, alpha: bool) -> Texture {
    let texels = (0..w * h)
        .map(|k| {
            let x = k.wrapping_mul(2654435761).rotate_left(7) ^ 0x9e37_79b9;
            let a = if alpha {
                [255, 0][(k as usize * 7 / 3) % 2]
            } else {
                255
            };
            [
                (x & 255) as u8,
                (x >> 8 & 255) as u8,
                (x >> 16 & 255) as u8,
                a,
            ]
        })
        .collect();
    Texture::new("noise".into(), w, h, true, texels).unwrap()
}

/// Texture coordinates of a point of the plane y = 0: `tiles` periods over [-half, half].
fn plane_uv(p: Vec3, half: f32, tiles: f32) -> Vec2 {
    Vec2::new((p.x + half) / (2.0 * half), (p.z + half) / (2.0 * half)) * tiles
}

/// Attributes for triangles whose texture coordinates are `uv` of their vertices.
fn attributes_of(tris: &[Triangle], uv: impl Fn(Vec3) -> Vec2) -> Vec<TriAttributes> {
    tris.iter()
        .map(|t| TriAttributes {
            uv: t.v.map(&uv),
            color: [Vec4::ONE; 3],
        })
        .collect()
}

fn textured(name: &str, rho: Vec3, sampler: Sampler) -> Material {
    Material {
        texture: Some(TextureRef {
            texture: 0,
            sampler,
            transform: UvTransform::IDENTITY,
        }),
        ..material(name, rho, Vec3::ZERO)
    }
}

/// Level 0 alone, `filter` inside and between texels, `wrap` on both axes.
fn level0(filter: Filter, wrap: Wrap) -> Sampler {
    Sampler {
        wrap_s: wrap,
        wrap_t: wrap,
        mag: filter,
        min: filter,
        mip: None,
    }
}

/// Distance from `x` (in texel units) to the nearest texel edge (nearest filtering flips
/// there) or centre (bilinear weights are continuous, but so is nothing else to test).
fn to_texel_edge(x: f32) -> f32 {
    (x - x.round()).abs()
}

/// The floor of half side `half` (two triangles), textured with `tiles` periods.
fn textured_floor(half: f32, tiles: f32, mat: Material, tex: Texture, light: PointLight) -> Scene {
    let mut scene = lit_floor(half, mat, light);
    scene.attributes = attributes_of(&scene.triangles, |p| plane_uv(p, half, tiles));
    scene.textures = vec![tex];
    scene
}

#[test]
fn textured_plane_is_texel_albedo_times_irradiance_over_pi() {
    let Some(ctx) = gpu() else { return };
    let (half, tiles) = (6.0, 5.0);
    let light = PointLight {
        position: Vec3::new(0.5, 1.5, 0.3),
        intensity: Vec3::new(2.0, 3.0, 4.0),
    };
    let tex = noise_texture(4, 3, false);
    let factor = Vec3::new(0.9, 0.8, 1.0);
    let camera = floor_camera();
    let settings = RenderSettings {
        width: 64,
        height: 48,
        output: OutputBuffer::Direct,
        ..RenderSettings::default()
    };
    for filter in [Filter::Nearest, Filter::Linear] {
        for wrap in [Wrap::Repeat, Wrap::ClampToEdge, Wrap::MirroredRepeat] {
            let sampler = level0(filter, wrap);
            let scene = textured_floor(
                half,
                tiles,
                textured("floor", factor, sampler),
                tex.clone(),
                light,
            );
            let frame = render(&ctx, &scene, &settings);
            let (mut worst, mut checked) = (0.0f32, 0);
            let mut seen = std::collections::HashSet::new();
            for y in 0..settings.height {
                for x in 0..settings.width {
                    let d = camera.pixel_dir(settings.width, settings.height, x, y);
                    let p = camera.eye + (-camera.eye.y / d.y) * d;
                    let uv = plane_uv(p, half, tiles);
                    let texel = uv * Vec2::new(4.0, 3.0);
                    if filter == Filter::Nearest
                        && (to_texel_edge(texel.x) < 1e-3 || to_texel_edge(texel.y) < 1e-3)
                    {
                        continue;
                    }
                    let albedo = factor
                        * texture::sample_level(&tex.levels[0], true, uv, filter, (wrap, wrap))
                            .truncate();
                    seen.insert((albedo * 1000.0).round().as_ivec3().to_array());
                    let to_light = light.position - p;
                    let cos = to_light.y / to_light.length();
                    let expected = albedo / PI * light.intensity * cos / to_light.length_squared();
                    let got = Vec3::from(frame.image.pixel(x, y));
                    let err =
                        ((got - expected).abs() / expected.max(Vec3::splat(1e-3))).max_element();
                    worst = worst.max(err);
                    checked += 1;
                }
            }
            assert!(
                checked > 2500,
                "{filter:?} {wrap:?}: {checked} pixels checked"
            );
            // The image shows the texture, not one colour.
            assert!(
                seen.len() > 10,
                "{filter:?} {wrap:?}: {} albedos",
                seen.len()
            );
            // sRGB decoding on the GPU (pow) and the hit's barycentrics against the CPU's
            // closed form: a few parts in 10^4 where bilinear weights move fastest.
            assert!(
                worst < 2e-3,
                "{filter:?} {wrap:?}: worst relative error {worst}"
            );
        }
    }
}

/// Texel (0, 0) is the first row's first texel, at texture coordinates (0, 0) - (1/w,
/// 1/h): glTF's orientation (TextureCoordinateTest), which the loaders convert OBJ's to.
#[test]
fn texture_coordinate_origin_is_the_first_texel() {
    let Some(ctx) = gpu() else { return };
    let texels = vec![
        [255, 0, 0, 255],
        [0, 255, 0, 255],
        [0, 0, 255, 255],
        [255, 255, 255, 255],
    ];
    let tex = Texture::new("2x2".into(), 2, 2, false, texels).unwrap();
    let half = 1.0;
    // Camera straight above, x to the right and -z up in the image: texture u along x, v
    // along z, so the image shows the texture as it is stored.
    let mut scene = textured_floor(
        half,
        1.0,
        textured(
            "floor",
            Vec3::ONE,
            level0(Filter::Nearest, Wrap::ClampToEdge),
        ),
        tex,
        PointLight {
            position: Vec3::new(0.0, 100.0, 0.0),
            intensity: Vec3::splat(1e4),
        },
    );
    scene.camera = igi_core::scene::Camera {
        eye: Vec3::new(0.0, 3.0, 0.0),
        target: Vec3::ZERO,
        up: Vec3::NEG_Z,
        fov_y_deg: 30.0,
    };
    let settings = RenderSettings {
        width: 32,
        height: 32,
        output: OutputBuffer::Direct,
        ..RenderSettings::default()
    };
    let frame = render(&ctx, &scene, &settings);
    let dominant = |x, y| {
        let p = Vec3::from(frame.image.pixel(x, y));
        [
            p.x > 0.5 * p.max_element(),
            p.y > 0.5 * p.max_element(),
            p.z > 0.5 * p.max_element(),
        ]
    };
    assert_eq!(
        dominant(13, 13),
        [true, false, false],
        "top left is texel (0, 0)"
    );
    assert_eq!(
        dominant(18, 13),
        [false, true, false],
        "top right is texel (1, 0)"
    );
    assert_eq!(
        dominant(13, 18),
        [false, false, true],
        "bottom left is texel (0, 1)"
    );
    assert_eq!(
        dominant(18, 18),
        [true, true, true],
        "bottom right is texel (1, 1)"
    );
}

#[test]
fn vertex_colours_interpolate_over_the_triangle() {
    let Some(ctx) = gpu() else { return };
    let light = PointLight {
        position: Vec3::new(0.3, 2.0, -0.2),
        intensity: Vec3::splat(3.0),
    };
    let v = [
        Vec3::new(-4.0, 0.0, -4.0),
        Vec3::new(4.0, 0.0, -4.0),
        Vec3::new(0.0, 0.0, 4.0),
    ];
    let tri = flat_triangle([v[0], v[2], v[1]], 0);
    let colors = [
        Vec4::new(1.0, 0.0, 0.0, 1.0),
        Vec4::new(0.0, 0.0, 1.0, 1.0),
        Vec4::new(0.0, 1.0, 0.0, 1.0),
    ];
    let mut scene = scene(
        floor_camera(),
        vec![tri],
        vec![Material {
            vertex_colors: true,
            ..material("coloured", Vec3::splat(0.8), Vec3::ZERO)
        }],
        vec![light],
    );
    scene.attributes = vec![TriAttributes {
        uv: [Vec2::ZERO; 3],
        color: colors,
    }];
    let settings = RenderSettings {
        width: 48,
        height: 48,
        output: OutputBuffer::Direct,
        ..RenderSettings::default()
    };
    let frame = render(&ctx, &scene, &settings);
    let camera = scene.camera;
    let (mut worst, mut checked) = (0.0f32, 0);
    for y in 0..settings.height {
        for x in 0..settings.width {
            let d = camera.pixel_dir(settings.width, settings.height, x, y);
            let p = camera.eye + (-camera.eye.y / d.y) * d;
            // Barycentrics of p in (v0, v2, v1), the triangle's corner order.
            let (a, b, c) = (tri.v[0], tri.v[1], tri.v[2]);
            let area = |p: Vec3, q: Vec3, r: Vec3| (q - p).cross(r - p).y;
            let total = area(a, b, c);
            let (wa, wb, wc) = (
                area(p, b, c) / total,
                area(a, p, c) / total,
                area(a, b, p) / total,
            );
            if wa.min(wb).min(wc) < 0.01 {
                continue;
            }
            let colour = (wa * colors[0] + wb * colors[1] + wc * colors[2]).truncate();
            let to_light = light.position - p;
            let cos = to_light.y / to_light.length();
            let expected = 0.8 * colour / PI * light.intensity * cos / to_light.length_squared();
            let got = Vec3::from(frame.image.pixel(x, y));
            worst = worst.max((got - expected).abs().max_element() / expected.max_element());
            checked += 1;
        }
    }
    assert!(checked > 300, "{checked} pixels on the triangle");
    // Colours travel as 16-bit unorm: 1 / 65535 of the brightest channel at most.
    assert!(worst < 1e-3, "worst error {worst} of the brightest channel");
}

/// A quad at height 1 with a mask (alternate texels cut out) between a point light and
/// a white floor, seen from above: where the camera ray crosses an opaque texel it sees
/// the quad, else the floor, lit unless the segment to the light crosses an opaque texel.
#[test]
fn alpha_masked_quad_casts_the_masks_shadow() {
    let Some(ctx) = gpu() else { return };
    let mask = noise_texture(6, 5, true);
    let quad_half = 1.0f32;
    let light = PointLight {
        position: Vec3::new(0.4, 3.0, 0.2),
        intensity: Vec3::splat(8.0),
    };
    let mut tris = floor_square(4.0, 0);
    let mut quad = floor_square(quad_half, 1);
    for t in &mut quad {
        for v in &mut t.v {
            v.y = 1.0;
        }
    }
    tris.extend(quad);
    let uv = |p: Vec3| plane_uv(p, quad_half, 1.0);
    let masked = Material {
        alpha: Alpha {
            mode: AlphaMode::Mask { cutoff: 0.5 },
            factor: 1.0,
        },
        ..textured(
            "leaf",
            Vec3::splat(0.5),
            level0(Filter::Nearest, Wrap::ClampToEdge),
        )
    };
    let mut scene = scene(
        igi_core::scene::Camera {
            eye: Vec3::new(-0.3, 2.6, 2.2),
            target: Vec3::new(0.0, 0.0, 0.0),
            up: Vec3::Y,
            fov_y_deg: 55.0,
        },
        tris,
        vec![material("floor", Vec3::splat(0.7), Vec3::ZERO), masked],
        vec![light],
    );
    scene.attributes = attributes_of(&scene.triangles, uv);
    scene.textures = vec![mask.clone()];
    // Where a point of the quad's plane is: None off the quad or near a texel edge (the
    // answer flips there), else whether it is opaque.
    let opaque_at = |p: Vec3| -> Option<bool> {
        if p.x.abs() > quad_half || p.z.abs() > quad_half {
            return Some(false);
        }
        let t = uv(p) * Vec2::new(6.0, 5.0);
        if to_texel_edge(t.x) < 0.02 || to_texel_edge(t.y) < 0.02 {
            return None;
        }
        let texel = texture::sample_level(
            &mask.levels[0],
            true,
            uv(p),
            Filter::Nearest,
            (Wrap::ClampToEdge, Wrap::ClampToEdge),
        );
        Some(texel.w >= 0.5)
    };
    let settings = RenderSettings {
        width: 64,
        height: 64,
        output: OutputBuffer::Direct,
        ..RenderSettings::default()
    };
    let frame = render(&ctx, &scene, &settings);
    let camera = scene.camera;
    let (mut checked, mut shadowed, mut through, mut wrong) = (0, 0, 0, Vec::new());
    for y in 0..settings.height {
        for x in 0..settings.width {
            let d = camera.pixel_dir(settings.width, settings.height, x, y);
            let at_quad = camera.eye + ((1.0 - camera.eye.y) / d.y) * d;
            let Some(hits_quad) = opaque_at(at_quad) else {
                continue;
            };
            let p = if hits_quad {
                at_quad
            } else {
                camera.eye + (-camera.eye.y / d.y) * d
            };
            if p.x.abs() > 3.9 || p.z.abs() > 3.9 {
                continue;
            }
            let albedo = if hits_quad {
                0.5 * texture::sample_level(
                    &mask.levels[0],
                    true,
                    uv(p),
                    Filter::Nearest,
                    (Wrap::ClampToEdge, Wrap::ClampToEdge),
                )
                .truncate()
            } else {
                Vec3::splat(0.7)
            };
            // The floor's segment to the light crosses the quad's plane at s.
            let lit = if hits_quad {
                true
            } else {
                let s = (1.0 - p.y) / (light.position.y - p.y);
                match opaque_at(p + s * (light.position - p)) {
                    Some(blocked) => !blocked,
                    None => continue,
                }
            };
            let to_light = light.position - p;
            let cos = to_light.y / to_light.length();
            let e = if lit {
                light.intensity * cos / to_light.length_squared()
            } else {
                Vec3::ZERO
            };
            let expected = albedo / PI * e;
            let got = Vec3::from(frame.image.pixel(x, y));
            let err = (got - expected).abs().max_element();
            if err > 1e-3 * (light.intensity.x / to_light.length_squared()) {
                wrong.push((x, y, got, expected));
            }
            checked += 1;
            shadowed += usize::from(!lit);
            through += usize::from(!hits_quad && p.x.abs() < quad_half && p.z.abs() < quad_half);
        }
    }
    assert!(
        checked > 2000 && shadowed > 100 && through > 100,
        "{checked} pixels, {shadowed} in the mask's shadow, {through} seen through the mask"
    );
    assert!(
        wrong.is_empty(),
        "{} of {checked} pixels wrong, e.g. {:?}",
        wrong.len(),
        &wrong[..wrong.len().min(4)]
    );
}

/// VPLs that land on a textured floor carry the albedo of the texel under them (level 0,
/// the sampler's filter), as the CPU twin computes it and as the texture says.
#[test]
fn vpls_carry_the_albedo_of_their_texel() {
    let Some(ctx) = gpu() else { return };
    let (half, tiles) = (3.0, 2.0);
    let tex = noise_texture(5, 4, false);
    let sampler = level0(Filter::Nearest, Wrap::Repeat);
    let scene = textured_floor(
        half,
        tiles,
        textured("floor", Vec3::new(0.9, 1.0, 0.8), sampler),
        tex.clone(),
        PointLight {
            position: Vec3::new(0.2, 1.0, -0.1),
            intensity: Vec3::splat(2.0),
        },
    );
    let bvh = Bvh::build(&scene.triangles);
    let mut renderer = Renderer::new(&ctx, &scene, &bvh).unwrap();
    let settings = RenderSettings {
        width: 8,
        height: 8,
        vpls: 300,
        bounces: 1,
        ..RenderSettings::default()
    };
    let frame = renderer.render(&ctx, &settings).unwrap();
    let gpu = renderer.read_vpls(&ctx).unwrap();
    let cpu = igi_core::vpl::shoot_vpls(
        &scene,
        &bvh,
        &igi_core::sampling::DigitPermutations::new(settings.seed),
        frame.path_count,
        settings.bounces,
        settings.mirror_depth,
        igi_core::sampling::halton_base(settings.seed, settings.frame, frame.path_count),
    );
    assert!(gpu.len() > 200, "{} VPLs", gpu.len());
    let mut albedos = std::collections::HashSet::new();
    let mut checked = 0;
    for (g, c) in gpu.iter().zip(&cpu) {
        let p = Vec3::from(g.position);
        let albedo = Vec3::from(g.albedo);
        assert!(
            (c.albedo - albedo).abs().max_element() < 1e-4,
            "twin {} gpu {albedo}",
            c.albedo
        );
        let t = plane_uv(p, half, tiles) * Vec2::new(5.0, 4.0);
        if to_texel_edge(t.x) < 1e-3 || to_texel_edge(t.y) < 1e-3 {
            continue;
        }
        let texel = texture::sample_level(
            &tex.levels[0],
            true,
            plane_uv(p, half, tiles),
            Filter::Nearest,
            (Wrap::Repeat, Wrap::Repeat),
        );
        let expected = Vec3::new(0.9, 1.0, 0.8) * texel.truncate();
        assert!(
            (expected - albedo).abs().max_element() < 1e-4,
            "at {p}: {albedo}, texel says {expected}"
        );
        albedos.insert((albedo * 1000.0).round().as_ivec3().to_array());
        checked += 1;
    }
    assert!(
        checked > 200 && albedos.len() >= 15,
        "{checked} VPLs, {} albedos",
        albedos.len()
    );
}

/// A 1-texel checker seen to the horizon: with the mip chain chosen by the pixels' ray
/// cones the far floor is the checker's mean (linear 0.5), not black or white by where a
/// pixel's centre falls; magnified near texels (nearest magnification) stay black and
/// white.
#[test]
fn distant_texels_are_filtered_not_aliased() {
    let Some(ctx) = gpu() else { return };
    let n = 256u32;
    let texels = (0..n * n)
        .map(|k| {
            if (k % n + k / n).is_multiple_of(2) {
                [255; 4]
            } else {
                [0, 0, 0, 255]
            }
        })
        .collect();
    let tex = Texture::new("checker".into(), n, n, true, texels).unwrap();
    let half = 50.0;
    let light = PointLight {
        position: Vec3::new(0.0, 1e4, 0.0),
        intensity: Vec3::splat(1e8),
    };
    let mut scene = textured_floor(
        half,
        1.0,
        textured(
            "floor",
            Vec3::ONE,
            Sampler {
                mag: Filter::Nearest,
                ..Sampler::DEFAULT
            },
        ),
        tex,
        light,
    );
    scene.camera = igi_core::scene::Camera {
        eye: Vec3::new(0.0, 1.0, 45.0),
        target: Vec3::new(0.0, 0.0, 0.0),
        up: Vec3::Y,
        fov_y_deg: 40.0,
    };
    let settings = RenderSettings {
        width: 96,
        height: 64,
        output: OutputBuffer::Direct,
        ..RenderSettings::default()
    };
    let bvh = Bvh::build(&scene.triangles);
    let mut renderer = Renderer::new(&ctx, &scene, &bvh).unwrap();
    renderer.render(&ctx, &settings).unwrap();
    let albedo = renderer.read_frame_buffer(&ctx, "gbuffer albedo").unwrap();
    let camera = scene.camera;
    let (mut far, mut near_extremes, mut near) = (Vec::new(), 0, 0);
    for y in 0..settings.height {
        for x in 0..settings.width {
            let d = camera.pixel_dir(settings.width, settings.height, x, y);
            if d.y >= 0.0 {
                continue;
            }
            let t = -camera.eye.y / d.y;
            let a = albedo[(y * settings.width + x) as usize][0];
            // A texel is 100 / 256 = 0.39 wide; a pixel subtends 2 tan(20 deg) / 64 =
            // 0.011, and at height 1 it meets the floor at cos 1 / t: past t = 15 its cone
            // covers 0.011 t^2 = 2.6 units, 6 or more texels, along the view.
            if t > 15.0 && (camera.eye + t * d).z > -half {
                far.push(a);
            } else if t < 3.0 {
                near += 1;
                near_extremes += usize::from(!(0.02..=0.98).contains(&a));
            }
        }
    }
    assert!(
        far.len() > 200 && near > 100,
        "{} far, {near} near pixels",
        far.len()
    );
    let off = far.iter().filter(|&&a| !(0.3..=0.7).contains(&a)).count();
    assert!(
        off * 100 <= far.len(),
        "{off} of {} far pixels alias (outside 0.3..0.7)",
        far.len()
    );
    assert!(
        near_extremes * 10 >= near * 8,
        "{near_extremes} of {near} near pixels are black or white"
    );
}
