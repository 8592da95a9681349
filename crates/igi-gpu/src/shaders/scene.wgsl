// scene.wgsl: the scene as every pass sees it (bind group 0). Layouts are documented
// field by field in `layout.rs` (Rust side), which a test checks against this file.

// One interior node of the binary BVH: the boxes of both children, so that one 64-byte
// fetch decides which children a ray visits and in which order.
// A child with count == 0 is an interior node at nodes[index]; a child with count > 0 is a
// leaf of `count` triangles starting at triangle `index` (of the BVH-ordered arrays).
struct BvhNode {
    a_min: vec3<f32>, a_index: u32,
    a_max: vec3<f32>, a_count: u32,
    b_min: vec3<f32>, b_index: u32,
    b_max: vec3<f32>, b_count: u32,
}

// Shading data of one triangle (BVH order), read only at hits.
struct TriShading {
    n0: vec3<f32>, material: u32,
    n1: vec3<f32>, _pad1: u32,
    n2: vec3<f32>, _pad2: u32,
}

struct Material {
    diffuse: vec3<f32>, _pad0: f32,
    mirror: vec3<f32>, _pad1: f32,
}

struct PointLight {
    position: vec3<f32>, _pad0: f32,
    intensity: vec3<f32>, _pad1: f32,
}

@group(0) @binding(0) var<storage, read> bvh_nodes: array<BvhNode>;
// Three rows per triangle, in BVH order: the x, the y and the z coordinates of its
// vertices 0, 1 and 2 (w unused), so that the triangle test reads the rows of its ray's
// Woop axes by index (igi_core::bvh::Bvh::tri_rows).
@group(0) @binding(1) var<storage, read> tri_rows: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> tri_shading: array<TriShading>;
@group(0) @binding(3) var<storage, read> materials: array<Material>;
@group(0) @binding(4) var<storage, read> lights: array<PointLight>;
// Rays traced per kind (ray_count.wgsl's RAY_* indices), counted only when
// params.count_rays is set: one atomic add per invocation and kind, in an untimed frame.
// Entry CUT_WALKS counts walks a software adapter cut short (traverse.wgsl), always.
@group(0) @binding(5) var<storage, read_write> ray_counters: array<atomic<u32>, 8>;
const CUT_WALKS: u32 = 7u;
