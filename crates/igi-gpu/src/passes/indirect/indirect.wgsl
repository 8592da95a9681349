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
// Bindings 1 and 2 of group 1 (the VPL list) are gather.wgsl's.

#import params
#import gbuffer
#import mirror_list
#import gather

// The G-buffer, or the mirror record (gbuffer.wgsl).
@group(1) @binding(3) var<storage, read> gbuf_position: array<vec4<f32>>;
@group(1) @binding(4) var<storage, read> gbuf_normal: array<vec4<f32>>;
@group(1) @binding(5) var<storage, read> gbuf_geometric: array<vec4<f32>>;
// At the indirect term's resolution (low_width x low_height).
@group(1) @binding(6) var<storage, read_write> irradiance_out: array<vec4<f32>>;

// One pixel's share of E: its subset's VPLs from `lane` on, every `lanes`-th.
fn pixel_sum(x: u32, y: u32, lane: u32, lanes: u32) -> vec3<f32> {
    let pixel = representative_pixel(x, y);
    let position = gbuf_position[pixel];
    if (!has_surface(position)) {
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

// Each pixel's VPLs split over COHERENT_LANES threads (lanes: 4 or 8, set by the
// pipeline, passes::lanes_for), the threads of a warp on 32 pixels of one interleaving
// subset and one lane: they trace to the same VPL at each step of the loop (rays that
// end at one point, from neighbouring pixels of the subset; warps that held the 8 lanes
// of 4 neighbouring pixels traced to 32 different VPLs, which was up to 1.6x slower).
// A workgroup is 32 pixels x COHERENT_LANES lanes: the pixels at the same place of
// 8 x 4 neighbouring interleaving tiles (the same subset with the regular pattern; the
// irregular one permutes subsets per tile, which costs coherence, not correctness), and
// group.z is that place in the tile. The
// lanes' sums are added in lane order.
override COHERENT_LANES: u32 = 8u;
// One sum per thread of the workgroup: main_coherent's here, main_list's below. Each
// entry point has its own array, sized by its own pipeline constant: one array sized for
// both took 4 KiB of shared memory from every main_coherent workgroup of 128 threads,
// which needs 2 (shared memory is taken from the L1 cache the walks live in).
var<workgroup> coherent_sums: array<vec4<f32>, 32u * COHERENT_LANES>;

@compute @workgroup_size(32u * COHERENT_LANES)
fn main_coherent(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) l: u32) {
    let n = params.interleave_n;
    let m = params.interleave_m;
    let p = l % 32u;
    let lane = l / 32u;
    let x = group.x * 8u * n + (p % 8u) * n + group.z % n;
    let y = group.y * 4u * m + (p / 8u) * m + group.z / n;
    let inside = x < params.low_width && y < params.low_height;
    var sum = vec3<f32>(0.0);
    if (inside) {
        sum = pixel_sum(x, y, lane, COHERENT_LANES);
    }
    coherent_sums[l] = vec4<f32>(sum, 0.0);
    workgroupBarrier();
    if (inside && lane == 0u) {
        // The lanes' sums in lane order.
        var total = vec3<f32>(0.0);
        for (var k = 0u; k < COHERENT_LANES; k += 1u) {
            total += coherent_sums[k * 32u + p].xyz;
        }
        store_irradiance(x, y, total);
    }
}

// The mirror indirect stage over the list of mirrored pixels (direct.wgsl's mirror_list):
// about one pixel in twenty sees a mirror in the conference room, and a dispatch over the
// whole image spent most of its workgroups on pixels with nothing to gather. The list
// has one bucket per interleaving subset, so that the 32 pixels of a warp gather the
// same VPLs in step, as in main_coherent.
// The list is read-only here, so that nothing keeps this gather from running beside the
// indirect gather (frame.rs).
@group(3) @binding(0) var<storage, read> mirror_list: array<u32>;

// Threads of a main_list workgroup: 256, or 32 per lane where that is more, so that a
// warp always holds one lane of 32 pixels; it takes LIST_GROUP / VPL_LANES listed pixels.
// Set by frame.rs (`passes::indirect::list_group`).
override LIST_GROUP: u32 = 256u;
var<workgroup> list_sums: array<vec4<f32>, LIST_GROUP>;

// The gather over the listed pixels of bucket group.z, VPL_LANES threads per pixel, a
// warp holding one lane of 32 pixels (as main_coherent): they trace to the same VPL at
// each step. The lanes' sums are added in lane order. A fixed grid of workgroups per
// bucket (frame.rs sizes it by the image, not by the list) strides over the bucket's
// pixels, so that nothing has to size the dispatch between the direct pass, which
// lists them, and this gather.
@compute @workgroup_size(LIST_GROUP)
fn main_list(@builtin(workgroup_id) group: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>, @builtin(local_invocation_index) l: u32) {
    let per_group = LIST_GROUP / VPL_LANES;
    let p = l % per_group;
    let lane = l / per_group;
    let bucket = group.z;
    let count = mirror_list[bucket];
    let stride = groups.x * groups.y * per_group;
    for (var first = (group.x + group.y * groups.x) * per_group; first < count; first += stride) {
        let slot = first + p;
        let inside = slot < count;
        var pixel = 0u;
        var sum = vec3<f32>(0.0);
        if (inside) {
            pixel = mirror_list[MAX_SUBSETS + bucket * mirror_bucket_size() + slot];
            sum = pixel_sum(pixel % params.low_width, pixel / params.low_width, lane, VPL_LANES);
        }
        list_sums[l] = vec4<f32>(sum, 0.0);
        workgroupBarrier();
        if (inside && lane == 0u) {
            // The lanes' sums in lane order.
            var total = vec3<f32>(0.0);
            for (var k = 0u; k < VPL_LANES; k += 1u) {
                total += list_sums[k * per_group + p].xyz;
            }
            store_irradiance(pixel % params.low_width, pixel / params.low_width, total);
        }
        // The next pixels' sums overwrite these.
        workgroupBarrier();
    }
}
