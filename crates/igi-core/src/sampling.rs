//! The Halton sequence that drives the light paths of VPL shooting (paper section 4:
//! "particles ... using the Halton sequence"), and the sampling maps built on it.
//! `halton.wgsl` in igi-gpu is the GPU twin of [`radical_inverse`]; a test compares them.

use glam::Vec3;
use std::f32::consts::PI;

/// The first 64 primes: the bases of Halton dimensions 0..64.
pub const PRIMES: [u32; 64] = [
    2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37, 41, 43, 47, 53, 59, 61, 67, 71, 73, 79, 83, 89, 97,
    101, 103, 107, 109, 113, 127, 131, 137, 139, 149, 151, 157, 163, 167, 173, 179, 181, 191, 193,
    197, 199, 211, 223, 227, 229, 233, 239, 241, 251, 257, 263, 269, 271, 277, 281, 283, 293, 307,
    311,
];

/// Largest f32 below one: sample values stay in [0, 1).
pub const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// Radical inverse of `index` in `base`: the digits of `index` mirrored about the point.
/// Accumulated in f32 digit by digit (not through an integer that would overflow u32 for
/// bases above 2), exactly as the WGSL twin does it.
pub fn radical_inverse(base: u32, index: u32) -> f32 {
    let inv_base = 1.0 / base as f32;
    let mut n = index;
    let mut weight = inv_base;
    let mut value = 0.0f32;
    while n > 0 {
        let next = n / base;
        let digit = n - next * base;
        value += digit as f32 * weight;
        weight *= inv_base;
        n = next;
    }
    value.min(ONE_MINUS_EPSILON)
}

/// Halton sample `index` in dimension `dim` (dimensions beyond the prime table wrap).
pub fn halton(dim: usize, index: u32) -> f32 {
    radical_inverse(PRIMES[dim % PRIMES.len()], index)
}

/// First Halton index of the light paths of frame `frame` with seed `seed`, for `paths`
/// paths a frame. Consecutive frames take consecutive windows of the sequence, so K
/// accumulated frames form one low-discrepancy set of K x paths paths; the seed moves the
/// whole run to another part of the sequence. Index 0 (all zeros) is never used.
pub fn halton_base(seed: u32, frame: u32, paths: u32) -> u32 {
    let seed_offset = seed.wrapping_mul(0x9E37_79B1) >> 8;
    1u32.wrapping_add(seed_offset)
        .wrapping_add(frame.wrapping_mul(paths))
}

/// Halton index window used to estimate VPLs per path before the real shooting; disjoint
/// from the render's windows for any practical seed, so the path count the pilot picks is
/// independent of the paths it is used with.
pub fn pilot_base(seed: u32) -> u32 {
    halton_base(seed, 0, 0) ^ 0x8000_0000
}

/// Uniform direction on the unit sphere from two uniform numbers.
pub fn uniform_sphere(u1: f32, u2: f32) -> Vec3 {
    let z = 1.0 - 2.0 * u1;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u2;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Cosine-weighted direction about +z from two uniform numbers (Malley's method).
pub fn cosine_hemisphere(u1: f32, u2: f32) -> Vec3 {
    let r = u1.sqrt();
    let phi = 2.0 * PI * u2;
    Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - u1).max(0.0).sqrt())
}

/// An orthonormal basis (t, b) completing unit `n` (Duff et al. 2017).
pub fn orthonormal_basis(n: Vec3) -> (Vec3, Vec3) {
    let sign = 1.0f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        Vec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radical_inverse_known_values() {
        // Base 2: 1 -> 0.1b = 0.5, 2 -> 0.01b = 0.25, 3 -> 0.11b = 0.75, 6 -> 0.011b.
        assert_eq!(radical_inverse(2, 1), 0.5);
        assert_eq!(radical_inverse(2, 2), 0.25);
        assert_eq!(radical_inverse(2, 3), 0.75);
        assert_eq!(radical_inverse(2, 6), 0.375);
        // Base 3: 1 -> 1/3, 2 -> 2/3, 3 -> 0.01 (base 3) = 1/9, 5 = 12 (base 3) -> 0.21 = 7/9.
        assert!((radical_inverse(3, 1) - 1.0 / 3.0).abs() < 1e-7);
        assert!((radical_inverse(3, 2) - 2.0 / 3.0).abs() < 1e-7);
        assert!((radical_inverse(3, 3) - 1.0 / 9.0).abs() < 1e-7);
        assert!((radical_inverse(3, 5) - 7.0 / 9.0).abs() < 1e-7);
        // Base 5: 7 = 12 (base 5) -> 0.21 = 2/5 + 1/25 = 0.44.
        assert!((radical_inverse(5, 7) - 0.44).abs() < 1e-7);
        // Index 0 is 0 in every base; large indices stay below one.
        assert_eq!(radical_inverse(7, 0), 0.0);
        assert!(radical_inverse(2, u32::MAX) < 1.0);
        assert!((radical_inverse(2, u32::MAX) - ONE_MINUS_EPSILON).abs() < 1e-7);
        // Halton dimension 1 is base 3.
        assert_eq!(halton(1, 5), radical_inverse(3, 5));
    }

    #[test]
    fn first_points_of_base_two_are_stratified() {
        // The first 2^k points of base 2 fall one in each interval [i/2^k, (i+1)/2^k).
        let mut seen = [false; 16];
        for i in 0..16 {
            seen[(radical_inverse(2, i) * 16.0) as usize] = true;
        }
        assert!(seen.iter().all(|&s| s));
    }

    #[test]
    fn sampling_maps_are_unit_and_oriented() {
        for i in 1..200 {
            let s = uniform_sphere(halton(0, i), halton(1, i));
            assert!((s.length() - 1.0).abs() < 1e-5);
            let c = cosine_hemisphere(halton(2, i), halton(3, i));
            assert!((c.length() - 1.0).abs() < 1e-5 && c.z >= 0.0);
            let n = s;
            let (t, b) = orthonormal_basis(n);
            assert!(t.dot(n).abs() < 1e-5 && b.dot(n).abs() < 1e-5 && t.dot(b).abs() < 1e-5);
        }
    }
}
