// vpl.wgsl: VPL shooting (paper section 4, first stage). One thread per light path: a
// particle leaves a point light (chosen in proportion to power), and at every hit on a
// surface with a diffuse part stores a VPL carrying the particle's flux; it continues by
// Russian roulette on the mean albedo (diffuse bounce or mirror reflection), up to B
// stored VPLs. Path i is driven by the scrambled Halton sequence at index
// halton_base + i: dimension 0 picks the light, 1-2 the emission direction, then 3 per
// segment (direction u, v; continuation).
// The per-path slots are compacted into a dense, deterministic VPL list: by the shooting
// workgroup itself when one workgroup holds every path (`shoot_and_compact`, the paper's
// 30-180 VPLs: a dispatch of its own cost the frame a stage boundary), else by a second
// entry point (`compact`) after `shoot`.

#import constants
#import params
#import scene
#import traverse
#import surface
#import sampling
#import ray_count
#import vpl_record

@group(1) @binding(1) var<storage, read_write> vpl_slots: array<Vpl>;
@group(1) @binding(2) var<storage, read_write> vpls: array<Vpl>;
@group(1) @binding(3) var<storage, read_write> vpl_header: VplHeader;
// Digit permutations of the scrambled Halton sequence: PRIMES[d] entries for dimension
// d, concatenated (igi_core::sampling::DigitPermutations).
@group(1) @binding(4) var<storage, read> halton_perms: array<u32>;

const PRIMES = array<u32, 64>(2u, 3u, 5u, 7u, 11u, 13u, 17u, 19u, 23u, 29u, 31u, 37u, 41u, 43u, 47u, 53u, 59u, 61u, 67u, 71u, 73u, 79u, 83u, 89u, 97u, 101u, 103u, 107u, 109u, 113u, 127u, 131u, 137u, 139u, 149u, 151u, 157u, 163u, 167u, 173u, 179u, 181u, 191u, 193u, 197u, 199u, 211u, 223u, 227u, 229u, 233u, 239u, 241u, 251u, 257u, 263u, 269u, 271u, 277u, 281u, 283u, 293u, 307u, 311u);

// Sum of the primes before each dimension: where its permutation starts.
const PERMUTATION_OFFSETS = array<u32, 64>(0u, 2u, 5u, 10u, 17u, 28u, 41u, 58u, 77u, 100u, 129u, 160u, 197u, 238u, 281u, 328u, 381u, 440u, 501u, 568u, 639u, 712u, 791u, 874u, 963u, 1060u, 1161u, 1264u, 1371u, 1480u, 1593u, 1720u, 1851u, 1988u, 2127u, 2276u, 2427u, 2584u, 2747u, 2914u, 3087u, 3266u, 3447u, 3638u, 3831u, 4028u, 4227u, 4438u, 4661u, 4888u, 5117u, 5350u, 5589u, 5830u, 6081u, 6338u, 6601u, 6870u, 7141u, 7418u, 7699u, 7982u, 8275u, 8582u);

// The largest f32 below 1: where the radical inverse is clamped.
const ONE_MINUS_EPSILON: f32 = 0.99999994;

// Scrambled radical inverse, as igi_core::sampling::scrambled_radical_inverse computes it:
// every digit of the index (and the zeros past its last one, up to base^k >= 2^32)
// through the dimension's permutation.
fn halton(dim_in: u32, index: u32) -> f32 {
    let dim = dim_in % 64u;
    let base = PRIMES[dim];
    let offset = PERMUTATION_OFFSETS[dim];
    let inv_base = 1.0 / f32(base);
    var n = index;
    var weight = inv_base;
    var value = 0.0;
    var reach = 1.0;
    while (reach < 4294967296.0) {
        let next = n / base;
        let digit = n - next * base;
        value += f32(halton_perms[offset + digit]) * weight;
        weight *= inv_base;
        reach *= f32(base);
        n = next;
    }
    return min(value, ONE_MINUS_EPSILON);
}

const SHOOT_GROUP: u32 = 64u;

fn mean3(v: vec3<f32>) -> f32 {
    return (v.x + v.y + v.z) / 3.0;
}

// No light chosen: none emits.
const NO_LIGHT: u32 = 0xffffffffu;

// Clamped: shoot_path asks for NO_LIGHT's weight too (and then shoots nothing).
fn light_power_weight(l: u32) -> f32 {
    let i = lights[min(l, params.light_count - 1u)].intensity;
    return 4.0 * PI * (i.x + i.y + i.z);
}

@compute @workgroup_size(64)
fn shoot(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let path = gid.x + gid.y * groups.x * SHOOT_GROUP;
    if (path < params.path_count) {
        shoot_path(path);
    }
}

