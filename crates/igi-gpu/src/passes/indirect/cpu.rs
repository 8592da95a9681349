//! CPU twin of `shaders/gather.wgsl` as `indirect.wgsl` runs it: E at the
//! representative pixel of each pixel of the indirect term, from the VPLs of its
//! interleaving subset (paper sections 4 and 4.3), E(x) = n m sum_k Phi_k (rho_k / pi)
//! V(x, y_k) G(x, y_k) with the bounded G of geometry_term.wgsl. Function by function as the
//! WGSL, with its names; its bindings are the fields of [`Gather`], and its dispatches
//! over the ranges of the VPL list and its lanes are the arguments of [`Gather::image`],
//! so that the twin adds what the GPU adds in the order the GPU adds it.
//!
//! Visibility is the CPU traversal of the same BVH (`igi_core::bvh`, the twin of
//! traverse.wgsl) with the same ray ends (`offset_ray_origin`). Imperfect visibility
//! (boxes for triangles) has no CPU walk, so this twin gathers with perfect visibility
//! only.

use crate::layout::{FrameParams, Vpl};
use crate::shaders::gbuffer::{representative_pixel, Rgba};
use crate::shaders::upsample::xyz;
use glam::Vec3;
use igi_core::bvh::{offset_ray_origin, Bvh};
use igi_core::sampling::hash_u32;

/// PI of constants.wgsl (3.14159265358979 there, the same f32).
pub const PI: f32 = std::f32::consts::PI;

/// indirect.wgsl's bindings (and the BVH of its scene bind group): the VPL list (its
/// header's count is the list's length), the G-buffer (or the mirror record) and the
/// frame's parameters.
pub struct Gather<'a> {
    pub params: &'a FrameParams,
    pub vpls: &'a [Vpl],
    pub bvh: &'a Bvh,
    pub gbuf_position: &'a [Rgba],
    pub gbuf_normal: &'a [Rgba],
    pub gbuf_geometric: &'a [Rgba],
}

/// One dispatch's range of the VPL list (gather.wgsl's `GatherRange`).
#[derive(Clone, Copy, Debug)]
pub struct GatherRange {
    pub begin: u32,
    pub end: u32,
}

