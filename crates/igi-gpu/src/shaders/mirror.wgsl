// mirror.wgsl: indirect diffuse light at hits seen through mirrors (paper section 4: "at
// hits reached through mirrors the indirect term is gathered from the full VPL set"; the
// paper lists its cost as future work). The direct pass records, per pixel, the first
// diffuse hit of its mirror chain; this pass gathers E there from every VPL and adds
// weight x E to the pixel's direct + specular radiance. A separate pass, so that the few
// pixels that see a mirror can split their VPLs over lanes instead of holding back the
// direct pass's warps.

@group(1) @binding(1) var<storage, read> vpls: array<Vpl>;
@group(1) @binding(2) var<storage, read> vpl_header: VplHeader;
// The record: position (w = 1 where there is one), shading normal, geometric normal, and
// the weight: the chain's mirror throughput times rho / pi of the hit.
@group(1) @binding(3) var<storage, read> mirror_position: array<vec4<f32>>;
@group(1) @binding(4) var<storage, read> mirror_normal: array<vec4<f32>>;
@group(1) @binding(5) var<storage, read> mirror_geometric: array<vec4<f32>>;
@group(1) @binding(6) var<storage, read> mirror_weight: array<vec4<f32>>;
@group(1) @binding(7) var<storage, read_write> direct_out: array<vec4<f32>>;

// This lane's share of the E at pixel's mirrored hit (zero without one).
fn mirrored_sum(pixel: u32, lane: u32, lanes: u32) -> vec3<f32> {
    let position = mirror_position[pixel];
    if (position.w <= 0.0) {
        return vec3<f32>(0.0);
    }
    return vpl_irradiance(position.xyz, mirror_geometric[pixel].xyz, mirror_normal[pixel].xyz, gather_first() + lane, gather_last(), lanes);
}

fn add_mirrored(pixel: u32, e: vec3<f32>) {
    if (mirror_position[pixel].w > 0.0) {
        direct_out[pixel] = vec4<f32>(direct_out[pixel].xyz + mirror_weight[pixel].xyz * e, 1.0);
    }
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= params.width || gid.y >= params.height) {
        return;
    }
    let pixel = gid.y * params.width + gid.x;
    add_mirrored(pixel, mirrored_sum(pixel, 0u, 1u));
}

@compute @workgroup_size(64)
fn main_lanes(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) l: u32) {
    let p = lane_pixel(group, l);
    let lane = l % VPL_LANES;
    let inside = p.x < params.width && p.y < params.height;
    let pixel = p.y * params.width + p.x;
    var sum = vec3<f32>(0.0);
    if (inside) {
        sum = mirrored_sum(pixel, lane, VPL_LANES);
    }
    lane_sums[l] = vec4<f32>(sum, 0.0);
    workgroupBarrier();
    if (inside && lane == 0u) {
        add_mirrored(pixel, lanes_total(l));
    }
}
