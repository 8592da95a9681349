//! Arbitrary bytes to `load_gltf_bytes`, named both `fuzz.glb` and `fuzz.gltf` (the format
//! is told by the GLB magic; the name changes only messages). The files' directory is a
//! per-process temp dir that holds a 42-byte `b.bin` (one triangle: 3 f32 positions and
//! u16 indices 0 1 2) and a 1x1 `t.png`, so external buffer and image URIs can resolve.
#![no_main]

use std::path::PathBuf;
use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;

include!("../../crates/igi-core/tests/common/tiny_png.rs");

fn paths() -> &'static (PathBuf, PathBuf) {
    static PATHS: OnceLock<(PathBuf, PathBuf)> = OnceLock::new();
    PATHS.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("igi-fuzz-gltf-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("create the fuzz dir");
        let mut bin = Vec::new();
        for v in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
            bin.extend_from_slice(&v.to_le_bytes());
        }
        for i in [0u16, 1, 2] {
            bin.extend_from_slice(&i.to_le_bytes());
        }
        std::fs::write(dir.join("b.bin"), bin).expect("write b.bin");
        std::fs::write(dir.join("t.png"), PNG).expect("write t.png");
        (dir.join("fuzz.glb"), dir.join("fuzz.gltf"))
    })
}

fuzz_target!(|data: &[u8]| {
    let (glb, gltf) = paths();
    let _ = igi_core::scene::gltf::load_gltf_bytes(data, glb);
    let _ = igi_core::scene::gltf::load_gltf_bytes(data, gltf);
});