impl Gather<'_> {
    /// The VPLs [first, last) a dispatch over `range` gathers from.
    pub fn gather_first(&self, range: GatherRange) -> u32 {
        range.begin
    }
    pub fn gather_last(&self, range: GatherRange) -> u32 {
        range.end.min(self.vpls.len() as u32)
    }

    /// The VPL subset of pixel (x, y): its place in its n x m tile, permuted per tile
    /// when the pattern is irregular.
    pub fn interleave_subset(&self, x: u32, y: u32) -> u32 {
        let p = self.params;
        let local = (x % p.interleave_n) + p.interleave_n * (y % p.interleave_m);
        if p.pattern == 0 {
            return local;
        }
        self.irregular_subset(x, y, local)
    }

    /// The irregular pattern's subset at place `local` of pixel (x, y)'s tile: a seeded
    /// Fisher-Yates permutation of the tile's places.
    pub fn irregular_subset(&self, x: u32, y: u32, local: u32) -> u32 {
        let n = self.params.interleave_n;
        let m = self.params.interleave_m;
        let mut perm = [0u32; 64];
        let count = n * m;
        for (i, slot) in perm.iter_mut().enumerate().take(count as usize) {
            *slot = i as u32;
        }
        let tile = ((x / n).wrapping_mul(0x8da6_b343)) ^ ((y / m).wrapping_mul(0xd816_3841));
        let mut h = hash_u32(self.params.seed ^ hash_u32(tile));
        let mut i = count - 1;
        while i > 0 {
            h = hash_u32(h.wrapping_add(0x9e37_79b9));
            let j = h % (i + 1);
            perm.swap(i as usize, j as usize);
            i -= 1;
        }
        perm[local as usize]
    }

    /// E at surface point p from the subset of pixel (x, y): the subset's VPLs within
    /// `range`, from `lane` on, every `lanes`-th (not yet scaled by the subset count).
    #[allow(clippy::too_many_arguments)]
    pub fn subset_irradiance(
        &self,
        p: Vec3,
        ng: Vec3,
        ns: Vec3,
        x: u32,
        y: u32,
        lane: u32,
        lanes: u32,
        range: GatherRange,
    ) -> Vec3 {
        let subsets = self.params.interleave_n * self.params.interleave_m;
        let subset = self.interleave_subset(x, y);
        // First VPL of the subset within the dispatch's range, then this lane's.
        let begin = self.gather_first(range);
        let first = begin + (subset + subsets - begin % subsets) % subsets + lane * subsets;
        self.vpl_irradiance(p, ng, ns, first, self.gather_last(range), subsets * lanes)
    }

    /// What a pixel holds after the dispatch over `range`: what earlier ranges left
    /// (`previous`, ignored in the first range) plus this range's `sum`, scaled by the
    /// subset count.
    pub fn accumulated_irradiance(&self, previous: Rgba, sum: Vec3, range: GatherRange) -> Rgba {
        let mut e = Vec3::ZERO;
        if self.gather_first(range) > 0 {
            e = xyz(previous);
        }
        let e = e + (self.params.interleave_n * self.params.interleave_m) as f32 * sum;
        [e.x, e.y, e.z, 1.0]
    }

    /// The sum over VPLs first, first + stride, ... below `count` of their light at p,
    /// each behind its shadow ray.
    pub fn vpl_irradiance(
        &self,
        p: Vec3,
        ng: Vec3,
        ns: Vec3,
        first: u32,
        count: u32,
        stride: u32,
    ) -> Vec3 {
        let floor = self.params.ray_offset_floor;
        let mut e = Vec3::ZERO;
        let mut k = first;
        while k < count {
            let vpl = &self.vpls[k as usize];
            k += stride;
            let position = Vec3::from(vpl.position);
            let normal = Vec3::from(vpl.normal);
            let d = position - p;
            let dist2 = d.dot(d);
            let inv_dist = 1.0 / dist2.sqrt();
            let cos_x = ns.dot(d) * inv_dist;
            let cos_y = -normal.dot(d) * inv_dist;
            if cos_x <= 0.0 || cos_y <= 0.0 || ng.dot(d) <= 0.0 {
                continue;
            }
            let g = cos_x * cos_y * self.bounded_inverse_square(dist2);
            if g <= 0.0 {
                continue;
            }
            let end = offset_ray_origin(position, normal, floor);
            let origin = offset_ray_origin(p, ng, floor);
            if self.bvh.trace_segment(origin, end - origin) {
                continue;
            }
            e += Vec3::from(vpl.flux) * Vec3::from(vpl.albedo) * (g / PI);
        }
        e
    }

    /// `bounded_inverse_square` of geometry_term.wgsl: the paper's smoothstep(0.8 m, 1.2 m, d) /
    /// d^2, or the classic clamp 1 / max(d^2, m^2).
    pub fn bounded_inverse_square(&self, dist2: f32) -> f32 {
        let m = self.params.min_dist;
        if self.params.geometry_bound == 1 {
            return 1.0 / dist2.max(m * m);
        }
        smoothstep(0.8 * m, 1.2 * m, dist2.sqrt()) / dist2
    }

    /// indirect.wgsl's `pixel_sum`: one pixel's share of E from `range`, its subset's
    /// VPLs from `lane` on, every `lanes`-th; 0 where its primary ray hit nothing.
    pub fn pixel_sum(&self, x: u32, y: u32, lane: u32, lanes: u32, range: GatherRange) -> Vec3 {
        let pixel = representative_pixel(self.params, x, y);
        let position = self.gbuf_position[pixel];
        if position[3] <= 0.0 {
            return Vec3::ZERO;
        }
        self.subset_irradiance(
            xyz(position),
            xyz(self.gbuf_geometric[pixel]),
            xyz(self.gbuf_normal[pixel]),
            x,
            y,
            lane,
            lanes,
            range,
        )
    }

    /// The indirect term (low_width x low_height) as the gathering dispatches leave it:
    /// one dispatch per range of `vpls_per_dispatch` VPLs (the ranges of
    /// `Renderer::submit_frame`; u32::MAX for one), each pixel's VPLs split over `lanes`
    /// lanes whose sums are added in lane order (`main` is one lane, `main_coherent`
    /// several).
    pub fn image(&self, vpls_per_dispatch: u32, lanes: u32) -> Vec<Rgba> {
        let p = self.params;
        let count = self.vpls.len() as u64;
        let per = u64::from(vpls_per_dispatch.max(1));
        let ranges: Vec<GatherRange> = (0..count.div_ceil(per).max(1))
            .map(|i| GatherRange {
                begin: (i * per).min(u32::MAX as u64) as u32,
                end: ((i + 1) * per).min(u32::MAX as u64) as u32,
            })
            .collect();
        let mut out = vec![[0.0f32; 4]; (p.low_width * p.low_height) as usize];
        for range in ranges {
            for y in 0..p.low_height {
                for x in 0..p.low_width {
                    let mut total = Vec3::ZERO;
                    for lane in 0..lanes {
                        total += self.pixel_sum(x, y, lane, lanes, range);
                    }
                    // store_irradiance
                    let low = (y * p.low_width + x) as usize;
                    out[low] = self.accumulated_irradiance(out[low], total, range);
                }
            }
        }
        out
    }
}

/// WGSL's smoothstep(e0, e1, x): t = clamp((x - e0) / (e1 - e0), 0, 1), t^2 (3 - 2 t).
pub fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The irregular pattern gives each place of a tile its own subset (a permutation),
    /// and not the regular pattern's in every tile.
    #[test]
    fn twins_irregular_subsets_are_a_permutation_per_tile() {
        let params = FrameParams {
            width: 64,
            height: 64,
            interleave_n: 3,
            interleave_m: 2,
            pattern: 1,
            seed: 5,
            ..FrameParams::default()
        };
        let bvh = Bvh::build_from_vertices(&[]);
        let g = Gather {
            params: &params,
            vpls: &[],
            bvh: &bvh,
            gbuf_position: &[],
            gbuf_normal: &[],
            gbuf_geometric: &[],
        };
        let mut differs = false;
        for tile in 0..8 {
            let (tx, ty) = (tile * 3, tile * 2);
            let mut seen: Vec<u32> = (0..6)
                .map(|k| g.interleave_subset(tx + k % 3, ty + k / 3))
                .collect();
            differs |= seen != (0..6).collect::<Vec<_>>();
            seen.sort_unstable();
            assert_eq!(seen, (0..6).collect::<Vec<_>>(), "tile {tile}");
        }
        assert!(differs, "every tile kept the regular order");
    }
}
