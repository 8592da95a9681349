//! Which dispatches of one compute pass the GPU runs side by side: spinning kernels (one
//! dependent chain of multiply-adds per thread, 132 workgroups of 64 threads, so that two
//! fit on the GPU at once) recorded in patterns of the buffers they write. A dispatch
//! that binds a buffer an earlier dispatch of the pass wrote gets a barrier from wgpu;
//! the others get none. Prints the median GPU time of each pattern against one dispatch
//! alone. A measuring tool for how the recorder groups passes (`frame/recorder.rs`).
//!
//! `cargo run --release -p igi-gpu --example overlap_probe -- [ITERATIONS] [RUNS]`

use igi_gpu::context::{AdapterChoice, GpuContext};
use igi_gpu::profiler::Profiler;
use wgpu::util::DeviceExt;

const SHADER: &str = r#"
@group(0) @binding(0) var<uniform> iterations: vec4<u32>;
@group(0) @binding(1) var<storage, read_write> out: array<f32>;

@compute @workgroup_size(64)
fn spin(@builtin(global_invocation_id) gid: vec3<u32>) {
    var x = f32(gid.x) * 1e-3;
    for (var i = 0u; i < iterations.x; i += 1u) {
        x = fma(x, 0.9999, 0.5);
    }
    out[gid.x] = x;
}
"#;

/// Patterns: the buffer each dispatch writes, in order.
const PATTERNS: &[(&str, &[usize])] = &[
    ("a", &[0]),
    ("a b", &[0, 1]),
    ("a a", &[0, 0]),
    ("a a b", &[0, 0, 1]),
    ("a b a", &[0, 1, 0]),
    ("a a b c", &[0, 0, 1, 2]),
    ("a b c d", &[0, 1, 2, 3]),
];

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), String> {
    let args: Vec<u32> = std::env::args()
        .skip(1)
        .map(|a| a.parse().map_err(|_| format!("not a number: {a}")))
        .collect::<Result<_, _>>()?;
    let iterations = args.first().copied().unwrap_or(200_000);
    let runs = args.get(1).copied().unwrap_or(20).max(1);
    let ctx = GpuContext::new(&AdapterChoice::Best).map_err(|e| e.to_string())?;
    if !ctx.timestamps {
        return Err(format!("{} has no timestamp queries", ctx.info.name));
    }
    println!("{}", ctx.describe());
    let device = &ctx.device;
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("spin"),
        source: wgpu::ShaderSource::Wgsl(SHADER.into()),
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("spin"),
        layout: None,
        module: &module,
        entry_point: Some("spin"),
        compilation_options: Default::default(),
        cache: None,
    });
    let groups = 132u32;
    let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("iterations"),
        contents: bytemuck::cast_slice(&[iterations, 0, 0, 0]),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let binds: Vec<wgpu::BindGroup> = (0..4)
        .map(|_| {
            let out = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("out"),
                size: groups as u64 * 64 * 4,
                usage: wgpu::BufferUsages::STORAGE,
                mapped_at_creation: false,
            });
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("spin"),
                layout: &pipeline.get_bind_group_layout(0),
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: uniform.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: out.as_entire_binding(),
                    },
                ],
            })
        })
        .collect();
    let profiler = Profiler::new(&ctx, 1);
    let mut alone = None;
    for &(name, pattern) in PATTERNS {
        let mut times = vec![];
        for _ in 0..runs + 2 {
            let mut encoder = device.create_command_encoder(&Default::default());
            {
                let mut cpass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some(name),
                    timestamp_writes: profiler.pass_writes(0),
                });
                cpass.set_pipeline(&pipeline);
                for &b in pattern {
                    cpass.set_bind_group(0, &binds[b], &[]);
                    cpass.dispatch_workgroups(groups, 1, 1);
                }
            }
            profiler.resolve(&mut encoder, 1);
            ctx.queue.submit([encoder.finish()]);
            let (_, ms) = profiler
                .read(&ctx, &[name])
                .map_err(|e| e.to_string())?
                .ok_or("no timestamps")?;
            times.push(ms);
        }
        times.drain(..2);
        times.sort_by(f64::total_cmp);
        let median = times[times.len() / 2];
        let one = *alone.get_or_insert(median);
        println!(
            "{name:10} {} dispatches: {median:.4} ms = {:.2} x one alone",
            pattern.len(),
            median / one
        );
    }
    Ok(())
}
