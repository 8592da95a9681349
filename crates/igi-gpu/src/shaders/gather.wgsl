// gather.wgsl: the incident indirect term from VPLs at a surface point (paper section 4,
// "indirect illumination"): E(x) = sum_k Phi_k (rho_k / pi) V(x, y_k) G(x, y_k), with the
// bounded G of geometry_term.wgsl. Both gathering passes (direct and indirect) bind the
// VPL list at bindings 1 and 2 of group 1, declared here.
//
// A gathering pass may be dispatched several times, each over one range of the VPL list
// (bind group 2, a dynamic offset per dispatch), adding to what earlier ranges left.
// Real GPUs take the whole list in one dispatch. The software adapter needs the split:
// llvmpipe stops a shader invocation after 65535 loop iterations in all (its
// LP_MAX_TGSI_LOOP_ITERATIONS, shared by every loop of the shader), and one VPL costs a
// whole BVH traversal.

#import constants
#import params
#import traverse
#import sampling
#import geometry_term
#import ray_count
#import vpl_record

@group(1) @binding(1) var<storage, read> vpls: array<Vpl>;
@group(1) @binding(2) var<storage, read> vpl_header: VplHeader;

// Imperfect visibility (paper section 4.1): VPL shadow rays test the triangles' bounding
// boxes instead of the triangles. Set per pipeline (passes::GatherPipelines).
override IMPERFECT_VISIBILITY: bool = false;

struct GatherRange {
    begin: u32,
    end: u32,
    // The direct pass only (direct.wgsl): 1 in its first walk, which gathers no VPLs, 0 in
    // its later walks, which add the range's VPLs at hits seen in a mirror seen in a mirror.
    first_walk: u32,
    _pad1: u32,
}

@group(2) @binding(0) var<uniform> gather_range: GatherRange;

// The VPLs [first, last) this dispatch gathers from.
fn gather_first() -> u32 {
    return gather_range.begin;
}
fn gather_last() -> u32 {
    return min(gather_range.end, vpl_header.count);
}

// Interleaved sampling (paper section 4.3): the VPL subset of pixel (x, y) of the image
// being gathered (the indirect term's, or the mirrored hits'): its place in its n x m
// tile, through a permutation drawn for the tile when the pattern is irregular.
fn interleave_subset(x: u32, y: u32) -> u32 {
    let local = (x % params.interleave_n) + params.interleave_n * (y % params.interleave_m);
    if (params.pattern == 0u) {
        return local;
    }
    return irregular_subset(x, y, local);
}

// The irregular pattern's subset at place `local` of pixel (x, y)'s tile: a seeded
// Fisher-Yates permutation of the tile's places. A function of its own, so that its
// permutation array (zeroed where it is declared, as every WGSL variable) costs only the
// irregular pattern: zeroed in interleave_subset, it slowed interleaved frames with the
// regular one too.
fn irregular_subset(x: u32, y: u32, local: u32) -> u32 {
    let n = params.interleave_n;
    let m = params.interleave_m;
    var perm: array<u32, 64>;
    let count = n * m;
    for (var i = 0u; i < count; i += 1u) {
        perm[i] = i;
    }
    var h = hash_u32(params.seed ^ hash_u32((x / n) * 0x8da6b343u ^ (y / m) * 0xd8163841u));
    for (var i = count - 1u; i > 0u; i -= 1u) {
        h = hash_u32(h + 0x9e3779b9u);
        let j = h % (i + 1u);
        let t = perm[i];
        perm[i] = perm[j];
        perm[j] = t;
    }
    return perm[local];
}

// E at surface point p from the interleaving subset of pixel (x, y) of the image being
// gathered: the subset's VPLs within this dispatch's range, from `lane` on, every
// `lanes`-th (not yet scaled by the number of subsets).
fn subset_irradiance(p: vec3<f32>, ng: vec3<f32>, ns: vec3<f32>, x: u32, y: u32, lane: u32, lanes: u32) -> vec3<f32> {
    let subsets = params.interleave_n * params.interleave_m;
    let subset = interleave_subset(x, y);
    // First VPL of the subset within the dispatch's range, then this lane's.
    let begin = gather_first();
    let first = begin + (subset + subsets - begin % subsets) % subsets + lane * subsets;
    var stack: WalkStack;
    return vpl_irradiance(&stack, p, ng, ns, first, gather_last(), subsets * lanes);
}

// What a pixel holds after this dispatch: what earlier VPL ranges left (`previous`,
// ignored in the first range) plus this range's `sum`, scaled by the subset count so
// that a tile's average stays an unbiased estimate.
fn accumulated_irradiance(previous: vec4<f32>, sum: vec3<f32>) -> vec4<f32> {
    var e = vec3<f32>(0.0);
    if (gather_first() > 0u) {
        e = previous.xyz;
    }
    return vec4<f32>(e + f32(params.interleave_n * params.interleave_m) * sum, 1.0);
}

fn vpl_irradiance(stack: ptr<function, WalkStack>, p: vec3<f32>, ng: vec3<f32>, ns: vec3<f32>, first: u32, count: u32, stride: u32) -> vec3<f32> {
    var e = vec3<f32>(0.0);
    var traced = 0u;
    for (var k = first; k < count; k += stride) {
        let vpl = vpls[k];
        let d = vpl.position - p;
        let dist2 = dot(d, d);
        let inv_dist = inverseSqrt(dist2);
        let cos_x = dot(ns, d) * inv_dist;
        let cos_y = -dot(vpl.normal, d) * inv_dist;
        if (cos_x <= 0.0 || cos_y <= 0.0 || dot(ng, d) <= 0.0) {
            continue;
        }
        let g = cos_x * cos_y * bounded_inverse_square(dist2);
        if (g <= 0.0) {
            continue;
        }
        let end = offset_ray_origin(vpl.position, vpl.normal, params.ray_offset_floor);
        // The same origin for every VPL, computed again for each rather than held over
        // the loop: three registers fewer across the walk, which made canonical frames
        // faster.
        let origin = offset_ray_origin(p, ng, params.ray_offset_floor);
        traced += 1u;
        if (trace_segment(stack, origin, end - origin, IMPERFECT_VISIBILITY)) {
            continue;
        }
        e += vpl.flux * vpl.albedo * (g / PI);
    }
    count_rays(RAY_VPL_SHADOW, traced);
    return e;
}

// Threads that share one pixel's VPL loop in the gathers over a list of pixels (a
// pipeline constant dividing 256: passes::mirror_lanes, 4 on GPUs, 1 on software ones).
// A pass with few pixels to gather at (the pixels that see a mirror) cannot fill a big
// GPU with one thread each, so each pixel's VPLs are split over lanes, and lane 0 adds
// the lanes' sums in lane order (the same image every run).
override VPL_LANES: u32 = 8u;
