// mirror.wgsl: indirect diffuse light at hits seen through mirrors (paper section 4: "at
// hits reached through mirrors the indirect term is gathered from the full VPL set"; the
// paper lists its cost as future work). The direct pass records, per pixel, the first
// diffuse hit of its mirror chain; this pass gathers E there and stores it, without the
// weight, for compose to add weight x E to the pixel's direct + specular radiance. A
// separate pass, so that the few pixels that see a mirror can split their VPLs over lanes
// instead of holding back the direct pass's warps.
// With interleaved sampling (section 4.3) the mirrored hits are interleaved too: each
// pixel gathers its subset of the VPLs, scaled by the number of subsets, and the
// discontinuity buffer then runs over the mirrored hits' own positions, normals and
// depths (filter.wgsl with this record as its G-buffer). Downsampling does not apply.

@group(1) @binding(1) var<storage, read> vpls: array<Vpl>;
@group(1) @binding(2) var<storage, read> vpl_header: VplHeader;
// The record: position (w = 1 where there is one), shading normal (w: the chain's
// length), geometric normal, and the weight (w = 1 where there is a record): the chain's
// mirror throughput times rho / pi of the hit.
@group(1) @binding(3) var<storage, read> mirror_position: array<vec4<f32>>;
@group(1) @binding(4) var<storage, read> mirror_normal: array<vec4<f32>>;
@group(1) @binding(5) var<storage, read> mirror_geometric: array<vec4<f32>>;
@group(1) @binding(6) var<storage, read> mirror_weight: array<vec4<f32>>;
// E at the mirrored hit (full resolution), summed over the dispatches of the VPL ranges.
@group(1) @binding(7) var<storage, read_write> mirror_irradiance: array<vec4<f32>>;

// This lane's share of the E at pixel (x, y)'s mirrored hit (zero without one): its
// interleaving subset's VPLs from `lane` on, every `lanes`-th.
fn mirrored_sum(x: u32, y: u32, lane: u32, lanes: u32) -> vec3<f32> {
    let pixel = y * params.width + x;
    let position = mirror_position[pixel];
    if (position.w <= 0.0) {
        return vec3<f32>(0.0);
    }
    return subset_irradiance(position.xyz, mirror_geometric[pixel].xyz, mirror_normal[pixel].xyz, x, y, lane, lanes);
}

fn store_mirrored(x: u32, y: u32, sum: vec3<f32>) {
    let pixel = y * params.width + x;
    mirror_irradiance[pixel] = accumulated_irradiance(mirror_irradiance[pixel], sum);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= params.width || gid.y >= params.height) {
        return;
    }
    store_mirrored(gid.x, gid.y, mirrored_sum(gid.x, gid.y, 0u, 1u));
}

@compute @workgroup_size(64)
fn main_lanes(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) l: u32) {
    let p = lane_pixel(group, l);
    let lane = l % VPL_LANES;
    let inside = p.x < params.width && p.y < params.height;
    var sum = vec3<f32>(0.0);
    if (inside) {
        sum = mirrored_sum(p.x, p.y, lane, VPL_LANES);
    }
    lane_sums[l] = vec4<f32>(sum, 0.0);
    workgroupBarrier();
    if (inside && lane == 0u) {
        store_mirrored(p.x, p.y, lanes_total(l));
    }
}
