//! The scene as the renderer sees it: flat triangles with materials, point lights and a
//! pinhole camera (paper section 4: the paper's only light type is the point light).
//!
//! Loading lives in [`loader`] (the TOML contract and OBJ/MTL, with private modules by
//! format: `toml_file` for the scene file's schema and checks, `obj`, `mtl`, and `error`
//! for [`SceneError`] and its message helpers) and [`gltf`], the built-in Cornell box
//! in [`builtin`].

pub mod builtin;
mod error;
pub mod gltf;
pub mod loader;
mod mtl;
mod obj;
mod toml_file;

use glam::{Vec2, Vec3, Vec3A, Vec4};
use std::path::PathBuf;

use crate::texture::{Texture, TextureRef};

pub use loader::{
    camera_toml, load_scene, max_light_intensity, parse_camera_toml, without_os_error_code,
    SceneError,
};

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
    /// image, y = 0 the top row: the CPU twin of direct.wgsl's `camera_ray_dir` (frame 0 of
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

/// Lambertian albedo plus a perfect mirror; `diffuse + mirror <= 1` per channel. A base
/// colour texture and vertex colours multiply both (so the bound holds at every texel).
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub name: String,
    pub diffuse: Vec3,
    pub mirror: Vec3,
    /// The base colour texture (glTF `baseColorTexture`, MTL `map_Kd`): its RGB multiplies
    /// `diffuse` and `mirror`, its alpha the opacity.
    pub texture: Option<TextureRef>,
    /// Whether the triangles' vertex colours ([`TriAttributes::color`], glTF `COLOR_0`)
    /// multiply the colour and the opacity.
    pub vertex_colors: bool,
    pub alpha: Alpha,
}

impl Material {
    /// An opaque material of constant colour.
    pub fn new(name: impl Into<String>, diffuse: Vec3, mirror: Vec3) -> Material {
        Material {
            name: name.into(),
            diffuse,
            mirror,
            texture: None,
            vertex_colors: false,
            alpha: Alpha::OPAQUE,
        }
    }

    /// Whether rays test this material's opacity where they hit it (its triangles are cut
    /// out where opacity < cutoff): [`AlphaMode::Mask`].
    pub fn alpha_tested(&self) -> bool {
        matches!(self.alpha.mode, AlphaMode::Mask { .. })
    }

    /// Whether its triangles need [`TriAttributes`] (texture coordinates or colours).
    pub fn uses_attributes(&self) -> bool {
        self.texture.is_some() || self.vertex_colors
    }
}

/// How a material's opacity shapes its geometry.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AlphaMode {
    /// Every point of the surface is there, whatever its alpha.
    Opaque,
    /// A point is there where opacity >= `cutoff` and cut out (every ray passes) elsewhere
    /// (glTF MASK; BLEND, MTL `d` and `map_d` are read as masks at 0.5: see the loaders).
    Mask { cutoff: f32 },
}

/// A material's opacity: `factor` (glTF's base colour factor alpha, MTL `d`) times the
/// texture's alpha and the vertex colours' alpha, tested by `mode`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Alpha {
    pub mode: AlphaMode,
    pub factor: f32,
}

impl Alpha {
    pub const OPAQUE: Alpha = Alpha {
        mode: AlphaMode::Opaque,
        factor: 1.0,
    };
}

/// What a textured or vertex-coloured triangle carries besides its geometry, per vertex
/// (in the order of [`Triangle::v`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriAttributes {
    /// Texture coordinates (the set its material's texture reads), glTF convention: (0, 0)
    /// is the image's top-left corner ([`crate::texture`]).
    pub uv: [Vec2; 3],
    /// Linear RGBA vertex colours (1 where the mesh has none).
    pub color: [Vec4; 3],
}

impl TriAttributes {
    pub const NONE: TriAttributes = TriAttributes {
        uv: [Vec2::ZERO; 3],
        color: [Vec4::ONE; 3],
    };
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
    /// Area, computed in f64: the f32 cross product of a valid triangle overflows once its
    /// edges pass about 1e19 (and underflows below about 1e-19).
    pub fn area(&self) -> f32 {
        (0.5 * cross_f64(&self.v).length()) as f32
    }
}

/// (v1 - v0) x (v2 - v0) in f64: finite and exact enough for any finite f32 vertices.
fn cross_f64(v: &[Vec3; 3]) -> glam::DVec3 {
    let [a, b, c] = v.map(|p| p.as_dvec3());
    (b - a).cross(c - a)
}

/// 2^j for j in [-126, 127], exactly (the exponent field alone).
fn pow2(j: i32) -> f32 {
    f32::from_bits(((127 + j) as u32) << 23)
}

/// `e` times the power of two that brings its largest component into [0.5, 1) (zero stays
/// zero). Only exponents change, so the products of two scaled edges round exactly as the
/// unscaled ones do, without their overflow (edges past ~1e19) or underflow. Twin of
/// surface.wgsl's `scale_pow2`; the factor is applied in two halves so that each stays a
/// normal f32.
pub fn scale_pow2(e: Vec3A) -> Vec3A {
    let m = e.abs().max_element();
    let k = 126 - ((m.to_bits() >> 23) & 0xff) as i32;
    e * pow2(k / 2) * pow2(k - k / 2)
}

