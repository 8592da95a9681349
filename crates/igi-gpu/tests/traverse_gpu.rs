//! The GPU ray-tracing layer (traverse.wgsl, igi's replacement for OptiX in Marques and
//! Santos' IGI) against the CPU, ray by ray: the brute-force reference (same triangle,
//! same distance within 1e-5 relative, same occlusion answer) and the CPU BVH traversal,
//! its twin (same answers; bit-identical where the GPU rounds like the CPU). Every ray is
//! also traced as a segment (trace_segment: from the origin to origin + dir), the walk of
//! the renderer's shadow rays.
//!
//! Runs on the adapter `GpuContext` picks (lavapipe where there is no GPU:
//! `apt-get install mesa-vulkan-drivers`; set XDG_RUNTIME_DIR=/tmp to silence its
//! warning); skips with a message when there is none.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use igi_core::bvh::{
    brute_force_any, brute_force_closest, offset_ray_origin, Bvh, BvhBuilder, Hit, NO_HIT,
};
use igi_gpu::context::{AdapterChoice, GpuContext};
use igi_gpu::shader::ParamsBinding;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use wgpu::util::DeviceExt;

/// Traces each ray for closest and any hit and as a segment, and offsets its origin along
/// its normal.
const KERNEL: &str = r#"
#import traverse

struct TestRay {
    origin: vec3<f32>, tmax: f32,
    dir: vec3<f32>, _pad0: f32,
    normal: vec3<f32>, floor: f32,
}

struct TestResult {
    hit: Hit,
    any_hit: u32, segment: u32, _p1: u32, _p2: u32,
    offset: vec3<f32>, _p3: f32,
}

@group(1) @binding(0) var<storage, read> rays: array<TestRay>;
@group(1) @binding(1) var<storage, read_write> results: array<TestResult>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= arrayLength(&rays)) {
        return;
    }
    let r = rays[i];
    var res: TestResult;
    var stack: WalkStack;
    res.hit = trace_closest(&stack, r.origin, r.dir, r.tmax);
    res.any_hit = select(0u, 1u, trace_any(&stack, r.origin, r.dir, r.tmax));
    res.segment = select(0u, 1u, trace_segment(&stack, r.origin, r.dir, false));
    res.offset = offset_ray_origin(r.origin, r.normal, r.floor);
    results[i] = res;
}
"#;

/// `TestRay` of the kernel: 48 bytes.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable, Debug)]
struct TestRay {
    origin: [f32; 3],
    tmax: f32,
    dir: [f32; 3],
    _pad0: f32,
    normal: [f32; 3],
    /// The offset floor to test offset_ray_origin with.
    floor: f32,
}

/// `TestResult` of the kernel: 48 bytes (hit 0..16, any_hit 16..20, segment 20..24,
/// offset 32..44).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable, Debug)]
struct TestResult {
    hit: Hit,
    any_hit: u32,
    segment: u32,
    _p: [u32; 2],
    offset: [f32; 3],
    _p3: f32,
}

/// What a ray is for: the fan rays must hit (watertightness), the others are random.
#[derive(Clone, Copy, PartialEq, Debug)]
enum Kind {
    Random,
    Segment,
    AxisAligned,
    FanVertex,
    FanSpoke,
}

fn rand_vec(r: &mut Pcg64, lo: f32, hi: f32) -> Vec3 {
    Vec3::new(
        r.random_range(lo..hi),
        r.random_range(lo..hi),
        r.random_range(lo..hi),
    )
}

fn rand_dir(r: &mut Pcg64) -> Vec3 {
    loop {
        let v = rand_vec(r, -1.0, 1.0);
        let l = v.length_squared();
        if l > 1e-4 && l <= 1.0 {
            return v / l.sqrt();
        }
    }
}

