// params.wgsl: the frame's parameters (FrameParams, documented field by field in
// layout.rs), bound at binding 0 of group 1 in every pass.

struct FrameParams {
    cam_eye: vec3<f32>, width: u32,
    cam_forward: vec3<f32>, height: u32,
    cam_right: vec3<f32>, tan_half_fov_y: f32,
    cam_up: vec3<f32>, aspect: f32,
    total_power: vec3<f32>, light_count: u32,
    path_count: u32, bounces: u32, min_dist: f32, geometry_bound: u32,
    mirror_depth: u32, halton_base: u32, output: u32, light_power_sum: f32,
    // The indirect term's resolution (full / downsample, rounded up) and its filters.
    low_width: u32, low_height: u32, downsample: u32, interleave_n: u32,
    interleave_m: u32, pattern: u32, seed: u32, accumulate_index: u32,
    upsample_sigma: f32, normal_power: f32, upsample_depth: u32, depth_threshold: f32,
    normal_threshold: f32, jitter_x: f32, jitter_y: f32, count_rays: u32,
    depth_scale: f32, ray_offset_floor: f32, _pad1: u32, _pad2: u32,
}

// A uniform buffer on GPUs; on software adapters `shader::compose_for` makes each
// uniform declaration a read-only storage buffer (lavapipe recompiled shaders that
// branch on uniform values each time their pipeline was bound: see `ParamsBinding`).
@group(1) @binding(0) var<uniform> params: FrameParams;
