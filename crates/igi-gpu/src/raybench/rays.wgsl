// rays.wgsl: the ray-tracing layer alone (`igi bench rays`): one thread per ray of a ray
// file (igi_core::rays: origin, tmin, direction, tmax), any-hit or closest-hit.

// params: binding 0 of group 1, as in every pass's layout (unused here).
#import params
#import traverse

@group(1) @binding(1) var<storage, read> rays: array<vec4<f32>>;
// any: 1 occluded / 0 free per ray; closest: (triangle slot or NO_HIT, bits of t) per ray.
@group(1) @binding(2) var<storage, read_write> results: array<u32>;

const RAY_GROUP: u32 = 64u;

fn ray_index(gid: vec3<u32>, groups: vec3<u32>) -> u32 {
    return gid.x + gid.y * groups.x * RAY_GROUP;
}

// One walk with a stack of its own. The stack is declared in these functions rather than
// in the entry points: declared in the entry point, the very same walks ran slower on
// NVIDIA's driver, for no reason its tools show.
fn ray_any_hit(origin: vec3<f32>, dir: vec3<f32>, tmax: f32) -> bool {
    var stack: WalkStack;
    return trace_any(&stack, origin, dir, tmax);
}

fn ray_closest_hit(origin: vec3<f32>, dir: vec3<f32>, tmax: f32) -> Hit {
    var stack: WalkStack;
    return trace_closest(&stack, origin, dir, tmax);
}

@compute @workgroup_size(64)
fn any_hit(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let i = ray_index(gid, groups);
    if (2u * i + 1u >= arrayLength(&rays)) {
        return;
    }
    let a = rays[2u * i];
    let b = rays[2u * i + 1u];
    results[i] = select(0u, 1u, ray_any_hit(a.xyz, b.xyz, b.w));
}

@compute @workgroup_size(64)
fn closest_hit(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let i = ray_index(gid, groups);
    if (2u * i + 1u >= arrayLength(&rays)) {
        return;
    }
    let a = rays[2u * i];
    let b = rays[2u * i + 1u];
    let hit = ray_closest_hit(a.xyz, b.xyz, b.w);
    results[2u * i] = hit.tri;
    results[2u * i + 1u] = bitcast<u32>(hit.t);
}
