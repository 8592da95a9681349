//! `igi compare`'s inputs: two OpenEXR files from one input (the first 4 bytes, little
//! endian, say where the first file ends), read and compared as the command does
//! (`Comparison::of`: relMSE, means, pixel differences). Images of other sizes are an
//! error; NaN and infinite pixels must not panic.
#![no_main]

use igi_core::image::{Comparison, Image};
use libfuzzer_sys::fuzz_target;
use std::path::Path;

include!("default_panic_hook.rs");

fuzz_target!(|data: &[u8]| {
    default_panic_hook();
    let Some((head, rest)) = data.split_first_chunk::<4>() else {
        return;
    };
    let split = u32::from_le_bytes(*head) as usize % (rest.len() + 1);
    let (a, b) = rest.split_at(split);
    let read = |bytes: &[u8], name: &str| Image::read_exr_bytes(bytes, Path::new(name));
    if let (Ok(a), Ok(b)) = (read(a, "image.exr"), read(b, "reference.exr")) {
        let _ = Comparison::of(&a, &b);
        let _ = Comparison::of(&a, &a);
    }
});
