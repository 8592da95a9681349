// texture.wgsl: base colour textures, vertex colours and alpha masks at a hit. The
// texels live in one storage buffer (scene.wgsl's `textures`) and are filtered here, the
// same way on every adapter; igi_core::texture is the CPU twin, function by function.

#import scene

const NO_TEXTURE: u32 = 0xffffffffu;

// Whether the scene has textures or vertex colours (SURFACE_MAPS) and alpha masks
// (ALPHA_MASKS): the passes that trace are built with what their scene needs
// (passes::SurfaceMaps), so that a scene runs without the code it does not use.
override SURFACE_MAPS: bool = true;
override ALPHA_MASKS: bool = true;

// Material.flags bits (layout.rs: material_flags).
const MAT_VERTEX_COLORS: u32 = 1u;
const MAT_ALPHA_TESTED: u32 = 2u;
// Wrap modes at bits 2-3 (s) and 4-5 (t): 0 repeat, 1 clamp to edge, 2 mirrored repeat.
const WRAP_REPEAT: u32 = 0u;
const WRAP_CLAMP: u32 = 1u;
const MAT_MAG_LINEAR: u32 = 64u;
const MAT_MIN_LINEAR: u32 = 128u;
const MAT_MIPMAPS: u32 = 256u;
const MAT_MIP_LINEAR: u32 = 512u;
// Header word 2: the level count, and this bit where colours are sRGB-encoded.
const TEX_SRGB: u32 = 256u;

fn srgb_to_linear(c: f32) -> f32 {
    return select(pow((c + 0.055) / 1.055, 2.4), c / 12.92, c <= 0.04045);
}

fn decode_texel(word: u32, srgb: bool) -> vec4<f32> {
    let v = unpack4x8unorm(word);
    if (srgb) {
        return vec4<f32>(srgb_to_linear(v.x), srgb_to_linear(v.y), srgb_to_linear(v.z), v.w);
    }
    return v;
}

fn wrap_index(i: i32, n: u32, wrap: u32) -> u32 {
    let m = i32(n);
    if (wrap == WRAP_CLAMP) {
        return u32(clamp(i, 0, m - 1));
    }
    if (wrap == WRAP_REPEAT) {
        return u32(((i % m) + m) % m);
    }
    let k = ((i % (2 * m)) + 2 * m) % (2 * m);
    return u32(select(2 * m - 1 - k, k, k < m));
}

// One period of the image, so that the coordinate stays exact in f32 (CPU: reduce).
fn reduce(x: f32, n: u32) -> f32 {
    let period = 2.0 * f32(n);
    return x - floor(x / period) * period;
}

// One mip level: its size and the word of its first texel.
struct TexLevel {
    width: u32,
    height: u32,
    first: u32,
}

fn texture_level(tex: u32, level: u32) -> TexLevel {
    let w = textures[4u * tex];
    let h = textures[4u * tex + 1u];
    var first = textures[4u * tex + 3u];
    for (var l = 0u; l < level; l += 1u) {
        first += max(w >> l, 1u) * max(h >> l, 1u);
    }
    return TexLevel(max(w >> level, 1u), max(h >> level, 1u), first);
}

// Texel (x, y) of a level, indices wrapped already.
fn texel_at(level: TexLevel, x: u32, y: u32, srgb: bool) -> vec4<f32> {
    return decode_texel(textures[level.first + y * level.width + x], srgb);
}

fn sample_level(level: TexLevel, srgb: bool, uv: vec2<f32>, linear: bool, wrap_s: u32, wrap_t: u32) -> vec4<f32> {
    let x = reduce(uv.x * f32(level.width), level.width);
    let y = reduce(uv.y * f32(level.height), level.height);
    if (!linear) {
        let i = wrap_index(i32(floor(x)), level.width, wrap_s);
        let j = wrap_index(i32(floor(y)), level.height, wrap_t);
        return texel_at(level, i, j, srgb);
    }
    let fx = x - 0.5;
    let fy = y - 0.5;
    let fi = floor(fx);
    let fj = floor(fy);
    let a = fx - fi;
    let b = fy - fj;
    // Each axis's two indices wrapped once, for the four taps (integer remainders are
    // slow on GPUs).
    let i0 = wrap_index(i32(fi), level.width, wrap_s);
    let i1 = wrap_index(i32(fi) + 1, level.width, wrap_s);
    let j0 = wrap_index(i32(fj), level.height, wrap_t);
    let j1 = wrap_index(i32(fj) + 1, level.height, wrap_t);
    let top = texel_at(level, i0, j0, srgb) * (1.0 - a) + texel_at(level, i1, j0, srgb) * a;
    let bottom = texel_at(level, i0, j1, srgb) * (1.0 - a) + texel_at(level, i1, j1, srgb) * a;
    return top * (1.0 - b) + bottom * b;
}

