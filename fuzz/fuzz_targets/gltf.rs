//! Arbitrary bytes to `load_gltf_bytes`, named both `fuzz.glb` and `fuzz.gltf` (the format
//! is told by the GLB magic; the name changes only messages). The files' directory is a
//! per-process temp dir that holds a 42-byte `b.bin` (one triangle: 3 f32 positions and
//! u16 indices 0 1 2) and a 1x1 `t.png`, so external buffer and image URIs can resolve.
#![no_main]

use std::path::PathBuf;
use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;

/// A 1x1 RGB PNG (pixel 200, 100, 50).
const PNG: [u8; 69] = [
    0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48, 0x44, 0x52,
    0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x01, 0x08, 0x02, 0x00, 0x00, 0x00, 0x90, 0x77, 0x53,
    0xde, 0x00, 0x00, 0x00, 0x0c, 0x49, 0x44, 0x41, 0x54, 0x78, 0x9c, 0x63, 0x38, 0x91, 0x62, 0x04,
    0x00, 0x03, 0x56, 0x01, 0x5f, 0xe8, 0x17, 0x84, 0x52, 0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e,
    0x44, 0xae, 0x42, 0x60, 0x82,
];

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
