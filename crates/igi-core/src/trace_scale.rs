//! The frame igi traces a scene in: the scene's own coordinates times a power of two
//! chosen from its size, so that every scene traces as one of ordinary size does.
//!
//! Ray tests work in 32-bit floats. Their rounding is relative, but a few of their
//! quantities are not: the triangle test's distance is a product of three coordinates
//! (relative to the ray's origin), which overflows once a scene is about 1e12 across and
//! is flushed to zero when it is about 1e-13 across, and ray origins near a coordinate
//! plane move off their surface by a fixed distance (Wächter and Binder's 1/65536 within
//! 1/32 of it). A scene whose largest coordinate magnitude `M` lies in [`TRACED_RANGE`]
//! is traced as it is; any other is scaled by the power of two that brings `M` into the
//! range's nearer octave, with its camera, its lights, and its lights' intensities (by
//! the square: irradiance I / r^2 stays what it is). Multiplying by a power of two only
//! changes exponents, so the scaled scene's rays round exactly as the scene's own would
//! in that range: the image is the one the scene would have at an ordinary size.
//!
//! What no scale fixes is a scene that is small against its distance from the origin:
//! 32-bit floats place its points M 2^-24 apart, and [`check_precision`] refuses it
//! where that spacing, which sets how far ray origins move off surfaces, would be a
//! visible part of the scene.

use glam::Vec3;

/// The largest coordinate magnitudes traced unscaled: [2^-4, 2^20). Inside it, the
/// triangle test's products stay far from the f32 range's ends and the fixed offsets near
/// the coordinate planes are at most 1/4096 of the scene, too little to change an image
/// beyond rounding (`tests/scale.rs` renders rooms at 0.07 and 0.1 of their size
/// unscaled; the lab log has what smaller scenes gave without the scale).
pub const TRACED_RANGE: (f32, f32) = (0.0625, 1_048_576.0);

/// How far ray origins may move off surfaces, at most, as a part of the scene's size:
/// beyond it shadows detach from their casters visibly.
pub const MAX_OFFSET_FRACTION: f32 = 1.0 / 1024.0;

/// Scene coordinates times `factor` are trace coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TraceScale {
    /// A power of two; 1 for a scene traced as it is. In f64, which holds the factors of
    /// scenes whose size is a subnormal f32 too; products are exact either way.
    pub factor: f64,
}

impl TraceScale {
    pub const ONE: TraceScale = TraceScale { factor: 1.0 };

    /// The scale of a scene whose largest coordinate magnitude is `m` (see the module's
    /// documentation); 1 for an empty or non-finite `m`.
    pub fn for_magnitude(m: f32) -> TraceScale {
        let (lo, hi) = TRACED_RANGE;
        if !(m.is_finite() && m > 0.0) || (lo..hi).contains(&m) {
            return TraceScale::ONE;
        }
        // The exponent of m (subnormals included, through their f64 value).
        let e = (m as f64).log2().floor() as i32;
        let target = if m < lo {
            lo.log2() as i32
        } else {
            hi.log2() as i32 - 1
        };
        TraceScale {
            factor: (2.0f64).powi(target - e),
        }
    }

    /// The scale of a scene with triangles within `lo`..`hi` (its bounds).
    pub fn for_bounds(lo: Vec3, hi: Vec3) -> TraceScale {
        Self::for_magnitude(lo.abs().max(hi.abs()).max_element())
    }

    pub fn is_one(&self) -> bool {
        self.factor == 1.0
    }

    /// A position (or a displacement) in trace coordinates.
    pub fn point(&self, p: Vec3) -> Vec3 {
        (p.as_dvec3() * self.factor).as_vec3()
    }

    /// A distance in trace coordinates.
    pub fn length(&self, d: f32) -> f32 {
        (d as f64 * self.factor) as f32
    }

