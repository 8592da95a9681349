//! What a rasterised visibility buffer of a scene would cost on this GPU: the scene's
//! triangles drawn once from its camera into a triangle-index target with a depth
//! buffer, timed with GPU timestamps, and compared pixel by pixel with the closest hits
//! of igi's own traversal of the same camera rays (pixel centres). A measuring tool: the
//! direct pass's primary closest hits are a small part of the frame, and NVIDIA's Hopper
//! GPUs keep graphics units in only two of their TPCs, so whether rasterising is cheaper
//! had to be measured (the lab log has the answer).
//!
//! `cargo run --release -p igi-gpu --example raster_probe -- SCENE.toml [WIDTH HEIGHT]
//! [FRAMES]` (default: the scene's film, 200 frames); prints the median GPU time of the
//! draw, and how many pixels name the triangle the CPU twin's closest hit names.

use glam::Mat4;
use igi_core::bvh::Bvh;
use igi_core::scene::Camera;
use igi_gpu::context::{AdapterChoice, GpuContext};
use wgpu::util::DeviceExt;

const SHADER: &str = r#"
struct Camera { view_proj: mat4x4<f32> }
@group(0) @binding(0) var<uniform> camera: Camera;

struct Out {
    @builtin(position) clip: vec4<f32>,
    @location(0) @interpolate(flat) tri: u32,
}

@vertex
fn vs(@location(0) p: vec3<f32>, @builtin(vertex_index) v: u32) -> Out {
    return Out(camera.view_proj * vec4<f32>(p, 1.0), v / 3u + 1u);
}

