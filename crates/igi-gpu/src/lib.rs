//! igi-gpu: Instant Global Illumination on the GPU through wgpu compute shaders.
//!
//! The frame of the paper (section 4) as passes, in the order `frame/listing.rs` lists
//! them: VPL shooting, direct + specular, indirect diffuse, the accelerations' filters,
//! compose. Each pass is a folder under `passes/`: a small struct owning its pipelines,
//! its typed bindings and its WGSL, and a CPU twin where it computes pixels. The
//! ray-tracing layer (BVH traversal in WGSL, `shaders/`) is shared by all;
//! docs/ARCHITECTURE.md says how the parts fit.

pub mod context;
pub mod frame;
pub mod layout;
pub mod passes;
pub mod profiler;
pub mod raybench;
pub mod scene_buffers;
pub mod shader;
pub mod shaders;
pub mod switches;

pub use context::{AdapterChoice, GpuContext, GpuError};
pub use frame::{FrameOutput, Passes, Renderer};