/// Random triangles in [-10, 10]^3, and a closed fan of 16 triangles around a vertex near
/// (0, 0, 14): a slightly bent umbrella, so that no two triangles are coplanar, but flat
/// enough that the steep rays from above never see it fold (at a silhouette a ray may
/// rightly pass between two neighbours).
fn scene(r: &mut Pcg64) -> (Vec<[Vec3; 3]>, Vec3, Vec<Vec3>) {
    let mut tris: Vec<[Vec3; 3]> = (0..2000)
        .map(|_| {
            let c = rand_vec(r, -10.0, 10.0);
            [
                c + rand_vec(r, -1.5, 1.5),
                c + rand_vec(r, -1.5, 1.5),
                c + rand_vec(r, -1.5, 1.5),
            ]
        })
        .collect();
    let center = Vec3::new(0.1, -0.2, 14.0);
    let ring: Vec<Vec3> = (0..16)
        .map(|i| {
            let a = std::f32::consts::TAU * i as f32 / 16.0;
            center
                + Vec3::new(
                    3.0 * a.cos(),
                    3.0 * a.sin(),
                    if i % 2 == 0 { 0.15 } else { -0.1 },
                )
        })
        .collect();
    for i in 0..16 {
        tris.push([center, ring[i], ring[(i + 1) % 16]]);
    }
    (tris, center, ring)
}

fn rays(r: &mut Pcg64, center: Vec3, ring: &[Vec3]) -> Vec<(TestRay, Kind)> {
    let mut out = vec![];
    let mut push = |o: Vec3, d: Vec3, tmax: f32, kind: Kind, r: &mut Pcg64| {
        let n = rand_dir(r);
        out.push((
            TestRay {
                origin: o.to_array(),
                tmax,
                dir: d.to_array(),
                _pad0: 0.0,
                normal: n.to_array(),
                // No floor, or a power of two (as igi_core::bvh::offset_floor makes).
                floor: [0.0, 1.0 / 256.0, 0.0625][r.random_range(0..3)],
            },
            kind,
        ));
    };
    // The GPU has no infinity: "unbounded" rays use 1e30 on both sides.
    for _ in 0..2048 {
        let o = rand_vec(r, -14.0, 14.0);
        let d = rand_dir(r) * r.random_range(0.5..3.0);
        push(o, d, 1e30, Kind::Random, r);
    }
    for _ in 0..512 {
        let o = rand_vec(r, -14.0, 14.0);
        let e = rand_vec(r, -14.0, 14.0);
        push(o, e - o, 1.0, Kind::Segment, r);
    }
    for k in 0..512 {
        let o = rand_vec(r, -14.0, 14.0);
        let mut d = Vec3::ZERO;
        d[k % 3] = if k % 2 == 0 { 1.0 } else { -1.0 };
        if k % 5 == 0 {
            // Two axes: one zero component only.
            d[(k + 1) % 3] = 0.5;
        }
        push(o, d, 1e30, Kind::AxisAligned, r);
    }
    // Rays from above the fan (z > 14.15, nothing in between) aimed at its inner vertex
    // and at points of its shared edges (the spokes): a leaky test lets some through.
    for k in 0..1024 {
        let o = center + Vec3::new(0.0, 0.0, 10.0) + rand_vec(r, -6.0, 6.0);
        let (target, kind) = if k % 4 == 0 {
            (center, Kind::FanVertex)
        } else {
            let s: f32 = r.random_range(0.0..0.95);
            let q = ring[k % ring.len()];
            (center + s * (q - center), Kind::FanSpoke)
        };
        push(o, (target - o) * r.random_range(0.3..2.0), 1e30, kind, r);
    }
    out
}

#[test]
fn gpu_traversal_matches_cpu() {
    let ctx = match GpuContext::new(&AdapterChoice::Best) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("skipping the GPU traversal test: {e}");
            return;
        }
    };
    eprintln!("adapter: {}", ctx.describe());
    // Early split clipping cuts the scene's long triangles into pieces: a triangle in
    // several leaves must answer the same.
    for builder in [BvhBuilder::Binned, BvhBuilder::Split] {
        check_builder(&ctx, builder);
    }
}

