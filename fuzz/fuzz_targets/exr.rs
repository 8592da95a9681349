//! Arbitrary bytes to the OpenEXR reader (`Image::read_exr_bytes`), as `igi compare`,
//! `igi bench` and the tests read references: every input ends in an image or one
//! `ImageError`, never a panic or an allocation its header alone asks for.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

include!("default_panic_hook.rs");

fuzz_target!(|data: &[u8]| {
    default_panic_hook();
    if let Ok(image) = igi_core::image::Image::read_exr_bytes(data, Path::new("fuzz.exr")) {
        // What the readers of an image do next.
        assert_eq!(image.data.len(), image.width as usize * image.height as usize);
        let _ = image.mean();
    }
});
