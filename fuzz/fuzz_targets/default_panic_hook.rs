// Included by the OpenEXR targets (exr.rs, compare.rs).

/// libfuzzer-sys's panic hook aborts on every panic, also one the reader catches (it
/// catches the decoder's, see `read_exr_bytes`); the default hook lets those be, and a
/// panic that escapes the reader still ends the run as a crash.
fn default_panic_hook() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let _ = std::panic::take_hook();
    });
}