// The texture's value at `uv` for a footprint of `lod` (log2 of its side in level-0
// texels; at most 0 is magnification), with the material's sampler (CPU: sample).
fn sample_texture(tex: u32, flags: u32, uv: vec2<f32>, lod: f32) -> vec4<f32> {
    let info = textures[4u * tex + 2u];
    let levels = info & 255u;
    let srgb = (info & TEX_SRGB) != 0u;
    let wrap_s = (flags >> 2u) & 3u;
    let wrap_t = (flags >> 4u) & 3u;
    let min_linear = (flags & MAT_MIN_LINEAR) != 0u;
    if (!(lod > 0.0) || (flags & MAT_MIPMAPS) == 0u) {
        let linear = select((flags & MAT_MAG_LINEAR) != 0u, min_linear, lod > 0.0);
        return sample_level(texture_level(tex, 0u), srgb, uv, linear, wrap_s, wrap_t);
    }
    let top = f32(levels - 1u);
    let l = min(lod, top);
    if ((flags & MAT_MIP_LINEAR) == 0u) {
        return sample_level(texture_level(tex, u32(floor(l + 0.5))), srgb, uv, min_linear, wrap_s, wrap_t);
    }
    let l0 = floor(l);
    let f = l - l0;
    let i0 = u32(l0);
    let i1 = min(i0 + 1u, levels - 1u);
    let a = sample_level(texture_level(tex, i0), srgb, uv, min_linear, wrap_s, wrap_t);
    let b = sample_level(texture_level(tex, i1), srgb, uv, min_linear, wrap_s, wrap_t);
    return a * (1.0 - f) + b * f;
}

fn unpack_color(c: vec2<u32>) -> vec4<f32> {
    return vec4<f32>(unpack2x16unorm(c.x), unpack2x16unorm(c.y));
}

// Texture coordinates at barycentrics (u, v) of BVH slot `tri`, before the transform.
fn attribute_uv(a: TriAttributes, u: f32, v: f32) -> vec2<f32> {
    return (1.0 - u - v) * a.uv01.xy + u * a.uv01.zw + v * a.uv2;
}

fn transformed_uv(m: Material, uv: vec2<f32>) -> vec2<f32> {
    let p = vec3<f32>(uv, 1.0);
    return vec2<f32>(dot(m.uv_row0, p), dot(m.uv_row1, p));
}

// log2 of the side, in level-0 texels, of the footprint of a ray cone `cone_width` wide
// where it meets slot `tri` at an angle of cosine `cos_theta` (Akenine-Moeller et al.
// 2019, "Texture Level of Detail Strategies for Real-Time Ray Tracing"): the triangle's
// texels per unit of length, sqrt(texel area / world area), times the width stretched
// by the slant. A width of 0 (particles) gives level 0.
fn cone_lod(tex: u32, m: Material, a: TriAttributes, v0: vec3<f32>, v1: vec3<f32>, v2: vec3<f32>, cone_width: f32, cos_theta: f32) -> f32 {
    if (cone_width <= 0.0) {
        return 0.0;
    }
    let size = vec2<f32>(f32(textures[4u * tex]), f32(textures[4u * tex + 1u]));
    let e1 = (a.uv01.zw - a.uv01.xy) * size;
    let e2 = (a.uv2 - a.uv01.xy) * size;
    let texel_area = abs(e1.x * e2.y - e1.y * e2.x);
    let world_area = length(cross(v1 - v0, v2 - v0));
    let stretch = sqrt(abs(m.uv_row0.x * m.uv_row1.y - m.uv_row0.y * m.uv_row1.x));
    let footprint = cone_width * sqrt(texel_area / world_area) * stretch / max(abs(cos_theta), 1e-4);
    return log2(footprint);
}

// The colour multiplier (rgb) and opacity (a) of material `m` at barycentrics (u, v) of
// a slot with attributes `a`: texture times vertex colours; `lod` as sample_texture's.
fn surface_color(m: Material, a: TriAttributes, u: f32, v: f32, lod: f32) -> vec4<f32> {
    var c = vec4<f32>(1.0);
    if ((m.flags & MAT_VERTEX_COLORS) != 0u) {
        c = (1.0 - u - v) * unpack_color(a.color0) + u * unpack_color(a.color1) + v * unpack_color(a.color2);
    }
    if (m.texture != NO_TEXTURE) {
        c *= sample_texture(m.texture, m.flags, transformed_uv(m, attribute_uv(a, u, v)), lod);
    }
    return c;
}

// Whether the point at barycentrics (u, v) of slot `tri`, of an alpha-tested material,
// is cut out: its opacity at level 0 is under the cutoff. Every ray kind asks this of
// the same level, so that what the camera sees is what casts shadows.
fn cut_out(tri: u32, u: f32, v: f32) -> bool {
    let m = materials[tri_shading[tri].material];
    let opacity = m.alpha_factor * surface_color(m, tri_attributes[tri], u, v, 0.0).w;
    return opacity < m.alpha_cutoff;
}
