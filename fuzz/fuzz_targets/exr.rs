//! Arbitrary bytes to the OpenEXR reader (`Image::read_exr_bytes`), as `igi compare`,
//! `igi bench` and the tests read references: every input ends in an image or one
//! `ImageError`, never a panic or an allocation its header alone asks for.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

/// libfuzzer-sys's panic hook aborts on every panic, also one the reader catches (it
/// catches the decoder's, see `read_exr_bytes`); the default hook lets those be, and a
/// panic that escapes the reader still ends the run as a crash.
fn default_panic_hook() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let _ = std::panic::take_hook();
    });
}

fuzz_target!(|data: &[u8]| {
    default_panic_hook();
    if let Ok(image) = igi_core::image::Image::read_exr_bytes(data, Path::new("fuzz.exr")) {
        // What the readers of an image do next.
        assert_eq!(image.data.len(), image.width as usize * image.height as usize);
        let _ = image.mean();
    }
});
