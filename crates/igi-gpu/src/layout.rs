//! Host/GPU structs, `#[repr(C)]` + Pod, each documented field by field with byte offsets.
//! The WGSL declarations live in `shaders/scene.wgsl`, `shaders/params.wgsl` and
//! `shaders/vpl_record.wgsl` (and the display's in `passes/display/display.wgsl`); a test
//! (tests/shaders.rs) checks sizes and offsets against what naga computes for the WGSL.

use bytemuck::{Pod, Zeroable};

pub use igi_core::bvh::BvhNode;

/// Shading data of one triangle in BVH order (48 bytes), read only at hits.
/// | offset | field | |
/// |---|---|---|
/// | 0 | n0: vec3f | unit shading normal at vertex 0 |
/// | 12 | material: u32 | index into the materials array |
/// | 16 | n1: vec3f | vertex 1 |
/// | 28 | _pad1 | |
/// | 32 | n2: vec3f | vertex 2 |
/// | 44 | _pad2 | |
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct TriShading {
    pub n0: [f32; 3],
    pub material: u32,
    pub n1: [f32; 3],
    pub _pad1: u32,
    pub n2: [f32; 3],
    pub _pad2: u32,
}

/// A material (64 bytes; texture.wgsl reads the texture fields).
/// | offset | field | |
/// |---|---|---|
/// | 0 | diffuse: vec3f | diffuse albedo (times the texture and vertex colours at a hit) |
/// | 12 | texture: u32 | texture index, or `NO_TEXTURE` (0xffffffff) |
/// | 16 | mirror: vec3f | mirror reflectance (times the same) |
/// | 28 | flags: u32 | [`material_flags`]: vertex colours, alpha test, sampler |
/// | 32 | uv_row0: vec3f | texture transform: u' = dot(uv_row0, (u, v, 1)) |
/// | 44 | alpha_factor: f32 | opacity factor (times texture and vertex alpha) |
/// | 48 | uv_row1: vec3f | v' = dot(uv_row1, (u, v, 1)) |
/// | 60 | alpha_cutoff: f32 | alpha-tested points under this opacity are cut out |
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuMaterial {
    pub diffuse: [f32; 3],
    pub texture: u32,
    pub mirror: [f32; 3],
    pub flags: u32,
    pub uv_row0: [f32; 3],
    pub alpha_factor: f32,
    pub uv_row1: [f32; 3],
    pub alpha_cutoff: f32,
}

/// `GpuMaterial::texture` of a material without one.
pub const NO_TEXTURE: u32 = u32::MAX;

/// `GpuMaterial::flags` (texture.wgsl's MAT_* constants): bit 0 vertex colours, bit 1
/// alpha-tested, bits 2-3 and 4-5 the s and t wrap modes (0 repeat, 1 clamp to edge, 2
/// mirrored repeat), bit 6 linear magnification, bit 7 linear minification, bit 8
/// mipmaps, bit 9 linear between mip levels.
pub fn material_flags(m: &igi_core::scene::Material) -> u32 {
    use igi_core::texture::{Filter, Wrap};
    let wrap = |w: Wrap| match w {
        Wrap::Repeat => 0,
        Wrap::ClampToEdge => 1,
        Wrap::MirroredRepeat => 2,
    };
    let mut flags = u32::from(m.vertex_colors) | (u32::from(m.alpha_tested()) << 1);
    if let Some(t) = &m.texture {
        let s = &t.sampler;
        flags |= wrap(s.wrap_s) << 2 | wrap(s.wrap_t) << 4;
        flags |= u32::from(s.mag == Filter::Linear) << 6;
        flags |= u32::from(s.min == Filter::Linear) << 7;
        flags |= u32::from(s.mip.is_some()) << 8;
        flags |= u32::from(s.mip == Some(Filter::Linear)) << 9;
    }
    flags
}

impl GpuMaterial {
    pub fn of(m: &igi_core::scene::Material) -> GpuMaterial {
        use igi_core::scene::AlphaMode;
        let transform = m
            .texture
            .map_or(igi_core::texture::UvTransform::IDENTITY, |t| t.transform);
        GpuMaterial {
            diffuse: m.diffuse.to_array(),
            texture: m.texture.map_or(NO_TEXTURE, |t| t.texture),
            mirror: m.mirror.to_array(),
            flags: material_flags(m),
            uv_row0: transform.rows[0].to_array(),
            alpha_factor: m.alpha.factor,
            uv_row1: transform.rows[1].to_array(),
            alpha_cutoff: match m.alpha.mode {
                AlphaMode::Mask { cutoff } => cutoff,
                AlphaMode::Opaque => 0.0,
            },
        }
    }
}