@fragment
fn fs(i: Out) -> @location(0) u32 {
    return i.tri;
}
"#;

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = args
        .first()
        .ok_or("usage: raster_probe SCENE.toml [WIDTH HEIGHT] [FRAMES]")?;
    let scene =
        igi_core::scene::load_scene(std::path::Path::new(path)).map_err(|e| e.to_string())?;
    let num = |i: usize, d: u32| args.get(i).and_then(|s| s.parse().ok()).unwrap_or(d);
    let (width, height) = (num(1, scene.film.width), num(2, scene.film.height));
    let frames = num(3, 200).max(1);
    let ctx = GpuContext::new(&AdapterChoice::Best).map_err(|e| e.to_string())?;
    if !ctx.timestamps {
        return Err(format!("{} has no timestamp queries", ctx.info.name));
    }
    let device = &ctx.device;

    // The camera of igi's primary rays (direct.wgsl camera_ray_dir, pixel centres).
    let cam = scene.camera;
    let aspect = width as f32 / height as f32;
    let (lo, hi) = scene.bounds();
    let far = (hi - lo).length() * 2.0;
    let view_proj = projection(cam.fov_y_deg.to_radians(), aspect, far * 1e-5, far) * look_at(&cam);
    let positions: Vec<[f32; 3]> = scene
        .triangles
        .iter()
        .flat_map(|t| t.v.map(|v| v.to_array()))
        .collect();
    let vertices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("vertices"),
        contents: bytemuck::cast_slice(&positions),
        usage: wgpu::BufferUsages::VERTEX,
    });
    let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("camera"),
        contents: bytemuck::cast_slice(&view_proj.to_cols_array()),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("raster probe"),
        source: wgpu::ShaderSource::Wgsl(SHADER.into()),
    });
    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("visibility"),
        layout: None,
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs"),
            compilation_options: Default::default(),
            buffers: &[Some(wgpu::VertexBufferLayout {
                array_stride: 12,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &wgpu::vertex_attr_array![0 => Float32x3],
            })],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: wgpu::TextureFormat::Depth32Float,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Less),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs"),
            compilation_options: Default::default(),
            targets: &[Some(wgpu::TextureFormat::R32Uint.into())],
        }),
        multiview_mask: None,
        cache: None,
    });
    let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("camera"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: uniform.as_entire_binding(),
        }],
    });
    let size = wgpu::Extent3d {
        width,
        height,
        depth_or_array_layers: 1,
    };
    let target = |format, usage| {
        device.create_texture(&wgpu::TextureDescriptor {
            label: None,
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        })
    };
    let ids = target(
        wgpu::TextureFormat::R32Uint,
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
    );
    let depth = target(
        wgpu::TextureFormat::Depth32Float,
        wgpu::TextureUsages::RENDER_ATTACHMENT,
    );
    let (ids_view, depth_view) = (
        ids.create_view(&Default::default()),
        depth.create_view(&Default::default()),
    );
    let queries = device.create_query_set(&wgpu::QuerySetDescriptor {
        label: None,
        ty: wgpu::QueryType::Timestamp,
        count: 2,
    });
    let resolve = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: 16,
        usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let row = (width * 4).next_multiple_of(256);
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: (row * height) as u64,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });

    let mut times = vec![];
    // Warm-up frames first (clocks), then the timed ones.
    for frame in 0..frames + 20 {
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("visibility"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &ids_view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &depth_view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: Some(wgpu::RenderPassTimestampWrites {
                    query_set: &queries,
                    beginning_of_pass_write_index: Some(0),
                    end_of_pass_write_index: Some(1),
                }),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(0, &bind, &[]);
            pass.set_vertex_buffer(0, vertices.slice(..));
            pass.draw(0..positions.len() as u32, 0..1);
        }
        encoder.resolve_query_set(&queries, 0..2, &resolve, 0);
        ctx.queue.submit([encoder.finish()]);
        let ticks: Vec<u64> = ctx.read_buffer(&resolve).map_err(|e| e.to_string())?;
        if frame >= 20 {
            let period = ctx.queue.get_timestamp_period() as f64;
            times.push(ticks[1].saturating_sub(ticks[0]) as f64 * period * 1e-6);
        }
    }
    times.sort_by(f64::total_cmp);
    println!(
        "{}: {} triangles drawn at {width} x {height}: median {:.4} ms of {frames} (min {:.4}, max {:.4})",
        ctx.info.name,
        scene.triangles.len(),
        times[frames as usize / 2],
        times[0],
        times[frames as usize - 1]
    );

    // The triangle of each pixel against the CPU twin's closest hit at the pixel centre.
    let mut encoder = device.create_command_encoder(&Default::default());
    encoder.copy_texture_to_buffer(
        ids.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &readback,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row),
                rows_per_image: None,
            },
        },
        size,
    );
    ctx.queue.submit([encoder.finish()]);
    let words: Vec<u32> = ctx.read_buffer(&readback).map_err(|e| e.to_string())?;
    let bvh = Bvh::build(&scene.triangles);
    let (mut same, mut both_miss, mut differ) = (0u64, 0u64, 0u64);
    for y in 0..height {
        for x in 0..width {
            let d = cam.pixel_dir(width, height, x, y);
            let traced = bvh
                .trace_closest(cam.eye, d, f32::INFINITY)
                .map(|h| bvh.tri_order[h.tri as usize] + 1)
                .unwrap_or(0);
            let drawn = words[(y * row / 4 + x) as usize];
            match (traced == drawn, traced == 0) {
                (true, true) => both_miss += 1,
                (true, false) => same += 1,
                _ => differ += 1,
            }
        }
    }
    println!(
        "pixels naming the traced triangle: {same}, both empty: {both_miss}, different: {differ} ({:.3}%)",
        100.0 * differ as f64 / (width * height) as f64
    );
    Ok(())
}

/// World to camera space, looking down -z, in the frame of igi's primary rays.
fn look_at(cam: &Camera) -> Mat4 {
    let (f, s, u) = cam.basis();
    let eye = cam.eye;
    Mat4::from_cols_array_2d(&[
        [s.x, s.y, s.z, -s.dot(eye)],
        [u.x, u.y, u.z, -u.dot(eye)],
        [-f.x, -f.y, -f.z, f.dot(eye)],
        [0.0, 0.0, 0.0, 1.0],
    ])
    .transpose()
}

/// Perspective projection to wgpu's clip space (depth 0 at `near`, 1 at `far`).
fn projection(fov_y: f32, aspect: f32, near: f32, far: f32) -> Mat4 {
    let focal = 1.0 / (0.5 * fov_y).tan();
    Mat4::from_cols_array_2d(&[
        [focal / aspect, 0.0, 0.0, 0.0],
        [0.0, focal, 0.0, 0.0],
        [0.0, 0.0, far / (near - far), near * far / (near - far)],
        [0.0, 0.0, -1.0, 0.0],
    ])
    .transpose()
}