fn check_builder(ctx: &GpuContext, builder: BvhBuilder) {
    let mut r = Pcg64::seed_from_u64(2024);
    let (tris, center, ring) = scene(&mut r);
    let fan = tris.len() - 16..tris.len();
    let bvh = Bvh::build_from_vertices_with(&tris, builder);
    eprintln!(
        "{} BVH: {} references for {} triangles",
        builder.name(),
        bvh.tri_order.len(),
        tris.len()
    );
    let rays = rays(&mut r, center, &ring);
    let results = run_kernel(ctx, &bvh, &rays);

    let mut failures = vec![];
    let (mut hits, mut ties, mut identical, mut cpu_differs) = (0, 0, 0, 0);
    for (i, ((ray, kind), res)) in rays.iter().zip(&results).enumerate() {
        let o = Vec3::from(ray.origin);
        let d = Vec3::from(ray.dir);
        let g = res.hit;
        let g_tri = (g.tri != NO_HIT).then(|| bvh.tri_order[g.tri as usize]);
        let mut fail = |what: String| failures.push(format!("ray {i} ({kind:?}) {o} {d}: {what}"));

        // Against the brute-force reference.
        let bf = brute_force_closest(&tris, o, d, ray.tmax);
        match (bf, g_tri) {
            (None, None) => {}
            (Some((bi, bt)), Some(gi)) => {
                hits += 1;
                let tol = t_tolerance(&tris[bi as usize], o, d, bt);
                if (g.t - bt).abs() > tol {
                    fail(format!(
                        "t {} on the GPU (tri {gi}), {bt} brute force (tri {bi})",
                        g.t
                    ));
                } else if gi != bi {
                    // Equal distances (a ray through a shared edge or vertex): the GPU's
                    // hit must lie on its own triangle, within rounding.
                    if on_triangle(&tris[gi as usize], o, d, &g) {
                        ties += 1;
                    } else {
                        fail(format!(
                            "GPU {g:?} is not on tri {gi}; brute force: tri {bi}"
                        ));
                    }
                }
            }
            (bf, _) => fail(format!("brute force {bf:?}, GPU tri {g_tri:?} t {}", g.t)),
        }
        let bf_any = brute_force_any(&tris, o, d, ray.tmax);
        if (res.any_hit == 1) != bf_any {
            fail(format!(
                "any hit: GPU {}, brute force {bf_any}",
                res.any_hit
            ));
        }
        let bf_segment = brute_force_any(&tris, o, d, 1.0);
        if (res.segment == 1) != bf_segment {
            fail(format!(
                "segment: GPU {}, brute force {bf_segment}",
                res.segment
            ));
        }
        let on_fan = g_tri.is_some_and(|t| fan.contains(&(t as usize)));
        if matches!(kind, Kind::FanVertex | Kind::FanSpoke) && (res.any_hit != 1 || !on_fan) {
            fail(format!("leaked through the fan (GPU tri {g_tri:?})"));
        }

        // Against the CPU twin.
        let c = bvh.trace_closest(o, d, ray.tmax);
        match c {
            Some(c) if g.tri != NO_HIT => {
                let same_bits = (c.t.to_bits(), c.tri, c.u.to_bits(), c.v.to_bits())
                    == (g.t.to_bits(), g.tri, g.u.to_bits(), g.v.to_bits());
                if same_bits {
                    identical += 1;
                } else {
                    cpu_differs += 1;
                    let tri = tris[bvh.tri_order[c.tri as usize] as usize];
                    if (c.t - g.t).abs() > t_tolerance(&tri, o, d, c.t) {
                        fail(format!("CPU BVH t {} ({c:?}), GPU {g:?}", c.t));
                    }
                }
            }
            None if g.tri == NO_HIT => identical += 1,
            _ => fail(format!("CPU BVH {c:?}, GPU {g:?}")),
        }
        if bvh.trace_any(o, d, ray.tmax) != (res.any_hit == 1) {
            fail("any hit differs from the CPU BVH".to_string());
        }
        if bvh.trace_segment(o, d) != (res.segment == 1) {
            fail("segment differs from the CPU BVH".to_string());
        }

        // The ray offset: bit for bit.
        let off = offset_ray_origin(o, Vec3::from(ray.normal), ray.floor);
        if off.to_array().map(f32::to_bits) != res.offset.map(f32::to_bits) {
            fail(format!("offset: CPU {off}, GPU {:?}", res.offset));
        }
    }
    eprintln!(
        "{} rays, {hits} hits ({ties} ties between triangles at equal distance); \
         GPU == CPU BVH bit for bit on {identical}, within 1e-5 on {cpu_differs}",
        rays.len()
    );
    assert!(
        failures.is_empty(),
        "{} failures, first ones:\n{}",
        failures.len(),
        failures[..failures.len().min(20)].join("\n")
    );
    assert!(
        hits > rays.len() / 4,
        "too few hits ({hits}) to mean anything"
    );
}

