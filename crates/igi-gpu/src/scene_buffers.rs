//! The scene on the GPU: BVH nodes, triangle rows and shading data in BVH order,
//! materials and lights, as bind group 0 of every pass (`shaders/scene.wgsl`).

use crate::context::{GpuContext, GpuError};
use crate::layout::{texture_words, GpuLight, GpuMaterial, GpuTriAttributes, TriShading};
use igi_core::bvh::{Bvh, TriRow};
use igi_core::scene::Scene;
use igi_core::trace_scale::TraceScale;

pub struct SceneBuffers {
    pub layout: wgpu::BindGroupLayout,
    pub bind_group: wgpu::BindGroup,
    /// The same scene with spare ray counters, one set per pass that runs beside another
    /// one in a frame that counts nothing, each used once a frame (the recorder hands
    /// them out in order): wgpu puts a barrier before a dispatch that binds read-write a
    /// buffer an earlier dispatch of the frame bound read-write, even when neither writes
    /// it (`frame::recorder`).
    pub beside_bind_groups: [wgpu::BindGroup; SPARE_COUNTERS],
    pub light_count: u32,
    /// The point lights (binding 4), rewritten when the viewer moves a light.
    pub lights: wgpu::Buffer,
    /// The ray counters of scene.wgsl (8 x u32).
    pub ray_counters: wgpu::Buffer,
    /// The spare ray counters of [`SceneBuffers::beside_bind_groups`], in their order.
    pub spare_ray_counters: Vec<wgpu::Buffer>,
    /// Bytes held on the GPU by the scene.
    pub bytes: u64,
}

/// Sets of spare ray counters (see [`SceneBuffers::beside_bind_groups`]): as many as a
/// frame has passes beside another (the direct pass, the two gathers beside the chain
/// walks, the mirror discontinuity buffer).
pub const SPARE_COUNTERS: usize = 4;

crate::bindings! {
    /// Bind group 0 of every pass (scene.wgsl).
    pub struct SceneBindings {
        bvh_nodes: Read,
        tri_rows: Read,
        tri_shading: Read,
        materials: Read,
        lights: Read,
        /// Rays traced per kind, counted only in frames that count them.
        ray_counters: Write,
        textures: Read,
        tri_attributes: Read,
    }
}

/// A storage buffer with `data` (at least 16 bytes: empty arrays still need a binding),
/// after checking it fits one binding on this device.
pub fn storage_buffer(
    ctx: &GpuContext,
    label: &str,
    data: &[u8],
) -> Result<wgpu::Buffer, GpuError> {
    let limit = ctx.max_storage_binding();
    if data.len() as u64 > limit {
        return Err(GpuError::Limit(format!(
            "the scene's {label} buffer needs {} MiB, more than this adapter's max_storage_buffer_binding_size of {} MiB",
            data.len() >> 20,
            limit >> 20
        )));
    }
    // Mapped at creation (zeroed) and filled in place: a multiple of 4 bytes, at least 16.
    let size = (data.len() as u64)
        .next_multiple_of(wgpu::COPY_BUFFER_ALIGNMENT)
        .max(16);
    let buffer = ctx.allocate(
        || format!("the {label} buffer"),
        size,
        "a smaller scene or ray set needs less",
        || {
            ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_DST
                    | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: true,
            })
        },
    )?;
    {
        let mut mapped = buffer
            .get_mapped_range_mut(..)
            .map_err(|e| GpuError::Device(e.to_string()))?;
        mapped.slice(..data.len()).copy_from_slice(data);
    }
    buffer.unmap();
    Ok(buffer)
}

/// The point lights as the GPU reads them, in trace coordinates (`scale`).
pub fn gpu_lights(lights: &[igi_core::scene::PointLight], scale: TraceScale) -> Vec<GpuLight> {
    lights
        .iter()
        .map(|l| GpuLight {
            position: scale.point(l.position).to_array(),
            _pad0: 0.0,
            intensity: scale.intensity(l.intensity).to_array(),
            _pad1: 0.0,
        })
        .collect()
}

