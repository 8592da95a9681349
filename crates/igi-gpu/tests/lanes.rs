//! The indirect pass splits each pixel's VPL loop over 4, 8 or 16 lanes on a GPU (by the
//! indirect term's pixel count and VPLs per pixel), and its gather at hits seen in a
//! mirror over 8; the software adapter always uses one lane. Every way
//! must give the same image up to the order of the additions: this checks how lanes,
//! subsets and VPL ranges index the list. (Its own test binary: it sets
//! IGI_VPL_LANES for the whole process.)

mod common;

use common::*;
use igi_core::image::rel_mse;
use igi_core::settings::{Accelerations, RenderSettings};

#[test]
fn lanes_equal_one_lane() {
    let Some(ctx) = gpu() else { return };
    let scene = igi_core::scene::builtin::builtin_scene("cornell-box").unwrap();
    for setup in ["ds", "ds+il", "iv+ds+il+irregular"] {
        compare_lanes(&ctx, &scene, setup, "IGI_VPL_LANES", &lane_choices());
    }
    // The gather at hits seen in a mirror, over the list of those pixels
    // (IGI_MIRROR_LANES): its workgroup grows with the lanes from 16 on.
    let mirrors = mirror_floor(glam::Vec3::splat(0.3), glam::Vec3::splat(0.5));
    for setup in ["canonical", "iv+ds+il"] {
        compare_lanes(
            &ctx,
            &mirrors,
            setup,
            "IGI_MIRROR_LANES",
            &[2, 4, 8, 16, 32],
        );
    }
}

/// The lane counts of the indirect pass above one.
fn lane_choices() -> Vec<u32> {
    igi_gpu::passes::LANE_CHOICES
        .into_iter()
        .filter(|&l| l > 1)
        .collect()
}

fn compare_lanes(
    ctx: &igi_gpu::GpuContext,
    scene: &igi_core::scene::Scene,
    setup: &str,
    variable: &str,
    lane_counts: &[u32],
) {
    let settings = RenderSettings {
        width: 96,
        height: 96,
        vpls: 90,
        accelerations: Accelerations::from_setup(setup).unwrap(),
        ..RenderSettings::default()
    };
    std::env::set_var(variable, "1");
    let one = render(ctx, scene, &settings);
    for &lanes in lane_counts {
        std::env::set_var(variable, lanes.to_string());
        let split = render(ctx, scene, &settings);
        let mut worst = 0.0f32;
        for (a, b) in one.image.data.iter().zip(&split.image.data) {
            for c in 0..3 {
                worst = worst.max((a[c] - b[c]).abs() / a[c].abs().max(1e-3));
            }
        }
        eprintln!("{setup}: {variable}={lanes} against 1: worst relative difference {worst:e}");
        // The same terms, summed in another order: float rounding only.
        assert!(
            worst < 1e-4,
            "{variable}={lanes}: worst relative difference {worst}"
        );
        assert!(rel_mse(&split.image, &one.image).unwrap() < 1e-9);
    }
    std::env::remove_var(variable);
}