/// 1e-5 relative to the larger of t and the distance (in units of t) from the origin to
/// the farthest vertex of the triangle: the ray-triangle test works on vertices relative
/// to the origin, so its rounding scales with them, not with t alone (a hit at t = 1e-4
/// on a triangle 10 units wide is only known to ~1e-6 absolute).
fn t_tolerance(tri: &[Vec3; 3], o: Vec3, d: Vec3, t: f32) -> f32 {
    let reach = tri.iter().map(|v| (*v - o).length()).fold(0.0, f32::max) / d.length();
    1e-5 * t.max(reach)
}

/// Whether a hit reported on `tri` lies on it: barycentrics inside (within 1e-5) and the
/// interpolated point at origin + t dir (within 1e-5 of the triangle's reach).
fn on_triangle(tri: &[Vec3; 3], o: Vec3, d: Vec3, h: &Hit) -> bool {
    let w = 1.0 - h.u - h.v;
    let inside = [w, h.u, h.v].iter().all(|&b| b >= -1e-5);
    let p = tri[0] * w + tri[1] * h.u + tri[2] * h.v;
    let q = o + d * h.t;
    inside && (p - q).length() <= t_tolerance(tri, o, d, h.t) * d.length()
}

fn run_kernel(ctx: &GpuContext, bvh: &Bvh, rays: &[(TestRay, Kind)]) -> Vec<TestResult> {
    let device = &ctx.device;
    let src = igi_gpu::shader::try_compose("traverse test", KERNEL, ParamsBinding::Uniform)
        .expect("traverse.wgsl and its imports resolve");
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("traverse test"),
        source: wgpu::ShaderSource::Wgsl(src.into()),
    });
    // Auto layout: bind group 0 gets only the scene bindings the kernel uses
    // (bvh_nodes, tri_rows, and ray_counters, where walks count being cut short).
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("traverse test"),
        layout: None,
        module: &module,
        entry_point: Some("main"),
        compilation_options: Default::default(),
        cache: None,
    });
    let storage = |label: &str, contents: &[u8], extra: wgpu::BufferUsages| {
        device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents,
            usage: wgpu::BufferUsages::STORAGE | extra,
        })
    };
    let nodes = storage(
        "bvh_nodes",
        bytemuck::cast_slice(&bvh.nodes),
        wgpu::BufferUsages::empty(),
    );
    let rows = storage(
        "tri_rows",
        bytemuck::cast_slice(&bvh.tri_rows),
        wgpu::BufferUsages::empty(),
    );
    let ray_data: Vec<TestRay> = rays.iter().map(|(r, _)| *r).collect();
    let ray_buf = storage(
        "rays",
        bytemuck::cast_slice(&ray_data),
        wgpu::BufferUsages::empty(),
    );
    let out = storage(
        "results",
        bytemuck::cast_slice(&vec![TestResult::zeroed(); rays.len()]),
        wgpu::BufferUsages::COPY_SRC,
    );
    let counters = storage("ray_counters", &[0u8; 32], wgpu::BufferUsages::empty());
    let bind = |index: u32, buffers: &[(u32, &wgpu::Buffer)]| {
        let entries: Vec<wgpu::BindGroupEntry> = buffers
            .iter()
            .map(|&(binding, b)| wgpu::BindGroupEntry {
                binding,
                resource: b.as_entire_binding(),
            })
            .collect();
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &pipeline.get_bind_group_layout(index),
            entries: &entries,
        })
    };
    // The walks reference the alpha-mask test's bindings (no slot is alpha-tested here:
    // the rows' w is 0); one zero buffer stands for them.
    let unused = storage("mask bindings", &[0u8; 64], wgpu::BufferUsages::empty());
    let scene_group = bind(
        0,
        &[
            (0, &nodes),
            (1, &rows),
            (2, &unused),
            (3, &unused),
            (5, &counters),
            (6, &unused),
            (7, &unused),
        ],
    );
    let io_group = bind(1, &[(0, &ray_buf), (1, &out)]);
    let mut encoder =
        device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
    {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("traverse test"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &scene_group, &[]);
        pass.set_bind_group(1, &io_group, &[]);
        let groups = (rays.len() as u32).div_ceil(64);
        assert!(groups <= 65535);
        pass.dispatch_workgroups(groups, 1, 1);
    }
    ctx.queue.submit([encoder.finish()]);
    ctx.read_buffer::<TestResult>(&out)
        .unwrap_or_else(|e| panic!("GPU traversal failed: {e}"))
}
