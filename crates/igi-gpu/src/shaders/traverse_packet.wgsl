// traverse_packet.wgsl: any-hit traversal of a subgroup's shadow rays as one packet, for
// rays that are coherent by construction: a warp of neighbouring pixels tracing to the
// same VPL or light (the gathering of paper section 4 with one thread per pixel). The
// paper traced each ray alone through OptiX; this is ours (docs/PERFORMANCE.md, attempt
// 20). All lanes of the subgroup walk the same nodes: a child is visited when the ray of
// any lane hits its box (subgroupAny), so node fetches are one address for the whole
// warp and the control flow never diverges between interior nodes. Each lane keeps
// whether its own ray hit every box on the way to the node (the stack's top bit) and
// tests a leaf's triangles only then, so it tests exactly the triangles that
// trace_shadow would: the answers are those of trace_shadow, bit for bit, whatever the
// rays, the subgroup size or the set of active lanes (a lane that leaves early only
// removes itself from later votes). Its CPU twin is therefore trace_shadow's
// (igi_core::bvh::traverse); crates/igi-gpu/tests/traverse_gpu.rs compares them.
//
// Composed after traverse.wgsl when the device has subgroup operations (shader.rs);
// traverse_single.wgsl stands in for it otherwise.

// Top bit of a stack entry: this lane's ray reached the node (hit all boxes above it).
const OWN_RAY: u32 = 0x80000000u;

// EXPERIMENT: 0 a first, 1 near first by the vote of lanes that hit both.
const PACKET_ORDER: u32 = 0u;

// Whether the segment origin + t dir, 0 < t < tmax, is occluded (trace_shadow), traced
// together with the calls of the other active lanes of the subgroup. Every lane of a
// subgroup must call it at the same time, also those with no ray to trace (`wants`
// false: they return false and only follow along).
fn trace_shadow_packet(origin: vec3<f32>, dir: vec3<f32>, tmax: f32, boxes: bool, wants: bool) -> bool {
    var own = wants && any(dir != vec3<f32>(0.0));
    let r = make_ray(origin, select(vec3<f32>(1.0), dir, own));
    if (!subgroupAny(own)) {
        return false;
    }
    var stack: array<u32, STACK_SIZE>;
    var sp = 0u;
    var node = 0u;
    loop {
        let n = bvh_nodes[node];
        let ta = box_near(n.a_min, n.a_max, r, tmax);
        let tb = box_near(n.b_min, n.b_max, r, tmax);
        let ha = ta >= 0.0 && own;
        let hb = tb >= 0.0 && own;
        if (ha && n.a_count > 0u) {
            if (leaf_any(n.a_index, n.a_count, r, tmax, boxes)) {
                return true;
            }
        }
        if (hb && n.b_count > 0u) {
            if (leaf_any(n.b_index, n.b_count, r, tmax, boxes)) {
                return true;
            }
        }
        // Interior children some lane's ray reached: the first visited, the other pushed.
        let va = subgroupAny(ha && n.a_count == 0u);
        let vb = subgroupAny(hb && n.b_count == 0u);
        var b_first = false;
        if (PACKET_ORDER == 1u) {
            let both = ha && hb;
            b_first = subgroupAdd(select(0u, 1u, both && tb < ta)) > subgroupAdd(select(0u, 1u, both && !(tb < ta)));
        }
        let v0 = select(va, vb, b_first);
        let v1 = select(vb, va, b_first);
        let i0 = select(n.a_index, n.b_index, b_first);
        let i1 = select(n.b_index, n.a_index, b_first);
        let h0 = select(ha, hb, b_first);
        let h1 = select(hb, ha, b_first);
        if (v0) {
            node = i0;
            own = h0;
            if (v1) {
                stack[sp] = i1 | select(0u, OWN_RAY, h1);
                sp += 1u;
            }
        } else if (v1) {
            node = i1;
            own = h1;
        } else {
            if (sp == 0u) {
                return false;
            }
            sp -= 1u;
            node = stack[sp] & ~OWN_RAY;
            own = (stack[sp] & OWN_RAY) != 0u;
        }
    }
    return false;
}
