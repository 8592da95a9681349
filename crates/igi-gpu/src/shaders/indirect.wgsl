// indirect.wgsl: indirect diffuse light at the primary hits (paper section 4, third
// stage): the incident term E(x) from the VPLs through shadow rays, stored without the
// albedo of x so that later filters do not blur texture and material edges.
// With the paper's accelerations it runs at 1/downsample of the resolution per axis
// (section 4.2: one G-buffer sample stands for each block) and, with interleaved
// sampling (section 4.3), each pixel gathers only its subset of the VPLs, scaled by the
// number of subsets, so that the tile's average stays an unbiased estimate.
// The same pass gathers at the hits seen through mirrors (the "mirror indirect" stage,
// frame.rs): bound to the direct pass's mirror record instead of the G-buffer, with
// parameters of full resolution (no downsampling), so that those hits are interleaved
// too; the discontinuity buffer then runs over that record (filter.wgsl) and compose
// adds weight x E. The paper gathers every VPL there and leaves the cost as future work.

@group(1) @binding(1) var<storage, read> vpls: array<Vpl>;
@group(1) @binding(2) var<storage, read> vpl_header: VplHeader;
@group(1) @binding(3) var<storage, read> gbuf_position: array<vec4<f32>>;
@group(1) @binding(4) var<storage, read> gbuf_normal: array<vec4<f32>>;
@group(1) @binding(5) var<storage, read> gbuf_geometric: array<vec4<f32>>;
// At the indirect term's resolution (low_width x low_height).
@group(1) @binding(6) var<storage, read_write> irradiance_out: array<vec4<f32>>;

// One pixel's share of E: its subset's VPLs from `lane` on, every `lanes`-th.
fn pixel_sum(x: u32, y: u32, lane: u32, lanes: u32) -> vec3<f32> {
    let pixel = representative_pixel(x, y);
    let position = gbuf_position[pixel];
    if (position.w <= 0.0) {
        return vec3<f32>(0.0);
    }
    return subset_irradiance(position.xyz, gbuf_geometric[pixel].xyz, gbuf_normal[pixel].xyz, x, y, lane, lanes);
}

fn store_irradiance(x: u32, y: u32, sum: vec3<f32>) {
    let low = y * params.low_width + x;
    irradiance_out[low] = accumulated_irradiance(irradiance_out[low], sum);
}

// One thread per pixel, 8 x 8 pixels per workgroup.
@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= params.low_width || gid.y >= params.low_height) {
        return;
    }
    store_irradiance(gid.x, gid.y, pixel_sum(gid.x, gid.y, 0u, 1u));
}

// Each pixel's VPLs split over VPL_LANES threads (see gather.wgsl).
@compute @workgroup_size(64)
fn main_lanes(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) l: u32) {
    let p = lane_pixel(group, l);
    let lane = l % VPL_LANES;
    let inside = p.x < params.low_width && p.y < params.low_height;
    var sum = vec3<f32>(0.0);
    if (inside) {
        sum = pixel_sum(p.x, p.y, lane, VPL_LANES);
    }
    lane_sums[l] = vec4<f32>(sum, 0.0);
    workgroupBarrier();
    if (inside && lane == 0u) {
        store_irradiance(p.x, p.y, lanes_total(l));
    }
}

// The mirror indirect stage over the list of mirrored pixels (direct.wgsl's mirror_list):
// about one pixel in twenty sees a mirror in the conference room, and a dispatch over the
// whole image spent most of its workgroups on pixels with nothing to gather.
@group(3) @binding(0) var<storage, read_write> mirror_list: array<u32>;
// Workgroups of main_list (x, y, z), for dispatch_workgroups_indirect.
@group(3) @binding(1) var<storage, read_write> mirror_args: array<u32>;

// Largest workgroup count of one dispatch dimension.
const MAX_GROUPS: u32 = 65535u;

// One thread: takes this frame's count of mirrored pixels, resets the counter for the next
// frame and sizes main_list's dispatch (VPL_LANES threads per pixel, 64 per workgroup).
@compute @workgroup_size(1)
fn mirror_args_main() {
    let n = mirror_list[0];
    mirror_list[0] = 0u;
    mirror_list[1] = n;
    let groups = (n * VPL_LANES + 63u) / 64u;
    let x = min(groups, MAX_GROUPS);
    mirror_args[0] = x;
    mirror_args[1] = select(0u, (groups + x - 1u) / max(x, 1u), x > 0u);
    mirror_args[2] = 1u;
}

// main_lanes over the listed pixels: VPL_LANES neighbouring threads per pixel.
@compute @workgroup_size(64)
fn main_list(@builtin(workgroup_id) group: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>, @builtin(local_invocation_index) l: u32) {
    let slot = ((group.x + group.y * groups.x) * 64u + l) / VPL_LANES;
    let lane = l % VPL_LANES;
    let inside = slot < mirror_list[1];
    var pixel = 0u;
    var sum = vec3<f32>(0.0);
    if (inside) {
        pixel = mirror_list[2u + slot];
        sum = pixel_sum(pixel % params.low_width, pixel / params.low_width, lane, VPL_LANES);
    }
    lane_sums[l] = vec4<f32>(sum, 0.0);
    workgroupBarrier();
    if (inside && lane == 0u) {
        store_irradiance(pixel % params.low_width, pixel / params.low_width, lanes_total(l));
    }
}
