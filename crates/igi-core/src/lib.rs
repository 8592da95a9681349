//! igi-core: everything of Instant Global Illumination that needs no GPU.
//!
//! Scenes and their loaders (the TOML contract of `docs/SCENE_FORMAT.md`, OBJ/MTL),
//! the BVH built on the CPU with its GPU layout and a CPU traversal (the twin of
//! `traverse.wgsl`), the Halton sequence, the render settings shared by every command,
//! and CPU references of each pass's math used by the tests (paper section 4).

pub mod bvh;
pub mod fingerprint;
pub mod image;
pub mod metrics;
pub mod rays;
pub mod sampling;
pub mod scene;
pub mod settings;
pub mod texture;
pub mod trace_scale;
pub mod vpl;

pub use glam::{Vec3, Vec4};
