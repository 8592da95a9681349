//! Walks a software adapter cut short: llvmpipe ends a shader invocation's loops after
//! 65,535 iterations in all, and traverse.wgsl's walks count where that left them
//! unfinished (`LOOP_CUTS_COUNTED`, in the software composition only) in entry
//! `CUT_WALKS` of every set of ray counters the frame binds.

use super::Renderer;
use crate::context::{GpuContext, GpuError};

/// scene.wgsl's entry of the ray counters that counts walks cut short (`CUT_WALKS`).
const CUT_WALKS: u64 = 7;

impl Renderer {
    /// Error where a software adapter cut BVH walks of the frames so far short: their
    /// images would be wrong. No work on GPUs, whose walks count nothing there. One
    /// readback: the entry of each set of counters is copied into one buffer first.
    pub fn check_walks(&mut self, ctx: &GpuContext) -> Result<(), GpuError> {
        if !self.software {
            return Ok(());
        }
        let scene = &self.scene;
        let sets: Vec<&wgpu::Buffer> = std::iter::once(&scene.ray_counters)
            .chain(&scene.spare_ray_counters)
            .collect();
        let gathered = self.cut_walks.get_or_insert_with(|| {
            ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("walks cut short"),
                size: 4 * sets.len() as u64,
                usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            })
        });
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        for (i, counters) in sets.iter().enumerate() {
            encoder.copy_buffer_to_buffer(counters, 4 * CUT_WALKS, gathered, 4 * i as u64, 4);
        }
        ctx.queue.submit([encoder.finish()]);
        let counts: Vec<u32> = ctx.read_buffer(gathered)?;
        let cut: u64 = counts.iter().map(|&c| c as u64).sum();
        if cut == 0 {
            return Ok(());
        }
        Err(GpuError::Limit(format!(
            "the software adapter ended {cut} ray traversals before they were done (llvmpipe stops a shader after 65,535 loop iterations, and this scene's BVH needs more: many overlapping triangles), so the image would be wrong; render on a GPU, or with fewer overlapping triangles"
        )))
    }
}
