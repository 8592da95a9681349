//! Inputs found by (or kept from) fuzzing the scene loaders with cargo-fuzz (`fuzz/`, see
//! `docs/FUZZING.md`), run the way each fuzz target runs them, so that they keep being
//! exercised without cargo-fuzz.
//!
//! Inputs live in `tests/fuzz_inputs/<target>/`; the file name says what loading must give:
//! `ok-*` must load, `err-*` must fail with a one-line [`SceneError`]. Either way nothing
//! may panic, not even a panic that the loaders catch (`catch_unwind` is their last
//! resort): a panic hook records every panic on the test's thread.
//!
//! The harnesses mirror `fuzz/fuzz_targets/*.rs` (same file names, same fixed TOML and
//! helper files); keep them in sync.

use std::cell::Cell;
use std::path::{Path, PathBuf};
use std::sync::Once;

use igi_core::scene::gltf::load_gltf_bytes;
use igi_core::scene::loader::{load_scene_str, SceneError};

thread_local! {
    static PANICKED: Cell<usize> = const { Cell::new(0) };
}

/// Counts panics per thread (caught ones included), then reports them as usual.
fn count_panics() {
    static HOOK: Once = Once::new();
    HOOK.call_once(|| {
        let default = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            PANICKED.with(|p| p.set(p.get() + 1));
            default(info);
        }));
    });
    PANICKED.with(|p| p.set(0));
}

fn panics() -> usize {
    PANICKED.with(|p| p.get())
}

/// A fresh directory under the system's temp dir, removed when dropped.
struct TestDir(PathBuf);

impl TestDir {
    fn new(tag: &str) -> Self {
        let dir =
            std::env::temp_dir().join(format!("igi-fuzz-regressions-{}-{tag}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("create test dir");
        TestDir(dir)
    }

    fn write(&self, name: &str, contents: impl AsRef<[u8]>) {
        std::fs::write(self.0.join(name), contents).expect("write test file");
    }
}

impl Drop for TestDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// The inputs of one target: (file name, bytes), sorted by name.
fn inputs(target: &str) -> Vec<(String, Vec<u8>)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fuzz_inputs")
        .join(target);
    let mut out: Vec<(String, Vec<u8>)> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("cannot list {}: {e}", dir.display()))
        .map(|e| {
            let e = e.expect("directory entry");
            let name = e.file_name().to_string_lossy().into_owned();
            (name, std::fs::read(e.path()).expect("read input"))
        })
        .collect();
    out.sort();
    assert!(!out.is_empty(), "no inputs in {}", dir.display());
    out
}

/// Checks one result against the input's name (`ok-*` or `err-*`); returns a problem.
fn check<T>(name: &str, r: Result<T, SceneError>, panics: usize) -> Option<String> {
    if panics > 0 {
        return Some(format!("{name}: {panics} panic(s) while loading"));
    }
    match (name.starts_with("ok-"), r) {
        (true, Ok(_)) => None,
        (true, Err(e)) => Some(format!("{name}: expected to load, got: {e}")),
        (false, Ok(_)) => Some(format!("{name}: expected an error, it loaded")),
        (false, Err(e)) => {
            let msg = e.to_string();
            (msg.contains('\n') || msg.is_empty())
                .then(|| format!("{name}: the message is not one line: {msg:?}"))
        }
    }
}

fn run_all<T>(target: &str, mut load: impl FnMut(&[u8]) -> Result<T, SceneError>) {
    count_panics();
    let mut problems = Vec::new();
    for (name, bytes) in inputs(target) {
        assert!(
            name.starts_with("ok-") || name.starts_with("err-"),
            "{target}/{name}: name it ok-* or err-*"
        );
        let r = load(&bytes);
        let n = panics();
        PANICKED.with(|p| p.set(0));
        problems.extend(check(&name, r, n));
    }
    assert!(problems.is_empty(), "{target}:\n{}", problems.join("\n"));
}

// Fixed files of the fuzz targets (fuzz/fuzz_targets/scene_toml.rs).
const TRI_OBJ: &str = "mtllib tri.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nusemtl red\nf 1//1 2//1 3//1\nusemtl white\nf 1 3 2\n";
const TRI_MTL: &str =
    "newmtl red\nKd 0.6 0.1 0.1\nnewmtl white\nKd 0.7 0.7 0.7\nKs 0.2 0.2 0.2\nillum 3\n";
