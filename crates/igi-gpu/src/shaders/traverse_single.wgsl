// traverse_single.wgsl: trace_shadow_packet (traverse_packet.wgsl) for devices without
// subgroup operations: each ray traverses alone, with the same answers.

fn trace_shadow_packet(origin: vec3<f32>, dir: vec3<f32>, tmax: f32, boxes: bool, wants: bool) -> bool {
    if (!wants) {
        return false;
    }
    return trace_shadow(origin, dir, tmax, boxes);
}
