// direct.wgsl: direct + specular at full resolution (paper section 4, second stage). One
// primary ray per pixel; at each hit the point lights add (rho_d / pi) I V cos / d^2, a
// mirror part continues the Whitted tree up to the depth limit, and at hits reached
// through mirrors the indirect diffuse term comes from the full VPL set (no screen-space
// pass reaches them): at the first such hit it is gathered by indirect.wgsl from the
// record written here (compose adds it), at any later one (a mirror seen in a mirror)
// here. Writes the G-buffer of the primary hit.
// The pass walks twice. Its first walk (`main`) gathers no VPLs, so that it can run
// beside VPL shooting, before any VPL exists (frame.rs: the two are not kept apart by a
// barrier); it does everything else and lists the pixels whose chain has hits seen in a
// mirror seen in a mirror. Later walks (`chains_main`, after VPL shooting, over that
// list) follow only those chains again and add the VPL light of their range (one range
// on GPUs, several on llvmpipe, see gather.wgsl) at those hits.
// Bindings 1 and 2 of group 1 (the VPL list) are gather.wgsl's.

#import constants
#import params
#import scene
#import traverse
#import surface
#import ray_count
#import gbuffer
#import mirror_list
#import gather

@group(1) @binding(3) var<storage, read_write> direct_out: array<vec4<f32>>;
// G-buffer of the primary hits (gbuffer.wgsl says what each record holds).
@group(1) @binding(4) var<storage, read_write> gbuf_position: array<vec4<f32>>;
@group(1) @binding(5) var<storage, read_write> gbuf_normal: array<vec4<f32>>;
@group(1) @binding(6) var<storage, read_write> gbuf_geometric: array<vec4<f32>>;
@group(1) @binding(7) var<storage, read_write> gbuf_albedo: array<vec4<f32>>;
// The first diffuse hit of the pixel's mirror chain, for the mirror indirect stage
// (indirect.wgsl) to gather at (gbuffer.wgsl's mirror record).
@group(1) @binding(8) var<storage, read_write> mirror_position: array<vec4<f32>>;
@group(1) @binding(9) var<storage, read_write> mirror_normal: array<vec4<f32>>;
@group(1) @binding(10) var<storage, read_write> mirror_geometric: array<vec4<f32>>;
@group(1) @binding(11) var<storage, read_write> mirror_weight: array<vec4<f32>>;
// The pixels that have such a hit, for the mirror indirect stage to gather at only them,
// in one bucket per interleaving subset (mirror_list.wgsl says where each bucket lies):
// [s] counts the pixels appended to bucket s (zeroed before each frame by frame.rs).
@group(1) @binding(12) var<storage, read_write> mirror_list: array<atomic<u32>>;
// The pixels whose chain has hits seen in a mirror seen in a mirror, for the later walks:
// [0] counts those the first walk appended (zeroed before each frame by frame.rs), the
// pixels follow from [1] on. (A dispatch over the whole image that skipped the others
// cost time even in scenes that have none.)
@group(1) @binding(13) var<storage, read_write> chain_list: array<atomic<u32>>;

// Listed pixels per workgroup of the later walks (chains_main).
const CHAIN_GROUP: u32 = 32u;

// The first walk: one thread per pixel, 8 x 4 pixels (one warp) per workgroup, which
// was faster than 8 x 8.
@compute @workgroup_size(8, 4)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= params.width || gid.y >= params.height) {
        return;
    }
    shade(gid.x, gid.y);
}

// The later walks over the listed pixels, one thread each: a fixed grid (frame.rs
// sizes it by the image, not by the list) strides over the list, so that nothing has to
// size the dispatch between the first walk and this one.
@compute @workgroup_size(CHAIN_GROUP)
fn chains_main(@builtin(workgroup_id) group: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>, @builtin(local_invocation_index) l: u32) {
    let count = atomicLoad(&chain_list[0]);
    let stride = groups.x * groups.y * CHAIN_GROUP;
    for (var slot = (group.x + group.y * groups.x) * CHAIN_GROUP + l; slot < count; slot += stride) {
        let pixel = atomicLoad(&chain_list[1u + slot]);
        shade(pixel % params.width, pixel / params.width);
    }
}

// The primary ray through pixel (x, y); y = 0 is the top row.
fn camera_ray_dir(x: u32, y: u32) -> vec3<f32> {
    // Frame 0 of an accumulation looks through pixel centres; later frames jitter
    // within the pixel, so that accumulation converges to the pixel's box average.
    let sx = (2.0 * (f32(x) + 0.5 + params.jitter_x) / f32(params.width) - 1.0) * params.tan_half_fov_y * params.aspect;
    let sy = (1.0 - 2.0 * (f32(y) + 0.5 + params.jitter_y) / f32(params.height)) * params.tan_half_fov_y;
    return normalize(params.cam_forward + sx * params.cam_right + sy * params.cam_up);
}