/// The unit geometric normal of the triangle `v` (on the side of its winding), or `None`
/// when it is degenerate: zero area in f32, or edges that are not finite f32 numbers.
/// The cross product is taken of edges scaled by powers of two ([`scale_pow2`]), as the
/// GPU's `geometric_normal` does, so a large valid triangle (whose plain f32 cross
/// product overflows) is kept and gets the normal the GPU computes, and every other
/// triangle gets exactly the normal of the plain formula. The loaders keep what this
/// accepts.
///
/// In `Vec3A`, whose fourth lane glam keeps a copy of z, and not `Vec3`: LLVM vectorised
/// the `Vec3` arithmetic with fourth lanes left undefined, whose products were often
/// subnormal, and each cost a microcode assist, which made the normals several times
/// slower and a visible share of loading a large scene.
/// The results are the same bit for bit (the same products and sums in the same order;
/// the tests compare with the plain formula).
pub fn geometric_normal(v: &[Vec3; 3]) -> Option<Vec3> {
    let [a, b, c] = v.map(Vec3A::from);
    let (e1, e2) = (b - a, c - a);
    if !(e1.is_finite() && e2.is_finite()) {
        return None;
    }
    let n = scale_pow2(e1).cross(scale_pow2(e2));
    // At most 2 per component: the length is finite.
    let len = n.length();
    (len > 0.0).then(|| Vec3::from(n / len))
}

/// Length of the box diagonal hi - lo, in f64: its f32 square overflows once the box
/// passes ~1.8e19 (a triangle at 1e20 among small ones made it, and the default bounding
/// distance of G, infinite). Saturates at f32::MAX, for boxes whose diagonal itself is
/// past the f32 range; an empty box (lo > hi) gives 0.
pub fn diagonal_of(lo: Vec3, hi: Vec3) -> f32 {
    let d = (hi.as_dvec3() - lo.as_dvec3())
        .max(glam::DVec3::ZERO)
        .length();
    d.min(f32::MAX as f64) as f32
}

/// A loaded scene, ready for the BVH build and the GPU upload.
#[derive(Clone, Debug)]
pub struct Scene {
    pub camera: Camera,
    pub film: Film,
    pub triangles: Vec<Triangle>,
    pub materials: Vec<Material>,
    /// The images that materials' [`Material::texture`] index.
    pub textures: Vec<Texture>,
    /// Empty, or one entry per triangle (in the order of [`Scene::triangles`]) where some
    /// material [`uses_attributes`](Material::uses_attributes).
    pub attributes: Vec<TriAttributes>,
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
        diagonal_of(lo, hi)
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
    fn geometric_normal_of_large_and_degenerate_triangles() {
        let big = |e: f32| {
            [
                Vec3::new(-e, -e, 0.0),
                Vec3::new(e, -e, 0.0),
                Vec3::new(0.0, e, 0.0),
            ]
        };
        // The plain f32 cross product of edges 2e10 overflows: the triangle is valid.
        for e in [1.0, 1e10, 1e18, 1e30, 1e37] {
            assert_eq!(geometric_normal(&big(e)), Some(Vec3::Z), "{e}");
        }
        assert_eq!(geometric_normal(&big(1e-30)), Some(Vec3::Z));
        // Zero area, edges beyond f32, vertices not finite: degenerate.
        let line = [Vec3::ZERO, Vec3::splat(1e10), Vec3::splat(2e10)];
        assert_eq!(geometric_normal(&line), None);
        assert_eq!(geometric_normal(&[Vec3::X; 3]), None);
        assert_eq!(geometric_normal(&big(3e38)), None);
        assert_eq!(geometric_normal(&[Vec3::NAN, Vec3::X, Vec3::Y]), None);
        // Elsewhere exactly the plain formula's normal (scaling by powers of two is exact).
        let mut x = 0x2545_f491_u32;
        let mut r = || {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            (x as f32 / u32::MAX as f32 - 0.5) * 20.0
        };
        for _ in 0..1000 {
            let v = [0; 3].map(|_| Vec3::new(r(), r(), r()));
            let c = (v[1] - v[0]).cross(v[2] - v[0]);
            assert_eq!(geometric_normal(&v), Some(c / c.length()));
        }
    }

    #[test]
    fn diagonal_of_far_bounds_is_finite() {
        // |hi - lo|^2 of 1e20 overflows f32.
        let d = diagonal_of(Vec3::ZERO, Vec3::new(1e20, 1.0, 1.0));
        assert!((d / 1e20 - 1.0).abs() < 1e-6, "{d}");
        assert_eq!(diagonal_of(Vec3::ZERO, Vec3::new(3.0, 4.0, 0.0)), 5.0);
        assert_eq!(diagonal_of(Vec3::splat(-3e38), Vec3::splat(3e38)), f32::MAX);
        assert_eq!(diagonal_of(Vec3::INFINITY, Vec3::NEG_INFINITY), 0.0);
    }

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
