//! Shared helpers of the GPU tests: the device (or a printed reason to skip), tiny scenes
//! built in code, and the path of the shared scenes and references.
#![allow(dead_code)]

use glam::Vec3;
use igi_core::bvh::Bvh;
use igi_core::scene::{Camera, Film, Material, PointLight, Scene, Triangle};
use igi_core::settings::RenderSettings;
use igi_gpu::{AdapterChoice, FrameOutput, GpuContext, Renderer};
use std::path::PathBuf;

/// The GPU, or `None` with the reason printed (the test then passes as skipped).
pub fn gpu() -> Option<GpuContext> {
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        std::env::set_var("XDG_RUNTIME_DIR", "/tmp");
    }
    match GpuContext::new(&AdapterChoice::Best) {
        Ok(ctx) => Some(ctx),
        Err(e) => {
            eprintln!("skipped: no GPU adapter ({e})");
            None
        }
    }
}

/// `../shared` beside the repository, if present.
pub fn shared() -> Option<PathBuf> {
    let p = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared"));
    if p.join("scenes").is_dir() {
        Some(p)
    } else {
        eprintln!("skipped: {} is absent", p.display());
        None
    }
}

pub fn render(ctx: &GpuContext, scene: &Scene, settings: &RenderSettings) -> FrameOutput {
    let bvh = Bvh::build(&scene.triangles);
    let mut renderer = Renderer::new(ctx, scene, &bvh).expect("renderer");
    renderer.render(ctx, settings).expect("frame")
}

/// The built-in Cornell box with its floor made of `diffuse` + `mirror`.
pub fn mirror_floor(diffuse: Vec3, mirror: Vec3) -> Scene {
    let mut scene = igi_core::scene::builtin::builtin_scene("cornell-box").unwrap();
    scene
        .materials
        .push(material("floor mirror", diffuse, mirror));
    let floor_material = scene.materials.len() as u32 - 1;
    for t in &mut scene.triangles {
        if t.v.iter().all(|v| v.y.abs() < 1e-4) {
            t.material = floor_material;
        }
    }
    scene
}

pub fn material(name: &str, diffuse: Vec3, mirror: Vec3) -> Material {
    Material::new(name, diffuse, mirror)
}

/// The square [-half, half]^2 of the plane y = 0 as two triangles facing +y.
pub fn floor_square(half: f32, material: u32) -> Vec<Triangle> {
    let c = [
        Vec3::new(-half, 0.0, -half),
        Vec3::new(half, 0.0, -half),
        Vec3::new(half, 0.0, half),
        Vec3::new(-half, 0.0, half),
    ];
    vec![
        flat_triangle([c[0], c[2], c[1]], material),
        flat_triangle([c[0], c[3], c[2]], material),
    ]
}

pub fn flat_triangle(v: [Vec3; 3], material: u32) -> Triangle {
    let n = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
    Triangle {
        v,
        n: [n; 3],
        material,
    }
}

pub fn scene(
    camera: Camera,
    triangles: Vec<Triangle>,
    materials: Vec<Material>,
    lights: Vec<PointLight>,
) -> Scene {
    Scene {
        camera,
        film: Film {
            width: 64,
            height: 64,
        },
        triangles,
        materials,
        textures: Vec::new(),
        attributes: Vec::new(),
        lights,
        source: "test".into(),
        files: vec![],
    }
}

/// The camera of [`lit_floor`]: above the floor, looking down at its centre.
pub fn floor_camera() -> Camera {
    Camera {
        eye: Vec3::new(0.2, 2.0, 1.5),
        target: Vec3::ZERO,
        up: Vec3::Y,
        fov_y_deg: 60.0,
    }
}

/// The square floor of [`floor_square`] (half side `half`) of one material, open to the
/// sky, under one point light, seen by [`floor_camera`].
pub fn lit_floor(half: f32, material: Material, light: PointLight) -> Scene {
    scene(
        floor_camera(),
        floor_square(half, 0),
        vec![material],
        vec![light],
    )
}

/// A sphere of radius `r` about the origin from a subdivided icosahedron, with radial
/// shading normals.
pub fn icosphere(r: f32, subdivisions: u32, material: u32) -> Vec<Triangle> {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let mut verts: Vec<Vec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| Vec3::new(x, y, z).normalize())
    .collect();
    let mut faces: Vec<[usize; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdivisions {
        let mut cache = std::collections::HashMap::new();
        let mut mid = |a: usize, b: usize, verts: &mut Vec<Vec3>| {
            *cache.entry((a.min(b), a.max(b))).or_insert_with(|| {
                verts.push(((verts[a] + verts[b]) * 0.5).normalize());
                verts.len() - 1
            })
        };
        let mut next = Vec::with_capacity(faces.len() * 4);
        for [a, b, c] in faces {
            let ab = mid(a, b, &mut verts);
            let bc = mid(b, c, &mut verts);
            let ca = mid(c, a, &mut verts);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        faces = next;
    }
    faces
        .iter()
        .map(|f| Triangle {
            v: f.map(|i| verts[i] * r),
            n: f.map(|i| verts[i]),
            material,
        })
        .collect()
}

/// The value of a scalar `const` of a WGSL module (tests that host constants match it).
pub fn wgsl_constant(module: &naga::Module, name: &str) -> naga::Literal {
    let (_, c) = module
        .constants
        .iter()
        .find(|(_, c)| c.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("no const {name}"));
    match module.global_expressions[c.init] {
        naga::Expression::Literal(l) => l,
        ref e => panic!("const {name} is not a literal: {e:?}"),
    }
}
