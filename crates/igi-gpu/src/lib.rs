//! igi-gpu: Instant Global Illumination on the GPU through wgpu compute shaders.
//!
//! The frame of the paper (section 4) as passes, in the order [`frame::Renderer::encode_frame`]
//! lists them: VPL shooting, direct + specular, indirect diffuse, compose. Each pass is a
//! small struct owning its pipeline, with its WGSL beside it in `shaders/` and a CPU twin of
//! its math in `igi-core`. The ray-tracing layer (BVH traversal in WGSL) is shared by all.

pub mod context;
pub mod frame;
pub mod layout;
pub mod passes;
pub mod profiler;
pub mod raybench;
pub mod scene_buffers;
pub mod shader;

pub use context::{AdapterChoice, GpuContext, GpuError};
pub use frame::{FrameOutput, Passes, Renderer};
