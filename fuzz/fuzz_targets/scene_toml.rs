//! Arbitrary bytes as the scene TOML (`load_scene_str`), in a directory that holds a small
//! valid OBJ + MTL (`tri.obj`, `tri.mtl`) and glTF (`tri.gltf`), so that valid TOML reaches
//! the mesh and material code. Non-UTF-8 input is skipped (`load_scene` rejects it before
//! the TOML is parsed).
#![no_main]

use std::path::PathBuf;
use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;

const OBJ: &str = "mtllib tri.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nusemtl red\nf 1//1 2//1 3//1\nusemtl white\nf 1 3 2\n";
const MTL: &str =
    "newmtl red\nKd 0.6 0.1 0.1\nnewmtl white\nKd 0.7 0.7 0.7\nKs 0.2 0.2 0.2\nillum 3\n";
/// One triangle (3 f32 positions, then u16 indices 0 1 2) in a base64 `data:` URI.
const GLTF: &str = r#"{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],"meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1,"material":0}]}],"materials":[{"name":"g","pbrMetallicRoughness":{"baseColorFactor":[0.5,0.5,0.5,1]}}],"buffers":[{"byteLength":42,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIA"}],"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":6}],"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}]}"#;

fn base_dir() -> &'static PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("igi-fuzz-scene-toml-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("create the fuzz base dir");
        std::fs::write(dir.join("tri.obj"), OBJ).expect("write tri.obj");
        std::fs::write(dir.join("tri.mtl"), MTL).expect("write tri.mtl");
        std::fs::write(dir.join("tri.gltf"), GLTF).expect("write tri.gltf");
        dir
    })
}

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let _ = igi_core::scene::loader::load_scene_str(text, base_dir(), "fuzz.toml");
});
