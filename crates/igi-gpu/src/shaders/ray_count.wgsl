// ray_count.wgsl: rays traced per kind, counted into the scene's ray_counters in the
// extra frame `Renderer::count_rays` renders for the bench (timed frames never count).

#import scene
#import params

// Kinds of rays: their counters in ray_counters, in the order `Renderer::count_rays`
// returns them.
const RAY_PRIMARY: u32 = 0u;
const RAY_MIRROR: u32 = 1u;
const RAY_LIGHT_SHADOW: u32 = 2u;
const RAY_VPL_SHADOW: u32 = 3u;
const RAY_PARTICLE: u32 = 4u;

// Add n rays of `kind` to the counters when this frame counts rays.
fn count_rays(kind: u32, n: u32) {
    if (params.count_rays != 0u && n > 0u) {
        atomicAdd(&ray_counters[kind], n);
    }
}