impl SceneBuffers {
    pub fn layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
        crate::passes::bindings::compute_layout::<SceneBindings>(device, "scene")
    }

    /// The scene in its own coordinates (the ray bench's: its rays are in them).
    pub fn upload(ctx: &GpuContext, scene: &Scene, bvh: &Bvh) -> Result<SceneBuffers, GpuError> {
        Self::upload_with(ctx, Self::layout(&ctx.device), scene, bvh, TraceScale::ONE)
    }

    /// As [`SceneBuffers::upload`], bound with `layout` (made by [`SceneBuffers::layout`]:
    /// the one the passes' pipelines were made with), the lights scaled by `scale` (`bvh`
    /// is scaled already: [`Bvh::scaled`]).
    pub fn upload_with(
        ctx: &GpuContext,
        layout: wgpu::BindGroupLayout,
        scene: &Scene,
        bvh: &Bvh,
        scale: TraceScale,
    ) -> Result<SceneBuffers, GpuError> {
        let shading: Vec<TriShading> = bvh
            .tri_order
            .iter()
            .map(|&i| {
                let t = &scene.triangles[i as usize];
                TriShading {
                    n0: t.n[0].to_array(),
                    material: t.material,
                    n1: t.n[1].to_array(),
                    _pad1: 0,
                    n2: t.n[2].to_array(),
                    _pad2: 0,
                }
            })
            .collect();
        let materials: Vec<GpuMaterial> = scene.materials.iter().map(GpuMaterial::of).collect();
        let lights = gpu_lights(&scene.lights, scale);
        let tri_rows = marked_rows(scene, bvh);
        let attributes = gpu_attributes(scene, bvh)?;
        let buffers = [
            storage_buffer(ctx, "BVH nodes", bytemuck::cast_slice(&bvh.nodes))?,
            storage_buffer(
                ctx,
                "triangle rows",
                bytemuck::cast_slice(tri_rows.as_deref().unwrap_or(&bvh.tri_rows)),
            )?,
            storage_buffer(ctx, "triangle shading", bytemuck::cast_slice(&shading))?,
            storage_buffer(ctx, "materials", bytemuck::cast_slice(&materials))?,
            storage_buffer(ctx, "lights", bytemuck::cast_slice(&lights))?,
            storage_buffer(
                ctx,
                "textures",
                bytemuck::cast_slice(&texture_words(&scene.textures)),
            )?,
            storage_buffer(
                ctx,
                "triangle attributes",
                bytemuck::cast_slice(&attributes),
            )?,
        ];
        let bytes = buffers.iter().map(|b| b.size()).sum();
        let ray_counters = storage_buffer(ctx, "ray counters", &[0u8; 32])?;
        let mut spare_counters = Vec::new();
        for _ in 0..SPARE_COUNTERS {
            spare_counters.push(storage_buffer(ctx, "spare ray counters", &[0u8; 32])?);
        }
        let group = |label: &str, ray_counters: &wgpu::Buffer| {
            let [bvh_nodes, tri_rows, tri_shading, materials, lights, textures, tri_attributes] =
                &buffers;
            let bindings = SceneBindings {
                bvh_nodes,
                tri_rows,
                tri_shading,
                materials,
                lights,
                ray_counters,
                textures,
                tri_attributes,
            };
            crate::passes::bindings::bind(&ctx.device, label, &layout, &bindings).group
        };
        let bind_group = group("scene", &ray_counters);
        let beside_bind_groups =
            std::array::from_fn(|i| group("scene (spare ray counters)", &spare_counters[i]));
        let [_, _, _, _, lights_buffer, _, _] = buffers;
        Ok(SceneBuffers {
            layout,
            bind_group,
            beside_bind_groups,
            light_count: lights.len() as u32,
            lights: lights_buffer,
            ray_counters,
            spare_ray_counters: spare_counters,
            bytes,
        })
    }
}

/// The triangle rows with w = 1 in the three rows of every slot whose material is
/// alpha-tested (traverse.wgsl tests those slots' masks), or `None` where no material is
/// (the BVH's rows, w = 0, are used as they are).
fn marked_rows(scene: &Scene, bvh: &Bvh) -> Option<Vec<TriRow>> {
    let tested: Vec<bool> = scene.materials.iter().map(|m| m.alpha_tested()).collect();
    if !tested.contains(&true) {
        return None;
    }
    let mut rows = bvh.tri_rows.clone();
    for (slot, &t) in bvh.tri_order.iter().enumerate() {
        let material = scene.triangles[t as usize].material as usize;
        if tested.get(material).copied().unwrap_or(false) {
            for row in &mut rows[3 * slot..3 * slot + 3] {
                row.0[3] = 1.0;
            }
        }
    }
    Some(rows)
}

/// The triangles' texture coordinates and colours in BVH order, or one unused row where
/// the scene has none.
fn gpu_attributes(scene: &Scene, bvh: &Bvh) -> Result<Vec<GpuTriAttributes>, GpuError> {
    if scene.attributes.is_empty() {
        if scene.materials.iter().any(|m| m.uses_attributes()) {
            return Err(GpuError::Device(format!(
                "{}: a material has a texture or vertex colours but the scene has no texture coordinates or colours",
                scene.source
            )));
        }
        return Ok(vec![GpuTriAttributes::of(
            &igi_core::scene::TriAttributes::NONE,
        )]);
    }
    if scene.attributes.len() != scene.triangles.len() {
        return Err(GpuError::Device(format!(
            "{}: {} triangle attribute rows for {} triangles",
            scene.source,
            scene.attributes.len(),
            scene.triangles.len()
        )));
    }
    Ok(bvh
        .tri_order
        .iter()
        .map(|&t| GpuTriAttributes::of(&scene.attributes[t as usize]))
        .collect())
}
