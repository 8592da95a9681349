// gbuffer.wgsl: the G-buffer of the primary hits and the mirror record, field by field:
// what each vec4 holds, and the functions that write and read its w components (no
// pass reads a .w of these records itself). The direct pass writes both, clearing them
// in its first walk of every frame.
//
// G-buffer, one record per full-resolution pixel, from the primary hit:
// - position:  xyz the hit point; w 1 where the primary ray hit a surface, else 0
//   (pack_position, has_surface).
// - normal:    xyz the unit shading normal; w the hit's distance t along the primary ray
//   (positive: traverse.wgsl takes hits at t > 0), 0 where there is no hit (pack_normal,
//   normal_depth, normal_has_surface): the depth the filters compare.
// - geometric: xyz the unit geometric normal; w 0, unused (pack_geometric).
// - albedo:    xyz the diffuse albedo; w 0, unused (pack_albedo).
//
// Mirror record, one per full-resolution pixel, from the first diffuse hit of the
// pixel's mirror chain (the hit the mirror indirect stage gathers at), in the same
// layout as the G-buffer, so that the indirect pass and the discontinuity filter run
// over either:
// - position:  as the G-buffer's: w 1 where the pixel has such a hit.
// - normal:    xyz the shading normal; w the length of the chain up to the hit (the sum
//   of its segments' t), the depth the mirror discontinuity filter compares.
// - geometric: as the G-buffer's.
// - weight:    xyz the chain's throughput times albedo / pi there; w 1 where there is
//   one, else 0 (pack_weight, has_weight).

#import params

// A record with nothing in it (no hit): every component 0.
fn empty_record() -> vec4<f32> {
    return vec4<f32>(0.0);
}

// The position record of hit point p.
fn pack_position(p: vec3<f32>) -> vec4<f32> {
    return vec4<f32>(p, 1.0);
}

// Whether a position record holds a hit.
fn has_surface(position: vec4<f32>) -> bool {
    return position.w > 0.0;
}

// The normal record of shading normal n at depth `depth` (a distance along the ray or
// chain, positive).
fn pack_normal(n: vec3<f32>, depth: f32) -> vec4<f32> {
    return vec4<f32>(n, depth);
}

// The depth of a normal record.
fn normal_depth(normal: vec4<f32>) -> f32 {
    return normal.w;
}

// Whether a normal record holds a hit (its depth is positive): where only the normal is
// read, this saves a read of the position record.
fn normal_has_surface(normal: vec4<f32>) -> bool {
    return normal.w > 0.0;
}

// The geometric normal record of unit normal ng.
fn pack_geometric(ng: vec3<f32>) -> vec4<f32> {
    return vec4<f32>(ng, 0.0);
}

// The albedo record of diffuse albedo rho.
fn pack_albedo(rho: vec3<f32>) -> vec4<f32> {
    return vec4<f32>(rho, 0.0);
}

// The mirror record's weight record.
fn pack_weight(weight: vec3<f32>) -> vec4<f32> {
    return vec4<f32>(weight, 1.0);
}

// Whether a weight record holds a mirrored hit.
fn has_weight(weight: vec4<f32>) -> bool {
    return weight.w > 0.0;
}

// The full-resolution pixel whose G-buffer sample stands for low-resolution pixel
// (x, y) of the indirect term: the centre of its downsample x downsample block.
fn representative_pixel(x: u32, y: u32) -> u32 {
    let half = params.downsample / 2u;
    let fx = min(x * params.downsample + half, params.width - 1u);
    let fy = min(y * params.downsample + half, params.height - 1u);
    return fy * params.width + fx;
}
