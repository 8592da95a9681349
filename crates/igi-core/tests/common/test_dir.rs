// What the loader tests that write scene files share: a fresh directory removed when
// dropped, a camera and a light in TOML, and the check of a one-line error; included
// with `#[path = "common/test_dir.rs"] mod test_dir;`.
#![allow(dead_code)]

use igi_core::scene::loader::{load_scene, SceneError};
use igi_core::scene::Scene;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};

/// A fresh directory under the system's temp dir, removed when dropped.
pub struct TestDir(pub PathBuf);

impl TestDir {
    /// `igi-TEST-PID-TAG-N`: TEST is the test file's name, N counts the directories made.
    pub fn new(tag: &str) -> Self {
        static COUNTER: AtomicUsize = AtomicUsize::new(0);
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let dir = std::env::temp_dir().join(format!(
            "igi-{}-{}-{tag}-{n}",
            env!("CARGO_CRATE_NAME"),
            std::process::id()
        ));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("create test dir");
        TestDir(dir)
    }

    pub fn path(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }

    pub fn write(&self, name: &str, contents: impl AsRef<[u8]>) -> PathBuf {
        let p = self.path(name);
        std::fs::write(&p, contents).expect("write test file");
        p
    }

    /// Writes `scene.toml` and loads it.
    pub fn load(&self, toml: &str) -> Result<Scene, SceneError> {
        load_scene(&self.write("scene.toml", toml))
    }
}

impl Drop for TestDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

pub const CAMERA: &str = "[camera]
eye = [0.0, 0.0, 5.0]
target = [0.0, 0.0, 0.0]
fov_y_deg = 40.0
";

pub const LIGHT: &str = "[[point_light]]
position = [0.0, 0.0, 3.0]
intensity = [1.0, 1.0, 1.0]
";

/// The error's message; checks that it is one line and contains `file` and `needles`.
pub fn expect_err(r: Result<Scene, SceneError>, file: &str, needles: &[&str]) -> String {
    let msg = match r {
        Ok(s) => panic!(
            "expected an error, the scene loaded ({} triangles)",
            s.triangles.len()
        ),
        Err(e) => e.to_string(),
    };
    // Messages may quote long text: at most 2,000 characters of them are shown.
    let shown: String = msg.chars().take(2000).collect();
    eprintln!("message: {shown}");
    assert!(
        !msg.contains('\n') && !msg.contains('\r'),
        "message is not one line: {shown:?}"
    );
    assert!(msg.contains(file), "message does not name {file}: {shown}");
    for n in needles {
        assert!(msg.contains(n), "message lacks {n:?}: {shown}");
    }
    msg
}
