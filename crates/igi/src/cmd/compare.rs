//! `igi compare`: a linear image against a reference, by relative MSE, channel means and
//! the pixels that differ.

use anyhow::Result;
use std::path::Path;

pub fn run(image: &Path, reference: &Path) -> Result<()> {
    let a = igi_core::image::Image::read_exr(image)?;
    let b = igi_core::image::Image::read_exr(reference)?;
    let c = igi_core::image::Comparison::of(&a, &b)?;
    let e = c.rel_mse;
    let (ma, mb) = c.means;
    // Five decimals as before, and the figure itself where they would round it to 0.
    if e > 0.0 && e < 5e-6 {
        igi::say!("relMSE {e:.5} ({e:.2e})");
    } else {
        igi::say!("relMSE {e:.5}");
    }
    igi::say!(
        "mean {:.4} {:.4} {:.4} (reference {:.4} {:.4} {:.4})",
        ma[0],
        ma[1],
        ma[2],
        mb[0],
        mb[1],
        mb[2]
    );
    let d = c.pixels;
    match d.largest {
        None => igi::say!("pixels differing: none of {} (the same bits)", d.pixels),
        Some((diff, (x, y), r)) => igi::say!(
            "pixels differing: {} of {}; largest difference {diff:.3e} at ({x}, {y}), where the reference is {r:.4e}",
            d.differing, d.pixels
        ),
    }
    Ok(())
}
