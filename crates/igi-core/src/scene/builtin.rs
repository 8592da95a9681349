//! Built-in scenes, defined in code so that the renderer and the tests need no files:
//! the Cornell box (`cornell-box`) from the measured data Cornell publishes.
//!
//! Geometry and camera: the Cornell Program of Computer Graphics' "Cornell Box Data" page
//! (<http://www.graphics.cornell.edu/online/box/data.html>), vertex coordinates in mm,
//! converted to metres. Its frame is kept as published: y up, the open side at z = 0, the
//! camera at (278, 273, -800) looking along +z. With the usual right-handed look-at camera
//! (image right = forward x up = -x here) the red wall, published at x = 550..556, appears
//! on the LEFT of the image and the green wall (x = 0) on the right, as in the photographs,
//! so no mirroring is needed.
//!
//! Albedos: the MTL of Morgan McGuire's Computer Graphics Archive version
//! (`CornellBox-Original.mtl`, public domain, also in `shared/scenes/cornell-box`), RGB
//! fits of the measured spectra: white (0.725, 0.71, 0.68), red (0.63, 0.065, 0.05),
//! green (0.14, 0.45, 0.091). No mirrors.
//!
//! The published area light (a 130 x 105 mm quad in the ceiling) is replaced by the paper's
//! only light type, a point light 14 mm below its centre; the quad itself is not modelled
//! (it would be coplanar with the ceiling).

use super::{Camera, Film, Material, PointLight, Scene, Triangle};
use glam::Vec3;

/// Names accepted by [`builtin_scene`].
pub const BUILTIN_NAMES: &[&str] = &["cornell-box"];

/// The built-in scene `name` (one of [`BUILTIN_NAMES`]), or `None`.
pub fn builtin_scene(name: &str) -> Option<Scene> {
    match name {
        "cornell-box" => Some(cornell_box()),
        _ => None,
    }
}

const WHITE: u32 = 0;
const RED: u32 = 1;
const GREEN: u32 = 2;

/// The published quads in mm, in the published vertex order, with their material.
const QUADS_MM: [([[f32; 3]; 4], u32); 15] = [
    // Floor.
    (
        [
            [552.8, 0.0, 0.0],
            [0.0, 0.0, 0.0],
            [0.0, 0.0, 559.2],
            [549.6, 0.0, 559.2],
        ],
        WHITE,
    ),
    // Ceiling.
    (
        [
            [556.0, 548.8, 0.0],
            [556.0, 548.8, 559.2],
            [0.0, 548.8, 559.2],
            [0.0, 548.8, 0.0],
        ],
        WHITE,
    ),
    // Back wall.
    (
        [
            [549.6, 0.0, 559.2],
            [0.0, 0.0, 559.2],
            [0.0, 548.8, 559.2],
            [556.0, 548.8, 559.2],
        ],
        WHITE,
    ),
    // Right wall (green; "right" as seen from the camera).
    (
        [
            [0.0, 0.0, 559.2],
            [0.0, 0.0, 0.0],
            [0.0, 548.8, 0.0],
            [0.0, 548.8, 559.2],
        ],
        GREEN,
    ),
    // Left wall (red).
    (
        [
            [552.8, 0.0, 0.0],
            [549.6, 0.0, 559.2],
            [556.0, 548.8, 559.2],
            [556.0, 548.8, 0.0],
        ],
        RED,
    ),
    // Short block: top, then four sides.
    (
        [
            [130.0, 165.0, 65.0],
            [82.0, 165.0, 225.0],
            [240.0, 165.0, 272.0],
            [290.0, 165.0, 114.0],
        ],
        WHITE,
    ),
    (
        [
            [290.0, 0.0, 114.0],
            [290.0, 165.0, 114.0],
            [240.0, 165.0, 272.0],
            [240.0, 0.0, 272.0],
        ],
        WHITE,
    ),
    (
        [
            [130.0, 0.0, 65.0],
            [130.0, 165.0, 65.0],
            [290.0, 165.0, 114.0],
            [290.0, 0.0, 114.0],
        ],
        WHITE,
    ),
    (
        [
            [82.0, 0.0, 225.0],
            [82.0, 165.0, 225.0],
            [130.0, 165.0, 65.0],
            [130.0, 0.0, 65.0],
        ],
        WHITE,
    ),
    (
        [
            [240.0, 0.0, 272.0],
            [240.0, 165.0, 272.0],
            [82.0, 165.0, 225.0],
            [82.0, 0.0, 225.0],
        ],
        WHITE,
    ),
    // Tall block: top, then four sides.
    (
        [
            [423.0, 330.0, 247.0],
            [265.0, 330.0, 296.0],
            [314.0, 330.0, 456.0],
            [472.0, 330.0, 406.0],
        ],
        WHITE,
    ),
    (
        [
            [423.0, 0.0, 247.0],
            [423.0, 330.0, 247.0],
            [472.0, 330.0, 406.0],
            [472.0, 0.0, 406.0],
        ],
        WHITE,
    ),
    (
        [
            [472.0, 0.0, 406.0],
            [472.0, 330.0, 406.0],
            [314.0, 330.0, 456.0],
            [314.0, 0.0, 456.0],
        ],
        WHITE,
    ),
    (
        [
            [314.0, 0.0, 456.0],
            [314.0, 330.0, 456.0],
            [265.0, 330.0, 296.0],
            [265.0, 0.0, 296.0],
        ],
        WHITE,
    ),
    (
        [
            [265.0, 0.0, 296.0],
            [265.0, 330.0, 296.0],
            [423.0, 330.0, 247.0],
            [423.0, 0.0, 247.0],
        ],
        WHITE,
    ),
];

