//! The Halton sequence that drives the light paths of VPL shooting (paper section 4:
//! "particles ... using the Halton sequence"), and the sampling maps built on it.
//! `vpl.wgsl` in igi-gpu holds the GPU twin of [`scrambled_radical_inverse`]; the VPL
//! twin test compares the paths it drives.
//!
//! Light paths use the Halton sequence with random digit permutations (one permutation
//! of the digits 0..p per dimension, chosen by the seed; pbrt-v3's scrambled Halton). The
//! plain sequence is poor for the few dozen paths IGI shoots: in base p the first p
//! points are 1/p, 2/p, ..., so for a roulette dimension of base 37 the first 12 paths all
//! read values below 0.33 and all survive; permuting the digits spreads them.

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

/// Offset of dimension d's permutation in [`DigitPermutations::table`]: the sum of the
/// primes before it.
pub const fn permutation_offset(dim: usize) -> u32 {
    let mut sum = 0;
    let mut i = 0;
    while i < dim {
        sum += PRIMES[i];
        i += 1;
    }
    sum
}

/// Entries of the permutation table: the sum of all primes of [`PRIMES`].
pub const PERMUTATION_TABLE_LEN: usize = permutation_offset(PRIMES.len()) as usize;

/// Random permutations of the digits 0..p of each Halton dimension, concatenated.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DigitPermutations {
    pub table: Vec<u32>,
}

/// A 32-bit integer hash (Chris Wellons' lowbias32): seeds the shuffles.
pub fn hash_u32(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    x
}

impl DigitPermutations {
    /// The identity in every dimension: the plain Halton sequence.
    pub fn identity() -> Self {
        let mut table = Vec::with_capacity(PERMUTATION_TABLE_LEN);
        for &p in &PRIMES {
            table.extend(0..p);
        }
        DigitPermutations { table }
    }

    /// One Fisher-Yates shuffle per dimension, driven by a hash of (seed, dimension, step).
    pub fn new(seed: u32) -> Self {
        let mut perms = Self::identity();
        for (dim, &p) in PRIMES.iter().enumerate() {
            let offset = permutation_offset(dim) as usize;
            let digits = &mut perms.table[offset..offset + p as usize];
            let mut state = hash_u32(seed ^ hash_u32(dim as u32 + 0x51ed_270b));
            for i in (1..p as usize).rev() {
                state = hash_u32(state.wrapping_add(0x9e37_79b9));
                digits.swap(i, (state % (i as u32 + 1)) as usize);
            }
        }
        perms
    }
}

/// Radical inverse of `index` in the base of `dim` with each digit permuted, over as
/// many digits as a u32 index can have in that base (the permuted zeros past the last
/// digit of `index` count too, as in pbrt-v3). Accumulated in f32 digit by digit exactly
/// as the WGSL twin does it.
pub fn scrambled_radical_inverse(perms: &DigitPermutations, dim: usize, index: u32) -> f32 {
    let dim = dim % PRIMES.len();
    let base = PRIMES[dim];
    let offset = permutation_offset(dim) as usize;
    let inv_base = 1.0 / base as f32;
    let mut n = index;
    let mut weight = inv_base;
    let mut value = 0.0f32;
    // Digits until base^k reaches 2^32.
    let mut reach = 1.0f32;
    while reach < 4_294_967_296.0 {
        let next = n / base;
        let digit = n - next * base;
        value += perms.table[offset + digit as usize] as f32 * weight;
        weight *= inv_base;
        reach *= base as f32;
        n = next;
    }
    value.min(ONE_MINUS_EPSILON)
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
    fn scrambled_radical_inverse_known_values() {
        let id = DigitPermutations::identity();
        assert_eq!(id.table.len(), PERMUTATION_TABLE_LEN);
        // The identity gives the plain sequence (trailing zeros add nothing).
        for i in [1u32, 2, 3, 5, 7, 1000, 123_456] {
            for dim in [0usize, 1, 2, 11, 63] {
                let (a, b) = (scrambled_radical_inverse(&id, dim, i), halton(dim, i));
                assert!((a - b).abs() < 1e-6, "dim {dim} index {i}: {a} vs {b}");
            }
        }
        // A hand-made permutation of base 3 (dimension 1): 0->2, 1->0, 2->1. Index 5 is 12
        // in base 3, digits (least first) 2, 1, then zeros: 1/3 + 0/9 + 2/27 + 2/81 + ...
        // = 1/3 + 2 (1/27) / (1 - 1/3) over 21 digits.
        let mut perms = DigitPermutations::identity();
        let o = permutation_offset(1) as usize;
        perms.table[o..o + 3].copy_from_slice(&[2, 0, 1]);
        let tail: f64 = (3..=21).map(|k| 2.0 / 3f64.powi(k)).sum();
        let expected = 1.0 / 3.0 + tail;
        assert!((scrambled_radical_inverse(&perms, 1, 5) as f64 - expected).abs() < 1e-6);
    }

    #[test]
    fn scrambled_sequence_is_a_permutation_of_strata() {
        // Scrambling permutes the strata: the first p^2 points of a dimension still fall
        // one in each interval [i/p^2, (i+1)/p^2), and different seeds differ.
        let a = DigitPermutations::new(1);
        let b = DigitPermutations::new(2);
        assert_ne!(a, b);
        for dim in [0usize, 1, 4, 11] {
            let p = PRIMES[dim];
            let n = p * p;
            // (Values can sit a rounding error below a stratum's end, so compare the gaps
            // between sorted values with 1/p^2 instead of flooring.)
            let mut v: Vec<f32> = (0..n)
                .map(|i| scrambled_radical_inverse(&a, dim, i))
                .collect();
            v.sort_by(f32::total_cmp);
            for w in v.windows(2) {
                let gap = (w[1] - w[0]) * n as f32;
                assert!(
                    (gap - 1.0).abs() < 1e-3,
                    "dimension {dim}: gap {gap} strata"
                );
            }
        }
        // The point of scrambling: the first 12 values of base 37 no longer all sit
        // below 0.33.
        let low = (1..13)
            .filter(|&i| scrambled_radical_inverse(&a, 11, i) < 0.33)
            .count();
        assert!(low < 12);
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