    /// A point light's intensity in trace coordinates: times the factor squared, so that
    /// the irradiance I / r^2 it gives is the scene's. Infinite where the result is past
    /// the f32 range (the renderer refuses such lights).
    pub fn intensity(&self, i: Vec3) -> Vec3 {
        (i.as_dvec3() * (self.factor * self.factor)).as_vec3()
    }
}

/// Error unless 32-bit floats resolve a scene with triangles within `lo`..`hi` finely
/// enough to trace it: the ray offset floor (32 ulps of its largest coordinate
/// magnitude, [`crate::bvh::offset_floor`]) must be at most [`MAX_OFFSET_FRACTION`] of
/// its diagonal. Scaling does not change the ratio, so this is the scene's own.
pub fn check_precision(lo: Vec3, hi: Vec3) -> Result<(), String> {
    let diagonal = crate::scene::diagonal_of(lo, hi);
    let floor = crate::bvh::offset_floor(lo, hi);
    if diagonal > 0.0 && floor > diagonal * MAX_OFFSET_FRACTION {
        let m = lo.abs().max(hi.abs()).max_element();
        return Err(format!(
            "the scene is {diagonal:.3e} across but lies up to {m:.3e} from the origin: 32-bit floats place points {:.3e} apart there, and ray origins would move {floor:.3e} off surfaces, more than 1/{} of the scene; move the scene nearer the origin (translate its coordinates)",
            m * f32::EPSILON * 0.5,
            (1.0 / MAX_OFFSET_FRACTION) as u32
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ordinary_scenes_are_traced_as_they_are() {
        for m in [0.0625, 0.5592, 1.0, 1.5, 559.2, 1653.0, 1_048_575.0] {
            assert!(TraceScale::for_magnitude(m).is_one(), "{m}");
        }
        assert!(TraceScale::for_magnitude(0.0).is_one());
        assert!(TraceScale::for_magnitude(f32::INFINITY).is_one());
    }

    #[test]
    fn other_scenes_come_into_the_range_by_a_power_of_two() {
        for k in -140..=127 {
            for frac in [1.0f64, 1.3, 1.999] {
                let m = (2.0f64.powi(k) * frac) as f32;
                if m == 0.0 || !m.is_finite() {
                    continue;
                }
                let s = TraceScale::for_magnitude(m);
                let f = s.factor;
                assert!(f.is_finite() && f > 0.0, "{m}: {f}");
                // A power of two: no mantissa bits.
                assert_eq!(f.to_bits() & 0x000f_ffff_ffff_ffff, 0, "{m}: {f}");
                let scaled = m as f64 * f;
                // Exact: scaling back gives m.
                assert_eq!(s.length(m) as f64, scaled, "{m}");
                let (lo, hi) = TRACED_RANGE;
                assert!(
                    scaled >= lo as f64 && scaled < hi as f64,
                    "{m} x {f} = {scaled} outside the range"
                );
                if m < lo {
                    assert!(scaled < 2.0 * lo as f64, "{m}: {scaled}");
                } else if m >= hi {
                    assert!(scaled >= hi as f64 / 2.0, "{m}: {scaled}");
                }
            }
        }
    }

    #[test]
    fn a_small_scene_far_from_the_origin_is_refused() {
        // A 1 x 1 x 1 box at the origin, and the same box a million units away.
        let near = (Vec3::ZERO, Vec3::ONE);
        assert!(check_precision(near.0, near.1).is_ok());
        let far = (Vec3::splat(1e6), Vec3::splat(1e6 + 1.0));
        let e = check_precision(far.0, far.1).unwrap_err();
        assert!(e.contains("nearer the origin"), "{e}");
        // The conference room: 1,653 units from the origin, thousands across.
        let room = (
            Vec3::new(-1653.0, -1.6, -1200.0),
            Vec3::new(1000.0, 300.0, 1300.0),
        );
        assert!(check_precision(room.0, room.1).is_ok());
    }
}