// Shoots light path `path` into its B slots (empty ones marked so) and returns how many
// VPLs it stored.
fn shoot_path(path: u32) -> u32 {
    let index = params.halton_base + path;
    let first_slot = path * params.bounces;

    // Light choice in proportion to power: flux = Phi_l / (p_l M) = total / M for grey
    // lights, and exact per channel for coloured ones.
    // A light of zero power is never chosen, not even when rounding runs u past the
    // last weight (then the last light that emits is): its p_light of 0 made the flux
    // 0 / 0, NaN in every pixel. When no light emits, the path stores nothing.
    var u = halton(0u, index) * params.light_power_sum;
    var chosen = NO_LIGHT;
    for (var l = 0u; l < params.light_count; l += 1u) {
        let w = light_power_weight(l);
        if (w > 0.0) {
            chosen = l;
            if (u < w) {
                break;
            }
        }
        u -= w;
    }
    let light = lights[min(chosen, params.light_count - 1u)];
    let p_light = light_power_weight(chosen) / params.light_power_sum;
    var flux = 4.0 * PI * light.intensity / (p_light * f32(params.path_count));

    var origin = light.position;
    var dir = uniform_sphere(halton(1u, index), halton(2u, index));
    var stored = 0u;
    var dim = 3u;
    // Mirror reflections store nothing, so the walk is bounded separately.
    let max_segments = select(params.bounces + params.mirror_depth, 0u, chosen == NO_LIGHT);
    var stack: WalkStack;
    var traced = 0u;
    for (var segment = 0u; segment < max_segments; segment += 1u) {
        let hit = trace_closest(&stack, origin, dir, INFINITY);
        traced += 1u;
        if (hit.tri == NO_HIT) {
            break;
        }
        // Level 0: a particle is a point sample, whose albedos average to the texture's
        // over the paths.
        let s = surface_at(origin, dir, hit, 0.0);
        if (max(s.diffuse.x, max(s.diffuse.y, s.diffuse.z)) > 0.0) {
            var v: Vpl;
            v.position = s.position;
            v.valid = 1u;
            v.normal = s.shading_normal;
            v.bounce = stored + 1u;
            v.flux = flux;
            v.albedo = s.diffuse;
            vpl_slots[first_slot + stored] = v;
            stored += 1u;
            if (stored == params.bounces) {
                break;
            }
        }
        // Continue diffusely with probability mean(rho_d), by the mirror with mean(rho_m).
        let p_diffuse = mean3(s.diffuse);
        let p_mirror = mean3(s.mirror);
        let choice = halton(dim + 2u, index);
        if (choice < p_diffuse) {
            let local = cosine_hemisphere(halton(dim, index), halton(dim + 1u, index));
            let n = s.shading_normal;
            dir = local.x * basis_t(n) + local.y * basis_b(n) + local.z * n;
            if (dot(dir, s.geometric_normal) <= 0.0) {
                break;
            }
            flux *= s.diffuse / p_diffuse;
        } else if (choice < p_diffuse + p_mirror) {
            dir = reflect(dir, s.shading_normal);
            if (dot(dir, s.geometric_normal) <= 0.0) {
                dir = reflect(dir, s.geometric_normal);
            }
            flux *= s.mirror / p_mirror;
        } else {
            break;
        }
        origin = offset_ray_origin(s.position, s.geometric_normal, params.ray_offset_floor);
        dim += 3u;
    }
    count_rays(RAY_PARTICLE, traced);
    // Slots this path did not fill are marked empty for compaction.
    for (var k = stored; k < params.bounces; k += 1u) {
        vpl_slots[first_slot + k].valid = 0u;
    }
    return stored;
}

const COMPACT_GROUP: u32 = 256u;
var<workgroup> chunk_counts: array<u32, 256>;

// Thread t's place in a list to which each thread of the workgroup, in thread order,
// adds `count` entries: the sum of the counts of the threads before it. Has a workgroup
// barrier: call it from uniform control flow.
fn offset_before(t: u32, count: u32) -> u32 {
    chunk_counts[t] = count;
    workgroupBarrier();
    var offset = 0u;
    for (var i = 0u; i < t; i += 1u) {
        offset += chunk_counts[i];
    }
    return offset;
}

// The VPL list's header, written by the workgroup's last thread, `end` its place after
// its own VPLs: the list's length.
fn write_header(t: u32, end: u32) {
    if (t == COMPACT_GROUP - 1u) {
        vpl_header.count = end;
        vpl_header.path_count = params.path_count;
        vpl_header.slots = params.path_count * params.bounces;
    }
}

// One workgroup: each thread counts the valid slots of a contiguous chunk, a prefix sum
// over the chunk counts gives each chunk's output offset, then each thread copies its
// chunk. Slot order is kept, so the VPL list is the same on every run.
@compute @workgroup_size(256)
fn compact(@builtin(local_invocation_index) t: u32) {
    let slots = params.path_count * params.bounces;
    let chunk = (slots + COMPACT_GROUP - 1u) / COMPACT_GROUP;
    let begin = min(t * chunk, slots);
    let end = min(begin + chunk, slots);
    var count = 0u;
    for (var s = begin; s < end; s += 1u) {
        count += vpl_slots[s].valid;
    }
    var offset = offset_before(t, count);
    for (var s = begin; s < end; s += 1u) {
        if (vpl_slots[s].valid != 0u) {
            vpls[offset] = vpl_slots[s];
            offset += 1u;
        }
    }
    write_header(t, offset);
}

// Shooting and compaction in one workgroup, for up to COMPACT_GROUP paths: thread t
// shoots path t, then copies its own VPLs to the list after those of the paths before
// it, so the list is the one `compact` makes. A thread reads back only the slots it
// wrote itself.
@compute @workgroup_size(256)
fn shoot_and_compact(@builtin(local_invocation_index) t: u32) {
    var stored = 0u;
    if (t < params.path_count) {
        stored = shoot_path(t);
    }
    let offset = offset_before(t, stored);
    let first_slot = t * params.bounces;
    for (var k = 0u; k < stored; k += 1u) {
        vpls[offset + k] = vpl_slots[first_slot + k];
    }
    write_header(t, offset + stored);
}
