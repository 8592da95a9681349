//! CPU twins of the shared WGSL modules in this folder that compute pixel values, one file
//! each beside its WGSL (`X.wgsl` and `X.rs`). The passes' own twins are `cpu.rs` in
//! their folders: `passes::filter::cpu`, `passes::compose::cpu`, `passes::indirect::cpu`
//! (the gather); the VPL pass's is `igi_core::vpl`, the traversal's `igi_core::bvh`.
//! Each mirrors its WGSL function by function, with the WGSL's names, so that a test
//! (`tests/twins.rs`) runs the twin on the GPU's own inputs, read back with
//! `Renderer::read_frame_buffer`, and compares. Plain slices in, plain vectors out: no
//! wgpu here.

pub mod gbuffer;
pub mod upsample;
