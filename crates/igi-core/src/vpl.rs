//! CPU twin of `vpl.wgsl`: VPL shooting (paper section 4, first stage), the same light
//! paths with the same Halton dimensions, used by tests to check the GPU pass.

use crate::bvh::{offset_ray_origin, Bvh};
use crate::sampling::{
    cosine_hemisphere, orthonormal_basis, scrambled_radical_inverse, uniform_sphere,
    DigitPermutations,
};
use crate::scene::Scene;
use glam::Vec3;
use std::f32::consts::PI;

/// A virtual point light as the CPU twin stores it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CpuVpl {
    pub position: Vec3,
    pub normal: Vec3,
    pub flux: Vec3,
    pub albedo: Vec3,
    /// Diffuse hit number along its path, 1 = first hit.
    pub bounce: u32,
}

/// What a closest hit looks like to shading: both normals face the incoming ray.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceHit {
    pub position: Vec3,
    pub geometric_normal: Vec3,
    pub shading_normal: Vec3,
    pub diffuse: Vec3,
    pub mirror: Vec3,
}

/// Shading data at a closest hit (twin of `surface_at` in surface.wgsl).
pub fn surface_at(scene: &Scene, bvh: &Bvh, dir: Vec3, slot: u32, u: f32, v: f32) -> SurfaceHit {
    let tri = &scene.triangles[bvh.tri_order[slot as usize] as usize];
    let w = 1.0 - u - v;
    let position = w * tri.v[0] + u * tri.v[1] + v * tri.v[2];
    // Twin of surface.wgsl's geometric_normal (the loaders keep only triangles that have one).
    let mut ng = crate::scene::geometric_normal(&tri.v).unwrap_or(Vec3::Z);
    if ng.dot(dir) > 0.0 {
        ng = -ng;
    }
    let ns_raw = w * tri.n[0] + u * tri.n[1] + v * tri.n[2];
    let len = ns_raw.length();
    let mut ns = if len > 1e-12 { ns_raw / len } else { ng };
    if ns.dot(ng) < 0.0 {
        ns = -ns;
    }
    let m = &scene.materials[tri.material as usize];
    // Particles read level 0 (vpl.wgsl: a point sample).
    let c = if m.uses_attributes() {
        crate::texture::surface_color(scene, bvh.tri_order[slot as usize] as usize, u, v, 0.0)
            .truncate()
    } else {
        Vec3::ONE
    };
    SurfaceHit {
        position,
        geometric_normal: ng,
        shading_normal: ns,
        diffuse: m.diffuse * c,
        mirror: m.mirror * c,
    }
}

fn mean3(v: Vec3) -> f32 {
    (v.x + v.y + v.z) / 3.0
}

/// Shoot `paths` light paths from index `base` of the Halton sequence scrambled with
/// `perms`, storing at most `bounces` VPLs per path, in path order (the order of the
/// GPU's compacted list).
pub fn shoot_vpls(
    scene: &Scene,
    bvh: &Bvh,
    perms: &DigitPermutations,
    paths: u32,
    bounces: u32,
    mirror_depth: u32,
    base: u32,
) -> Vec<CpuVpl> {
    let halton = |dim: usize, index: u32| scrambled_radical_inverse(perms, dim, index);
    let floor = scene.ray_offset_floor();
    let weight = |l: usize| 4.0 * PI * scene.lights[l].intensity.element_sum();
    let power_sum: f32 = (0..scene.lights.len()).map(weight).sum();
    let mut out = vec![];
    for path in 0..paths {
        let index = base.wrapping_add(path);
        // As vpl.wgsl: a light of zero power is never chosen (its p_light of 0 made the
        // flux NaN), and a path stores nothing when no light emits.
        let mut u = halton(0, index) * power_sum;
        let mut chosen = None;
        for l in 0..scene.lights.len() {
            if weight(l) > 0.0 {
                chosen = Some(l);
                if u < weight(l) {
                    break;
                }
            }
            u -= weight(l);
        }
        let Some(chosen) = chosen else { continue };
        let light = &scene.lights[chosen];
        let p_light = weight(chosen) / power_sum;
        let mut flux = 4.0 * PI * light.intensity / (p_light * paths as f32);
        let mut origin = light.position;
        let mut dir = uniform_sphere(halton(1, index), halton(2, index));
        let mut stored = 0;
        let mut dim = 3;
        for _ in 0..bounces.saturating_add(mirror_depth) {
            let Some(hit) = bvh.trace_closest(origin, dir, f32::INFINITY) else {
                break;
            };
            let s = surface_at(scene, bvh, dir, hit.tri, hit.u, hit.v);
            if s.diffuse.max_element() > 0.0 {
                stored += 1;
                out.push(CpuVpl {
                    position: s.position,
                    normal: s.shading_normal,
                    flux,
                    albedo: s.diffuse,
                    bounce: stored,
                });
                if stored == bounces {
                    break;
                }
            }
            let p_diffuse = mean3(s.diffuse);
            let p_mirror = mean3(s.mirror);
            let choice = halton(dim + 2, index);
            if choice < p_diffuse {
                let local = cosine_hemisphere(halton(dim, index), halton(dim + 1, index));
                let n = s.shading_normal;
                let (t, b) = orthonormal_basis(n);
                dir = local.x * t + local.y * b + local.z * n;
                if dir.dot(s.geometric_normal) <= 0.0 {
                    break;
                }
                flux *= s.diffuse / p_diffuse;
            } else if choice < p_diffuse + p_mirror {
                dir = reflect(dir, s.shading_normal);
                if dir.dot(s.geometric_normal) <= 0.0 {
                    dir = reflect(dir, s.geometric_normal);
                }
                flux *= s.mirror / p_mirror;
            } else {
                break;
            }
            origin = offset_ray_origin(s.position, s.geometric_normal, floor);
            dim += 3;
        }
    }
    out
}

/// Mirror reflection of `d` about unit `n` (WGSL's `reflect`).
pub fn reflect(d: Vec3, n: Vec3) -> Vec3 {
    d - 2.0 * d.dot(n) * n
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::builtin::builtin_scene;

    /// Lights of zero power are never chosen (their p_light of 0 made the flux 0 / 0),
    /// and with no light that emits there are no VPLs.
    #[test]
    fn lights_of_zero_power_make_no_nan() {
        let mut scene = builtin_scene("cornell-box").unwrap();
        let bvh = Bvh::build(&scene.triangles);
        let perms = DigitPermutations::new(0);
        let light = scene.lights[0];
        let dark = crate::scene::PointLight {
            intensity: Vec3::ZERO,
            ..light
        };
        for (lights, expect_vpls) in [
            (vec![dark], false),
            (vec![dark, dark], false),
            (vec![dark, light], true),
            (vec![light, dark], true),
            (vec![dark, light, dark], true),
        ] {
            scene.lights = lights;
            let vpls = shoot_vpls(&scene, &bvh, &perms, 64, 4, 2, 0);
            assert_eq!(!vpls.is_empty(), expect_vpls, "{:?}", scene.lights);
            assert!(
                vpls.iter().all(|v| v.flux.is_finite()),
                "{:?}",
                scene.lights
            );
        }
    }
}