/// Texture coordinates and vertex colours of one triangle in BVH order (48 bytes).
/// | offset | field | |
/// |---|---|---|
/// | 0 | uv01: vec4f | texture coordinates of corners 0 (xy) and 1 (zw) |
/// | 16 | uv2: vec2f | corner 2 |
/// | 24 | color0: vec2u | linear RGBA of corner 0 as two pack2x16unorm words (rg, ba) |
/// | 32 | color1: vec2u | corner 1 |
/// | 40 | color2: vec2u | corner 2 |
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuTriAttributes {
    pub uv01: [f32; 4],
    pub uv2: [f32; 2],
    pub color0: [u32; 2],
    pub color1: [u32; 2],
    pub color2: [u32; 2],
}

impl GpuTriAttributes {
    pub fn of(a: &igi_core::scene::TriAttributes) -> GpuTriAttributes {
        let [u0, u1, u2] = a.uv;
        // As WGSL's pack2x16unorm: clamped to [0, 1], times 65535, rounded.
        let unorm = |x: f32| (x.clamp(0.0, 1.0) * 65535.0).round() as u32;
        let color =
            |c: igi_core::Vec4| [unorm(c.x) | unorm(c.y) << 16, unorm(c.z) | unorm(c.w) << 16];
        GpuTriAttributes {
            uv01: [u0.x, u0.y, u1.x, u1.y],
            uv2: [u2.x, u2.y],
            color0: color(a.color[0]),
            color1: color(a.color[1]),
            color2: color(a.color[2]),
        }
    }
}

/// The words of the textures buffer (scene.wgsl's `textures`): a header of 4 words per
/// texture (width, height, level count with bit 8 set where colours are sRGB, the word of
/// its first texel), then each texture's levels in order, one RGBA8 word per texel (red in
/// the low byte, as unpack4x8unorm reads it). At least one (zero) header.
pub fn texture_words(textures: &[igi_core::texture::Texture]) -> Vec<u32> {
    let headers = 4 * textures.len().max(1);
    let texels: usize = textures.iter().map(|t| t.texel_count()).sum();
    let mut words = vec![0u32; headers];
    words.reserve(texels);
    for (i, t) in textures.iter().enumerate() {
        let first = words.len() as u32;
        words[4 * i..4 * i + 4].copy_from_slice(&[
            t.width,
            t.height,
            t.levels.len() as u32 | u32::from(t.srgb) << 8,
            first,
        ]);
        for level in &t.levels {
            words.extend(level.texels.iter().map(|&c| u32::from_le_bytes(c)));
        }
    }
    words
}

/// A point light (32 bytes): position at 0, intensity (W/sr, rgb) at 16.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuLight {
    pub position: [f32; 3],
    pub _pad0: f32,
    pub intensity: [f32; 3],
    pub _pad1: f32,
}

/// A virtual point light (64 bytes), as stored by VPL shooting.
/// | offset | field | |
/// |---|---|---|
/// | 0 | position: vec3f | on the surface |
/// | 12 | valid: u32 | 1 for a stored VPL (slots of paths that ended early stay 0) |
/// | 16 | normal: vec3f | unit, facing the side the particle came from |
/// | 28 | bounce: u32 | diffuse hit number along its path, 1 = first hit |
/// | 32 | flux: vec3f | power carried by the particle on arrival (W) |
/// | 44 | _pad0 | |
/// | 48 | albedo: vec3f | diffuse albedo at the VPL |
/// | 60 | _pad1 | |
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct Vpl {
    pub position: [f32; 3],
    pub valid: u32,
    pub normal: [f32; 3],
    pub bounce: u32,
    pub flux: [f32; 3],
    pub _pad0: f32,
    pub albedo: [f32; 3],
    pub _pad1: f32,
}