/// Millimetres (the published unit) to metres.
const MM: f32 = 0.001;

fn cornell_box() -> Scene {
    let mut triangles = Vec::with_capacity(2 * QUADS_MM.len());
    for (quad, material) in QUADS_MM {
        let q = quad.map(|p| Vec3::from(p) * MM);
        // The published quads are planar and convex: fan them like an OBJ polygon.
        for v in [[q[0], q[1], q[2]], [q[0], q[2], q[3]]] {
            let n = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
            triangles.push(Triangle {
                v,
                n: [n; 3],
                material,
            });
        }
    }
    let material =
        |name: &str, diffuse: [f32; 3]| Material::new(name, Vec3::from(diffuse), Vec3::ZERO);
    // Published camera: focal length 35 mm, 25 x 25 mm film, so the vertical field of view
    // is 2 atan(12.5 / 35) = 39.3 degrees.
    let fov_y_deg = 2.0 * (12.5f32 / 35.0).atan().to_degrees();
    // Same irradiance scale as shared/scenes/cornell-box (a box about 2 units wide lit by
    // 4 W/sr): irradiance goes as I / d^2, so a box 0.556 m wide needs 4 (0.556 / 2)^2.
    let intensity = 4.0 * (0.556f32 / 2.0).powi(2);
    Scene {
        camera: Camera {
            eye: Vec3::new(278.0, 273.0, -800.0) * MM,
            target: Vec3::new(278.0, 273.0, 0.0) * MM,
            up: Vec3::Y,
            fov_y_deg,
        },
        film: Film {
            width: 512,
            height: 512,
        },
        triangles,
        textures: Vec::new(),
        attributes: Vec::new(),
        materials: vec![
            // Index order matches WHITE, RED, GREEN.
            material("white", [0.725, 0.71, 0.68]),
            material("red", [0.63, 0.065, 0.05]),
            material("green", [0.14, 0.45, 0.091]),
        ],
        lights: vec![PointLight {
            // Centre of the published light quad (213..343, 227..332), 14 mm below the
            // ceiling (548.8 mm).
            position: Vec3::new(278.0, 548.8 - 14.0, 279.5) * MM,
            intensity: Vec3::splat(intensity),
        }],
        source: "builtin:cornell-box".to_string(),
        files: Vec::new(),
    }
}
