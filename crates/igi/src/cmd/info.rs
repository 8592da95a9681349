//! `igi info`: the GPU adapters wgpu sees, and the one igi would pick.

use anyhow::{bail, Result};

pub fn run() -> Result<()> {
    let (adapters, best) = igi_gpu::context::list_adapters();
    if adapters.is_empty() {
        bail!(igi_gpu::GpuError::NoAdapter);
    }
    for a in &adapters {
        let mark = if Some(a.index) == best { "*" } else { " " };
        igi::say!(
            "{mark} {}: {} ({}, {}, driver: {}, timestamps: {})",
            a.index,
            a.name,
            a.backend,
            a.device_type,
            if a.driver.is_empty() { "?" } else { &a.driver },
            if a.timestamps { "yes" } else { "no" }
        );
        if let Some(why) = &a.unusable {
            igi::say!("     unusable: it {why}");
        }
    }
    if let Some(i) = best {
        igi::say!("igi would use adapter {i} (marked *); choose another with --adapter INDEX|NAME");
    }
    Ok(())
}