const TRI_GLTF: &str = r#"{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],"meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1,"material":0}]}],"materials":[{"name":"g","pbrMetallicRoughness":{"baseColorFactor":[0.5,0.5,0.5,1]}}],"buffers":[{"byteLength":42,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIA"}],"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":6}],"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}]}"#;

/// Target `scene_toml`: the bytes as the scene TOML, next to tri.obj/.mtl/.gltf.
#[test]
fn scene_toml_inputs() {
    let dir = TestDir::new("scene-toml");
    dir.write("tri.obj", TRI_OBJ);
    dir.write("tri.mtl", TRI_MTL);
    dir.write("tri.gltf", TRI_GLTF);
    run_all("scene_toml", |bytes| {
        // The fuzz target skips non-UTF-8 input; load_scene rejects it the same way.
        let text = String::from_utf8_lossy(bytes);
        load_scene_str(&text, &dir.0, "fuzz.toml").map(|_| ())
    });
}

/// Fixed scene of the fuzz target `obj_mtl` (fuzz/fuzz_targets/obj_mtl.rs).
const OBJ_MTL_TOML: &str = "[camera]\neye = [0.0, 0.0, 5.0]\ntarget = [0.0, 0.0, 0.0]\nfov_y_deg = 40.0\n\n[[mesh]]\npath = \"m.obj\"\ndefault_material = \"d\"\n\n[[point_light]]\nposition = [0.0, 0.0, 3.0]\nintensity = [1.0, 1.0, 1.0]\n\n[materials.d]\ndiffuse = [0.5, 0.5, 0.5]\n\n[materials.t]\nmirror = [0.3, 0.3, 0.3]\n";

/// Target `obj_mtl`: the bytes up to the first NUL as m.obj, the rest (if any) as m.mtl.
#[test]
fn obj_mtl_inputs() {
    let dir = TestDir::new("obj-mtl");
    run_all("obj_mtl", |bytes| {
        let (obj, mtl) = match bytes.iter().position(|&b| b == 0) {
            Some(i) => (&bytes[..i], Some(&bytes[i + 1..])),
            None => (bytes, None),
        };
        dir.write("m.obj", obj);
        match mtl {
            Some(mtl) => dir.write("m.mtl", mtl),
            None => {
                let _ = std::fs::remove_file(dir.0.join("m.mtl"));
            }
        }
        load_scene_str(OBJ_MTL_TOML, &dir.0, "fuzz.toml").map(|_| ())
    });
}

/// Target `gltf`: the bytes as `fuzz.glb` and as `fuzz.gltf` (beside b.bin and t.png).
#[test]
fn gltf_inputs() {
    let dir = TestDir::new("gltf");
    let mut bin = Vec::new();
    for v in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        bin.extend_from_slice(&v.to_le_bytes());
    }
    for i in [0u16, 1, 2] {
        bin.extend_from_slice(&i.to_le_bytes());
    }
    dir.write("b.bin", bin);
    dir.write("t.png", PNG);
    let (glb, gltf) = (dir.0.join("fuzz.glb"), dir.0.join("fuzz.gltf"));
    run_all("gltf", |bytes| load_gltf_bytes(bytes, &glb).map(|_| ()));
    run_all("gltf", |bytes| load_gltf_bytes(bytes, &gltf).map(|_| ()));
}
include!("common/tiny_png.rs");

/// Target `exr` (and `compare`, which reads the same way): the bytes to the OpenEXR
/// reader. Its decoder's own panics on damaged data are caught there (see
/// `Image::read_exr_bytes`), so they are not counted: the file must end in one error.
#[test]
fn exr_inputs() {
    let mut problems = Vec::new();
    for (name, bytes) in inputs("exr") {
        let r = igi_core::image::Image::read_exr_bytes(&bytes, Path::new("fuzz.exr"));
        match (name.starts_with("ok-"), r) {
            (true, Ok(_)) | (false, Err(_)) => {}
            (true, Err(e)) => problems.push(format!("{name}: expected to load, got: {e}")),
            (false, Ok(_)) => problems.push(format!("{name}: expected an error, it loaded")),
        }
    }
    assert!(problems.is_empty(), "exr:\n{}", problems.join("\n"));
}
