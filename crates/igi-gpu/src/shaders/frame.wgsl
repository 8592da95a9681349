// frame.wgsl: what every pass of the frame shares: the frame parameters (binding 0 of
// group 1 in every pass), the VPL record, sampling maps, hit shading and the bounded
// geometry term.

const PI: f32 = 3.14159265358979;
const INFINITY: f32 = 3.4e38;
const ONE_MINUS_EPSILON: f32 = 0.99999994;

// Kinds of rays, as counted in ray_counters (igi_gpu::frame::RayCounts).
const RAY_PRIMARY: u32 = 0u;
const RAY_MIRROR: u32 = 1u;
const RAY_LIGHT_SHADOW: u32 = 2u;
const RAY_VPL_SHADOW: u32 = 3u;
const RAY_PARTICLE: u32 = 4u;

struct FrameParams {
    cam_eye: vec3<f32>, width: u32,
    cam_forward: vec3<f32>, height: u32,
    cam_right: vec3<f32>, tan_half_fov_y: f32,
    cam_up: vec3<f32>, aspect: f32,
    total_power: vec3<f32>, light_count: u32,
    path_count: u32, bounces: u32, min_dist: f32, geometry_bound: u32,
    mirror_depth: u32, halton_base: u32, output: u32, light_power_sum: f32,
    // The indirect term's resolution (full / downsample, rounded up) and its filters.
    low_width: u32, low_height: u32, downsample: u32, interleave_n: u32,
    interleave_m: u32, pattern: u32, seed: u32, accumulate_index: u32,
    upsample_sigma: f32, normal_power: f32, upsample_depth: u32, depth_threshold: f32,
    normal_threshold: f32, jitter_x: f32, jitter_y: f32, count_rays: u32,
    depth_scale: f32, ray_offset_floor: f32, _pad1: u32, _pad2: u32,
}

// A virtual point light: 64 bytes, see layout.rs.
struct Vpl {
    position: vec3<f32>, valid: u32,
    normal: vec3<f32>, bounce: u32,
    flux: vec3<f32>, _pad0: f32,
    albedo: vec3<f32>, _pad1: f32,
}

// Number of VPLs after compaction, and what they came from.
struct VplHeader {
    count: u32,
    path_count: u32,
    slots: u32,
    _pad: u32,
}

// A uniform buffer on GPUs; on software adapters `shader::compose_for` makes each
// uniform declaration a read-only storage buffer (lavapipe recompiled shaders that
// branch on uniform values at every bind: docs/PERFORMANCE.md attempt 123).
@group(1) @binding(0) var<uniform> params: FrameParams;

fn uniform_sphere(u1: f32, u2: f32) -> vec3<f32> {
    let z = 1.0 - 2.0 * u1;
    let r = sqrt(max(1.0 - z * z, 0.0));
    let phi = 2.0 * PI * u2;
    return vec3<f32>(r * cos(phi), r * sin(phi), z);
}

fn cosine_hemisphere(u1: f32, u2: f32) -> vec3<f32> {
    let r = sqrt(u1);
    let phi = 2.0 * PI * u2;
    return vec3<f32>(r * cos(phi), r * sin(phi), sqrt(max(1.0 - u1, 0.0)));
}

// Duff et al. 2017: an orthonormal basis around unit n, as two columns t, b.
fn basis_t(n: vec3<f32>) -> vec3<f32> {
    let s = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (s + n.z);
    return vec3<f32>(1.0 + s * n.x * n.x * a, s * n.x * n.y * a, -s * n.x);
}
fn basis_b(n: vec3<f32>) -> vec3<f32> {
    let s = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (s + n.z);
    return vec3<f32>(n.x * n.y * a, s + n.y * n.y * a, -n.y);
}

fn mean3(v: vec3<f32>) -> f32 {
    return (v.x + v.y + v.z) / 3.0;
}

// What a closest hit looks like to shading. Surfaces are two-sided: both normals face the
// side the ray came from.
struct SurfaceHit {
    position: vec3<f32>,
    geometric_normal: vec3<f32>,
    shading_normal: vec3<f32>,
    diffuse: vec3<f32>,
    mirror: vec3<f32>,
}

// 2^j for j in [-126, 127], exactly (the exponent field alone).
fn pow2(j: i32) -> f32 {
    return bitcast<f32>(u32(127 + j) << 23u);
}

// `e` times the power of two that brings its largest component into [0.5, 1): only
// exponents change, so a cross product of scaled edges rounds exactly as the plain one
// does, but cannot overflow (edges past ~1e19 square past the f32 range and normalize
// gave 0 or NaN). In two halves so that each factor is a normal f32. CPU twin:
// igi_core::scene::scale_pow2.
fn scale_pow2(e: vec3<f32>) -> vec3<f32> {
    let m = max(abs(e.x), max(abs(e.y), abs(e.z)));
    let k = 126 - i32((bitcast<u32>(m) >> 23u) & 0xffu);
    return e * pow2(k / 2) * pow2(k - k / 2);
}