/// Parameters of one frame (uniform buffer, 192 bytes; a read-only storage buffer on
/// software adapters, see `shader::ParamsBinding`).
/// | offset | field | |
/// |---|---|---|
/// | 0 | cam_eye: vec3f | camera position |
/// | 12 | width: u32 | image width in pixels |
/// | 16 | cam_forward: vec3f | unit view direction |
/// | 28 | height: u32 | image height |
/// | 32 | cam_right: vec3f | unit, image x to the right |
/// | 44 | tan_half_fov_y: f32 | |
/// | 48 | cam_up: vec3f | unit, image y upward |
/// | 60 | aspect: f32 | width / height |
/// | 64 | total_power: vec3f | sum of 4 pi I over lights (W) |
/// | 76 | light_count: u32 | |
/// | 80 | path_count: u32 | light paths shot this frame (M) |
/// | 84 | bounces: u32 | VPL slots per path (B) |
/// | 88 | min_dist: f32 | bounding distance m of G |
/// | 92 | geometry_bound: u32 | 0 smoothstep, 1 clamp |
/// | 96 | mirror_depth: u32 | Whitted depth limit |
/// | 100 | halton_base: u32 | first Halton index of this frame's paths |
/// | 104 | output: u32 | 0 final, 1 direct, 2 indirect, 3 irradiance, 4 normals, 5 depth |
/// | 108 | light_power_sum: f32 | sum over lights of (r + g + b) of the power: light choice |
/// | 112 | low_width: u32 | width of the indirect term (width / downsample, rounded up) |
/// | 116 | low_height: u32 | |
/// | 120 | downsample: u32 | 1 = full resolution |
/// | 124 | interleave_n: u32 | VPL subsets per tile, across |
/// | 128 | interleave_m: u32 | and down |
/// | 132 | pattern: u32 | 0 regular, 1 irregular (a permutation per tile) |
/// | 136 | seed: u32 | seeds the irregular pattern |
/// | 140 | accumulate_index: u32 | frames already averaged into the colour buffer |
/// | 144 | upsample_sigma: f32 | spatial Gaussian of the upsampler, low-res pixels |
/// | 148 | normal_power: f32 | exponent of the normal weight |
/// | 152 | upsample_depth: u32 | 1 when depth joins the upsampler's range weight |
/// | 156 | depth_threshold: f32 | relative depth difference of a discontinuity |
/// | 160 | normal_threshold: f32 | smallest normal dot product of a continuous neighbour |
/// | 164 | jitter_x: f32 | primary ray offset within the pixel, in pixels |
/// | 168 | jitter_y: f32 | |
/// | 172 | count_rays: u32 | 1 in a frame that counts its rays (scene binding 5) |
/// | 176 | depth_scale: f32 | 1 / scene diagonal: the depth buffer's unit |
/// | 180 | ray_offset_floor: f32 | least move of a ray origin off its surface (`Scene::ray_offset_floor`) |
/// | 184 | _pad: [u32; 2] | |
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct FrameParams {
    pub cam_eye: [f32; 3],
    pub width: u32,
    pub cam_forward: [f32; 3],
    pub height: u32,
    pub cam_right: [f32; 3],
    pub tan_half_fov_y: f32,
    pub cam_up: [f32; 3],
    pub aspect: f32,
    pub total_power: [f32; 3],
    pub light_count: u32,
    pub path_count: u32,
    pub bounces: u32,
    pub min_dist: f32,
    pub geometry_bound: u32,
    pub mirror_depth: u32,
    pub halton_base: u32,
    pub output: u32,
    pub light_power_sum: f32,
    pub low_width: u32,
    pub low_height: u32,
    pub downsample: u32,
    pub interleave_n: u32,
    pub interleave_m: u32,
    pub pattern: u32,
    pub seed: u32,
    pub accumulate_index: u32,
    pub upsample_sigma: f32,
    pub normal_power: f32,
    pub upsample_depth: u32,
    pub depth_threshold: f32,
    pub normal_threshold: f32,
    pub jitter_x: f32,
    pub jitter_y: f32,
    pub count_rays: u32,
    pub depth_scale: f32,
    pub ray_offset_floor: f32,
    pub _pad: [u32; 2],
}

impl FrameParams {
    /// The same frame for the passes over the mirrored hits, whose record is at full
    /// resolution: the indirect term's resolution is the image's, with no downsampling.
    pub fn at_full_resolution(&self) -> FrameParams {
        FrameParams {
            low_width: self.width,
            low_height: self.height,
            downsample: 1,
            ..*self
        }
    }
}

/// Parameters of the viewer's display pass (uniform buffer, 48 bytes, storage on software
/// adapters as [`FrameParams`]; `passes/display/display.wgsl`).
/// | offset | field | |
/// |---|---|---|
/// | 0 | viewport: vec4f | the image's rectangle in the target: x, y, width, height (pixels) |
/// | 16 | image_width: u32 | |
/// | 20 | image_height: u32 | |
/// | 24 | exposure: f32 | multiplier before clamping and sRGB encoding |
/// | 28 | encode_srgb: u32 | 1 when the shader encodes sRGB (a non-sRGB target format) |
/// | 32 | dot_radius: f32 | half side of a VPL dot, in target pixels |
/// | 36 | _pad: [u32; 3] | |
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct DisplayParams {
    pub viewport: [f32; 4],
    pub image_width: u32,
    pub image_height: u32,
    pub exposure: f32,
    pub encode_srgb: u32,
    pub dot_radius: f32,
    pub _pad: [u32; 3],
}
