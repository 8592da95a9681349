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
// mirror seen in a mirror. Later walks (`chains_main`,
// after VPL shooting, dispatched over that list) follow only those chains again and add
// the VPL light of their range (one range on GPUs, several on llvmpipe, see gather.wgsl)
// at those hits.

@group(1) @binding(1) var<storage, read> vpls: array<Vpl>;
@group(1) @binding(2) var<storage, read> vpl_header: VplHeader;
@group(1) @binding(3) var<storage, read_write> direct_out: array<vec4<f32>>;
// G-buffer: position (w = 1 where a surface was hit), shading normal, geometric normal,
// diffuse albedo.
@group(1) @binding(4) var<storage, read_write> gbuf_position: array<vec4<f32>>;
@group(1) @binding(5) var<storage, read_write> gbuf_normal: array<vec4<f32>>;
@group(1) @binding(6) var<storage, read_write> gbuf_geometric: array<vec4<f32>>;
@group(1) @binding(7) var<storage, read_write> gbuf_albedo: array<vec4<f32>>;
// The first diffuse hit of the pixel's mirror chain, for the mirror indirect stage
// (indirect.wgsl) to gather at. The shading normal's w is the chain's length (the
// depth the mirror discontinuity buffer compares), the weight's w is 1 where there is one.
@group(1) @binding(8) var<storage, read_write> mirror_position: array<vec4<f32>>;
@group(1) @binding(9) var<storage, read_write> mirror_normal: array<vec4<f32>>;
@group(1) @binding(10) var<storage, read_write> mirror_geometric: array<vec4<f32>>;
@group(1) @binding(11) var<storage, read_write> mirror_weight: array<vec4<f32>>;
// The pixels that have such a hit, for the mirror indirect stage to gather at only them,
// in one bucket per interleaving subset (see mirror_bucket in gather.wgsl): [s] counts
// the pixels appended to bucket s (zeroed before each frame by frame.rs), bucket s
// starts at MAX_SUBSETS + s mirror_bucket_size().
@group(1) @binding(12) var<storage, read_write> mirror_list: array<atomic<u32>>;
// The pixels whose chain has hits seen in a mirror seen in a mirror, for the later walks:
// [0] counts those the first walk appended (zeroed before each frame by frame.rs), the
// pixels follow from [1] on. (A dispatch over the whole image that skipped the others
// took 0.018 ms of the H200 in the conference room, which has none: docs/PERFORMANCE.md
// attempt 50.)
@group(1) @binding(13) var<storage, read_write> chain_list: array<atomic<u32>>;

// The first walk: one thread per pixel, 8 x 4 pixels (one warp) per workgroup: 8 x 8 took
// 0.74 ms against 0.66 ms on the H200 (conference room, 800 x 600; docs/PERFORMANCE.md
// attempt 32).
@compute @workgroup_size(8, 4)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= params.width || gid.y >= params.height) {
        return;
    }
    shade(gid.x, gid.y);
}

// The later walks over the listed pixels, one thread each: a fixed grid (frame.rs
// sizes it by the image, not by the list) strides over the list, so that nothing has to
// size the dispatch between the first walk and this one (docs/PERFORMANCE.md attempt
// 75).
@compute @workgroup_size(CHAIN_GROUP)
fn chains_main(@builtin(workgroup_id) group: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>, @builtin(local_invocation_index) l: u32) {
    let count = atomicLoad(&chain_list[0]);
    let stride = groups.x * groups.y * CHAIN_GROUP;
    for (var slot = (group.x + group.y * groups.x) * CHAIN_GROUP + l; slot < count; slot += stride) {
        let pixel = atomicLoad(&chain_list[1u + slot]);
        shade(pixel % params.width, pixel / params.width);
    }
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
        gbuf_position[pixel] = vec4<f32>(0.0);
        gbuf_normal[pixel] = vec4<f32>(0.0);
        gbuf_geometric[pixel] = vec4<f32>(0.0);
        gbuf_albedo[pixel] = vec4<f32>(0.0);
        mirror_position[pixel] = vec4<f32>(0.0);
        mirror_weight[pixel] = vec4<f32>(0.0);
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
        let s = surface_at(origin, dir, hit);
        travelled += hit.t;
        if (depth == 0u && first_walk) {
            gbuf_position[pixel] = vec4<f32>(s.position, 1.0);
            gbuf_normal[pixel] = vec4<f32>(s.shading_normal, hit.t);
            gbuf_geometric[pixel] = vec4<f32>(s.geometric_normal, 0.0);
            gbuf_albedo[pixel] = vec4<f32>(s.diffuse, 0.0);
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
                    mirror_position[pixel] = vec4<f32>(s.position, 1.0);
                    mirror_normal[pixel] = vec4<f32>(s.shading_normal, travelled);
                    mirror_geometric[pixel] = vec4<f32>(s.geometric_normal, 0.0);
                    mirror_weight[pixel] = vec4<f32>(weight, 1.0);
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
