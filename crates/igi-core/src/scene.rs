//! The scene as the renderer sees it: flat triangles with materials, point lights and a
//! pinhole camera (paper section 4: the paper's only light type is the point light).
//!
//! Loading lives in [`loader`] (the TOML contract and OBJ/MTL), the built-in Cornell box
//! in [`builtin`].

pub mod builtin;
pub mod gltf;
pub mod loader;

use glam::Vec3;
use std::path::PathBuf;

pub use loader::{camera_toml, load_scene, parse_camera_toml, SceneError};

/// A pinhole camera, as `[camera]` in the scene file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub eye: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    pub fov_y_deg: f32,
}

impl Camera {
    /// The camera's orthonormal frame: forward, right (forward x up), and the true up.
    pub fn basis(&self) -> (Vec3, Vec3, Vec3) {
        let forward = (self.target - self.eye).normalize();
        let right = forward.cross(self.up).normalize();
        (forward, right, right.cross(forward))
    }

    /// The primary ray direction through the centre of pixel (x, y) of a width x height
    /// image, y = 0 the top row: the CPU twin of frame.wgsl's `camera_ray_dir` (frame 0 of
    /// an accumulation, which looks through pixel centres).
    pub fn pixel_dir(&self, width: u32, height: u32, x: u32, y: u32) -> Vec3 {
        let (forward, right, up) = self.basis();
        let tan = (self.fov_y_deg.to_radians() * 0.5).tan();
        let aspect = width as f32 / height as f32;
        let sx = (2.0 * (x as f32 + 0.5) / width as f32 - 1.0) * tan * aspect;
        let sy = (1.0 - 2.0 * (y as f32 + 0.5) / height as f32) * tan;
        (forward + sx * right + sy * up).normalize()
    }
}

/// The default image size, as `[film]` in the scene file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Film {
    pub width: u32,
    pub height: u32,
}

/// Lambertian albedo plus a perfect mirror; `diffuse + mirror <= 1` per channel.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub name: String,
    pub diffuse: Vec3,
    pub mirror: Vec3,
}

/// A point light of radiant intensity `intensity` (W/sr, RGB); total power 4 pi I.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLight {
    pub position: Vec3,
    pub intensity: Vec3,
}

impl PointLight {
    /// Total emitted power (flux), 4 pi I per channel.
    pub fn power(&self) -> Vec3 {
        4.0 * std::f32::consts::PI * self.intensity
    }
}

/// One triangle of the scene. Surfaces are two-sided.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    /// Vertex positions, in the order of the file (fans of polygons keep the winding).
    pub v: [Vec3; 3],
    /// Unit shading normals at the vertices: the OBJ's `vn` where present, otherwise the
    /// geometric normal repeated three times.
    pub n: [Vec3; 3],
    /// Index into [`Scene::materials`].
    pub material: u32,
}

impl Triangle {
    /// Unnormalised geometric normal (v1 - v0) x (v2 - v0); its length is twice the area.
    pub fn cross(&self) -> Vec3 {
        (self.v[1] - self.v[0]).cross(self.v[2] - self.v[0])
    }
    pub fn area(&self) -> f32 {
        0.5 * self.cross().length()
    }
}

/// A loaded scene, ready for the BVH build and the GPU upload.
#[derive(Clone, Debug)]
pub struct Scene {
    pub camera: Camera,
    pub film: Film,
    pub triangles: Vec<Triangle>,
    pub materials: Vec<Material>,
    pub lights: Vec<PointLight>,
    /// Where the scene came from (a file, or `builtin:NAME`), for messages and reports.
    pub source: String,
    /// Files the scene was read from (the TOML and its meshes), for reports.
    pub files: Vec<PathBuf>,
}

impl Scene {
    /// Axis-aligned bounds of all triangles (min, max).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for t in &self.triangles {
            for v in t.v {
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
        (lo, hi)
    }

    /// Length of the diagonal of the bounds: the scene's size, used for default
    /// distances (the bounding distance of G) and the depth buffer's unit. Ray offsets
    /// use [`Scene::ray_offset_floor`] instead.
    pub fn diagonal(&self) -> f32 {
        let (lo, hi) = self.bounds();
        (hi - lo).length()
    }

    /// The least distance ray origins move off surfaces in this scene
    /// ([`crate::bvh::offset_floor`] of its bounds).
    pub fn ray_offset_floor(&self) -> f32 {
        let (lo, hi) = self.bounds();
        crate::bvh::offset_floor(lo, hi)
    }

    /// Total power of all lights (RGB).
    pub fn total_power(&self) -> Vec3 {
        self.lights.iter().map(|l| l.power()).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pixel_dir_looks_through_pixel_centres() {
        // Looking down -z with y up and a 90 degree field: tan(fov / 2) = 1.
        let cam = Camera {
            eye: Vec3::new(1.0, 2.0, 3.0),
            target: Vec3::new(1.0, 2.0, -7.0),
            up: Vec3::Y,
            fov_y_deg: 90.0,
        };
        assert_eq!(cam.basis(), (Vec3::NEG_Z, Vec3::X, Vec3::Y));
        // 4 x 2 pixels: pixel (3, 0) is the top right one, its centre at x = 1.5 (aspect
        // 2, three quarters of the half width) and y = 0.5 on the image plane at z = -1.
        let d = cam.pixel_dir(4, 2, 3, 0);
        assert!(
            (d - Vec3::new(1.5, 0.5, -1.0).normalize()).length() < 1e-6,
            "{d}"
        );
        // The centre pixel of an odd image looks straight ahead.
        assert!((cam.pixel_dir(3, 3, 1, 1) - Vec3::NEG_Z).length() < 1e-6);
    }
}
