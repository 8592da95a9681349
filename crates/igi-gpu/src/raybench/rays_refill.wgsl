// rays_refill.wgsl: the any-hit query over a ray file for incoherent batches, with the
// bindings and kernels of rays.wgsl (`RaySchedule::Refill` of raybench.rs). Aila and
// Laine's persistent threads with dynamic ray fetch ("Understanding the Efficiency of Ray
// Traversal on GPUs", 2009): a lane walks one node per loop iteration, and once enough
// lanes of its subgroup have finished their rays, each idle lane takes the next ray of
// the batch from a counter. With one ray per thread (any_hit), a warp runs as long as its
// longest walk, which for random segments is several times its lanes' average walk.
//
// Which ray a lane takes comes from its own atomic add: the subgroup's ballot only says
// when to refill, so the answers never depend on how the driver keeps lanes together
// (a leader's add for the whole subgroup, handed out by subgroupBroadcastFirst after a
// branch, relies on the lanes meeting again after it; it was no faster on NVIDIA's
// driver, which combines the lanes' adds itself).
//
// The answers are the walk's of trace_any (same functions, same order), ray for ray:
// change any_hit_lanes with walk_any (tests/ray_schedules.rs compares both schedules with
// the CPU twin, igi_core's Bvh::trace_any). The walk is written again here, not shared
// with the gathers', whose schedule by the driver swings with trivial rewrites.
// Coherent batches (neighbouring rays walk alike, as the renderer's VPL-major
// shadow rays do) trace faster with one ray per thread: a refilled lane walks apart from
// the lanes still on their old rays.

#import scene
#import traverse
#import rays

// The next unassigned ray of the batch; zeroed before each dispatch.
@group(1) @binding(3) var<storage, read_write> ray_counter: atomic<u32>;

// Idle lanes refill once at least REFILL_IDLE / 64 of their subgroup's lanes are idle
// (or all of its active ones). Three quarters measured best on random segments, among
// thresholds from one lane to nearly all of them.
override REFILL_IDLE: u32 = 48u;

fn ballot_count(b: vec4<u32>) -> u32 {
    return countOneBits(b.x) + countOneBits(b.y) + countOneBits(b.z) + countOneBits(b.w);
}

// The walk of walk_any (trace_any: no t pad, far ends scaled by BOX_TFAR_SCALE), one
// node per iteration of a loop that also hands out rays; a lane leaves the loop once it
// is idle and the batch is handed out.
fn any_hit_lanes(stack: ptr<function, WalkStack>, subgroup_size: u32) {
    let ray_count = arrayLength(&rays) / 2u;
    var ray = NO_HIT;
    var more = true;
    var r: TraceRay;
    var tmax = 0.0;
    var node = 0u;
    var sp = 0u;
    loop {
        let idle = ray == NO_HIT;
        if (idle && !more) {
            break;
        }
        let idle_lanes = ballot_count(subgroupBallot(idle));
        let active_lanes = ballot_count(subgroupBallot(true));
        if (idle && (64u * idle_lanes >= REFILL_IDLE * subgroup_size || idle_lanes == active_lanes)) {
            let i = atomicAdd(&ray_counter, 1u);
            more = i < ray_count;
            if (more) {
                let a = rays[2u * i];
                let b = rays[2u * i + 1u];
                if (all(b.xyz == vec3<f32>(0.0))) {
                    results[i] = 0u;
                } else {
                    ray = i;
                    r = make_ray(a.xyz, b.xyz, 0.0);
                    tmax = b.w;
                    node = 0u;
                    sp = 0u;
                }
            }
        }
        if (ray == NO_HIT) {
            continue;
        }
        let n = bvh_nodes[node];
        let hit_a = box_hit(n.a_min, n.a_max, r, tmax, BOX_TFAR_SCALE);
        let hit_b = box_hit(n.b_min, n.b_max, r, tmax, BOX_TFAR_SCALE);
        var next = NO_HIT;
        var found = false;
        if (hit_a) {
            if (n.a_count > 0u) {
                found = leaf_any(n.a_index, n.a_count, r, tmax, false);
            } else {
                next = n.a_index;
            }
        }
        if (hit_b && !found) {
            if (n.b_count > 0u) {
                found = leaf_any(n.b_index, n.b_count, r, tmax, false);
            } else if (next == NO_HIT) {
                next = n.b_index;
            } else {
                (*stack)[sp] = n.b_index;
                sp += 1u;
            }
        }
        if (!found && next == NO_HIT && sp > 0u) {
            sp -= 1u;
            next = (*stack)[sp];
        }
        if (found || next == NO_HIT) {
            results[ray] = select(0u, 1u, found);
            ray = NO_HIT;
        } else {
            node = next;
        }
    }
}

// Dispatched with at most REFILL_GROUPS (raybench.rs) workgroups, whatever the batch size.
@compute @workgroup_size(64)
fn any_hit_refill(@builtin(subgroup_size) subgroup_size: u32) {
    var stack: WalkStack;
    any_hit_lanes(&stack, subgroup_size);
}
