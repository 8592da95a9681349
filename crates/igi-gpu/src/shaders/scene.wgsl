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

// A material (layout.rs's GpuMaterial documents each field): its colours, and how its
// base colour texture, vertex colours and alpha mask modulate them (texture.wgsl).
struct Material {
    diffuse: vec3<f32>, texture: u32,
    mirror: vec3<f32>, flags: u32,
    uv_row0: vec3<f32>, alpha_factor: f32,
    uv_row1: vec3<f32>, alpha_cutoff: f32,
}

// Texture coordinates and linear RGBA colours of a triangle's corners (BVH order), read
// only for materials with a texture or vertex colours; each colour is two
// pack2x16unorm words (rg, ba).
struct TriAttributes {
    uv01: vec4<f32>,
    uv2: vec2<f32>, color0: vec2<u32>,
    color1: vec2<u32>, color2: vec2<u32>,
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
// The textures: a header of 4 words per texture (width, height, mip levels, the word
// where its level 0 starts), then the texels, one RGBA8 word each (red in the low byte),
// each texture's levels one after the other, rows from the top (layout.rs,
// texture_words). At least one header, so the buffer is never empty.
@group(0) @binding(6) var<storage, read> textures: array<u32>;
// One row per triangle in BVH order where some material reads them, else one.
@group(0) @binding(7) var<storage, read> tri_attributes: array<TriAttributes>;
