//! Shader assembly: every pass's WGSL is the shared modules (scene bindings, traversal,
//! frame types and sampling, VPL gathering, upsampling) followed by the pass's own file. Composition is
//! plain concatenation in a fixed order, done once at pipeline creation; a naga test
//! parses and validates every composed shader, so a broken shader fails a test, not a user.

use crate::passes::PassSource;

/// Shared WGSL modules, in the order they are prepended.
pub const SCENE: &str = include_str!("shaders/scene.wgsl");
pub const TRAVERSE: &str = include_str!("shaders/traverse.wgsl");
pub const FRAME: &str = include_str!("shaders/frame.wgsl");
pub const GATHER: &str = include_str!("shaders/gather.wgsl");
pub const UPSAMPLE: &str = include_str!("shaders/upsample.wgsl");

/// A pass's full shader: the shared modules, then the pass.
pub fn compose(pass: &PassSource) -> String {
    let gather = if pass.gathers { GATHER } else { "" };
    let upsample = if pass.upsamples { UPSAMPLE } else { "" };
    [SCENE, TRAVERSE, FRAME, gather, upsample, pass.wgsl].join("\n")
}

/// Every composed shader igi builds, by name, for validation tests.
pub fn all_shaders() -> Vec<(&'static str, String)> {
    crate::passes::SOURCES
        .iter()
        .map(|pass| (pass.name, compose(pass)))
        .collect()
}