// The angle one pixel subtends (at the image centre): a primary ray cone's width per
// unit of distance.
fn pixel_spread() -> f32 {
    return 2.0 * params.tan_half_fov_y / f32(params.height);
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

// Pixel (x, y)'s chain, in the walk `gather_range` says.
fn shade(x: u32, y: u32) {
    let pixel = y * params.width + x;
    var origin = params.cam_eye;
    var dir = camera_ray_dir(x, y);
    var throughput = vec3<f32>(1.0);
    var radiance = vec3<f32>(0.0);
    let first_walk = gather_range.first_walk != 0u;
    if (first_walk) {
        gbuf_position[pixel] = empty_record();
        gbuf_normal[pixel] = empty_record();
        gbuf_geometric[pixel] = empty_record();
        gbuf_albedo[pixel] = empty_record();
        mirror_position[pixel] = empty_record();
        mirror_weight[pixel] = empty_record();
    } else {
        // Later walks (over the listed pixels only) add VPL light at hits seen in a mirror
        // seen in a mirror.
        radiance = direct_out[pixel].xyz;
    }
    var stack: WalkStack;
    var traced = 0u;
    var recorded = false;
    // Whether the chain reaches a hit seen in a mirror seen in a mirror (first walk).
    var chained = false;
    // Length of the chain so far: the mirrored hit's depth for the mirror filter.
    var travelled = 0.0;
    for (var depth = 0u; depth <= params.mirror_depth; depth += 1u) {
        let hit = trace_closest(&stack, origin, dir, INFINITY);
        traced += 1u;
        if (hit.tri == NO_HIT) {
            break;
        }
        // The pixel's ray cone (its width grows by the pixel's angle per unit of length,
        // and flat mirrors keep the angle) picks the texture level.
        let s = surface_at(origin, dir, hit, pixel_spread() * (travelled + hit.t));
        travelled += hit.t;
        if (depth == 0u && first_walk) {
            gbuf_position[pixel] = pack_position(s.position);
            gbuf_normal[pixel] = pack_normal(s.shading_normal, hit.t);
            gbuf_geometric[pixel] = pack_geometric(s.geometric_normal);
            gbuf_albedo[pixel] = pack_albedo(s.diffuse);
        }
        if (max(s.diffuse.x, max(s.diffuse.y, s.diffuse.z)) > 0.0) {
            var e = vec3<f32>(0.0);
            if (first_walk) {
                e = direct_irradiance(&stack, s.position, s.geometric_normal, s.shading_normal);
            }
            let weight = throughput * s.diffuse / PI;
            if (depth > 0u && !recorded) {
                recorded = true;
                if (first_walk) {
                    let bucket = interleave_subset(x, y);
                    let slot = atomicAdd(&mirror_list[bucket], 1u);
                    atomicStore(&mirror_list[MAX_SUBSETS + bucket * mirror_bucket_size() + slot], pixel);
                    mirror_position[pixel] = pack_position(s.position);
                    mirror_normal[pixel] = pack_normal(s.shading_normal, travelled);
                    mirror_geometric[pixel] = pack_geometric(s.geometric_normal);
                    mirror_weight[pixel] = pack_weight(weight);
                }
            } else if (depth > 0u) {
                if (first_walk) {
                    chained = true;
                } else {
                    e += vpl_irradiance(&stack, s.position, s.geometric_normal, s.shading_normal, gather_first(), gather_last(), 1u);
                }
            }
            radiance += weight * e;
        }
        if (max(s.mirror.x, max(s.mirror.y, s.mirror.z)) <= 0.0) {
            break;
        }
        throughput *= s.mirror;
        dir = reflect(dir, s.shading_normal);
        if (dot(dir, s.geometric_normal) <= 0.0) {
            dir = reflect(dir, s.geometric_normal);
        }
        origin = offset_ray_origin(s.position, s.geometric_normal, params.ray_offset_floor);
    }
    if (first_walk) {
        count_rays(RAY_PRIMARY, 1u);
        count_rays(RAY_MIRROR, traced - 1u);
        if (chained) {
            let slot = atomicAdd(&chain_list[0], 1u);
            atomicStore(&chain_list[1u + slot], pixel);
        }
    }
    direct_out[pixel] = vec4<f32>(radiance, 1.0);
}
