//! Arbitrary bytes as the OBJ and MTL files of a fixed valid scene TOML: the input up to
//! the first NUL byte is `m.obj`, the rest (when there is a NUL) is `m.mtl`; without a NUL
//! there is no `m.mtl` (a missing material library). The loader reads meshes from disk,
//! so both are written to a per-process temp dir on every run.
#![no_main]

use std::path::PathBuf;
use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;

/// A valid scene whose mesh is `m.obj`; material `d` (default_material) and `t` are
/// defined in the TOML, others must come from `m.mtl`.
const TOML: &str = "[camera]\neye = [0.0, 0.0, 5.0]\ntarget = [0.0, 0.0, 0.0]\nfov_y_deg = 40.0\n\n[[mesh]]\npath = \"m.obj\"\ndefault_material = \"d\"\n\n[[point_light]]\nposition = [0.0, 0.0, 3.0]\nintensity = [1.0, 1.0, 1.0]\n\n[materials.d]\ndiffuse = [0.5, 0.5, 0.5]\n\n[materials.t]\nmirror = [0.3, 0.3, 0.3]\n";

/// The separator between the OBJ and the MTL.
const SEP: u8 = 0;

fn dir() -> &'static PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("igi-fuzz-obj-mtl-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("create the fuzz dir");
        dir
    })
}

fuzz_target!(|data: &[u8]| {
    let dir = dir();
    let (obj, mtl) = match data.iter().position(|&b| b == SEP) {
        Some(i) => (&data[..i], Some(&data[i + 1..])),
        None => (data, None),
    };
    std::fs::write(dir.join("m.obj"), obj).expect("write m.obj");
    match mtl {
        Some(mtl) => std::fs::write(dir.join("m.mtl"), mtl).expect("write m.mtl"),
        None => {
            let _ = std::fs::remove_file(dir.join("m.mtl"));
        }
    }
    let _ = igi_core::scene::loader::load_scene_str(TOML, dir, "fuzz.toml");
});
