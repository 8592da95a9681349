// gather.wgsl: the incident indirect term from VPLs at a surface point (paper section 4,
// "indirect illumination"): E(x) = sum_k Phi_k (rho_k / pi) V(x, y_k) G(x, y_k), with the
// bounded G of frame.wgsl. Uses the globals `vpls` and `vpl_header`, which every pass
// that includes this module declares.
//
// A gathering pass may be dispatched several times, each over one range of the VPL list
// (bind group 2, a dynamic offset per dispatch), adding to what earlier ranges left.
// Real GPUs take the whole list in one dispatch. The software adapter needs the split:
// llvmpipe stops a shader invocation after 65535 loop iterations in all (its
// LP_MAX_TGSI_LOOP_ITERATIONS, shared by every loop of the shader), and one VPL costs a
// whole BVH traversal.

// Imperfect visibility (paper section 4.1): VPL shadow rays test the triangles' bounding
// boxes instead of the triangles. Set per pipeline (passes::GatherPipelines).
override IMPERFECT_VISIBILITY: bool = false;

struct GatherRange {
    begin: u32,
    end: u32,
    _pad0: u32,
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

fn vpl_irradiance(p: vec3<f32>, ng: vec3<f32>, ns: vec3<f32>, first: u32, count: u32, stride: u32) -> vec3<f32> {
    var e = vec3<f32>(0.0);
    let origin = offset_ray_origin(p, ng);
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
        let end = offset_ray_origin(vpl.position, vpl.normal);
        traced += 1u;
        if (trace_shadow(origin, end - origin, 1.0, IMPERFECT_VISIBILITY)) {
            continue;
        }
        e += vpl.flux * vpl.albedo * (g / PI);
    }
    count_rays(RAY_VPL_SHADOW, traced);
    return e;
}