// Unit normal on the side of the winding (CPU twin: igi_core::scene::geometric_normal,
// which also decides which triangles the loaders keep: all of them have one).
fn geometric_normal(v0: vec3<f32>, v1: vec3<f32>, v2: vec3<f32>) -> vec3<f32> {
    return normalize(cross(scale_pow2(v1 - v0), scale_pow2(v2 - v0)));
}

fn surface_at(origin: vec3<f32>, dir: vec3<f32>, hit: Hit) -> SurfaceHit {
    var s: SurfaceHit;
    let x = tri_rows[3u * hit.tri].xyz;
    let y = tri_rows[3u * hit.tri + 1u].xyz;
    let z = tri_rows[3u * hit.tri + 2u].xyz;
    let v0 = vec3<f32>(x.x, y.x, z.x);
    let v1 = vec3<f32>(x.y, y.y, z.y);
    let v2 = vec3<f32>(x.z, y.z, z.z);
    // Barycentric position: on the triangle, not origin + t dir, whose rounding can put
    // the point behind the surface.
    s.position = (1.0 - hit.u - hit.v) * v0 + hit.u * v1 + hit.v * v2;
    var ng = geometric_normal(v0, v1, v2);
    if (dot(ng, dir) > 0.0) {
        ng = -ng;
    }
    let sh = tri_shading[hit.tri];
    var ns = (1.0 - hit.u - hit.v) * sh.n0 + hit.u * sh.n1 + hit.v * sh.n2;
    let len = length(ns);
    ns = select(ng, ns / len, len > 1e-12);
    if (dot(ns, ng) < 0.0) {
        ns = -ns;
    }
    s.geometric_normal = ng;
    s.shading_normal = ns;
    let m = materials[sh.material];
    s.diffuse = m.diffuse;
    s.mirror = m.mirror;
    return s;
}

// The primary ray through pixel (x, y); y = 0 is the top row.
fn camera_ray_dir(x: u32, y: u32) -> vec3<f32> {
    // Frame 0 of an accumulation looks through pixel centres; later frames jitter
    // within the pixel, so that accumulation converges to the pixel's box average.
    let sx = (2.0 * (f32(x) + 0.5 + params.jitter_x) / f32(params.width) - 1.0) * params.tan_half_fov_y * params.aspect;
    let sy = (1.0 - 2.0 * (f32(y) + 0.5 + params.jitter_y) / f32(params.height)) * params.tan_half_fov_y;
    return normalize(params.cam_forward + sx * params.cam_right + sy * params.cam_up);
}

// The bound on the distance part of G: the paper's smoothstep(0.8 m, 1.2 m, d) / d^2, or
// the classic clamp 1 / max(d^2, m^2).
fn bounded_inverse_square(dist2: f32) -> f32 {
    let m = params.min_dist;
    if (params.geometry_bound == 1u) {
        return 1.0 / max(dist2, m * m);
    }
    return smoothstep(0.8 * m, 1.2 * m, sqrt(dist2)) / dist2;
}

// Add n rays of `kind` to the counters when this frame counts rays.
fn count_rays(kind: u32, n: u32) {
    if (params.count_rays != 0u && n > 0u) {
        atomicAdd(&ray_counters[kind], n);
    }
}

// Irradiance from the point lights at p (shadow rays from the surface to each light).
fn direct_irradiance(stack: ptr<function, WalkStack>, p: vec3<f32>, ng: vec3<f32>, ns: vec3<f32>) -> vec3<f32> {
    var e = vec3<f32>(0.0);
    let origin = offset_ray_origin(p, ng, params.ray_offset_floor);
    var traced = 0u;
    for (var l = 0u; l < params.light_count; l += 1u) {
        let light = lights[l];
        let d = light.position - p;
        let dist2 = dot(d, d);
        let cos_x = dot(ns, d) * inverseSqrt(dist2);
        if (cos_x <= 0.0 || dot(ng, d) <= 0.0) {
            continue;
        }
        traced += 1u;
        if (trace_segment(stack, origin, light.position - origin, false)) {
            continue;
        }
        e += light.intensity * cos_x / dist2;
    }
    count_rays(RAY_LIGHT_SHADOW, traced);
    return e;
}

// The full-resolution pixel whose G-buffer sample stands for low-resolution pixel
// (x, y) of the indirect term: the centre of its downsample x downsample block.
fn representative_pixel(x: u32, y: u32) -> u32 {
    let half = params.downsample / 2u;
    let fx = min(x * params.downsample + half, params.width - 1u);
    let fy = min(y * params.downsample + half, params.height - 1u);
    return fy * params.width + fx;
}

// A 32-bit integer hash (igi_core::sampling::hash_u32).
fn hash_u32(v: u32) -> u32 {
    var x = v;
    x ^= x >> 16u;
    x *= 0x7feb352du;
    x ^= x >> 15u;
    x *= 0x846ca68bu;
    x ^= x >> 16u;
    return x;
}

// Most interleaving subsets (frame.rs MAX_SUBSETS).
const MAX_SUBSETS: u32 = 64u;

// Listed pixels per workgroup of the direct pass's later walks (direct.wgsl chains_main).
const CHAIN_GROUP: u32 = 32u;
