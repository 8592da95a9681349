// compose.wgsl: the final image (paper section 4, last stage):
// L = direct_specular + (rho_d(x) / pi) E(x), linear radiance; tone mapping happens only
// when an image is written. `params.output` picks another buffer for inspection (the
// viewer's buffer choice): direct (with the indirect light seen in mirrors), indirect,
// E, normals or depth of the primary hits.
// Two entry points: `main` reads E at full resolution (`irradiance_in`: the indirect
// pass's output, or the fused filter's); `main_upsampled` upsamples it from the indirect
// term's resolution (`irradiance_in` then holds the indirect pass's or the discontinuity
// buffer's output) with the joint bilateral upsampler of upsample.wgsl.
// Bindings 2 and 3 of group 1 (the G-buffer's shading normal and E, irradiance_in) are
// upsample.wgsl's, at the numbers the filter binds them at too.

#import constants
#import params
#import gbuffer
#import upsample

@group(1) @binding(1) var<storage, read> gbuf_position: array<vec4<f32>>;
@group(1) @binding(4) var<storage, read_write> color_out: array<vec4<f32>>;
@group(1) @binding(5) var<storage, read> direct_in: array<vec4<f32>>;
@group(1) @binding(6) var<storage, read> gbuf_albedo: array<vec4<f32>>;
// Indirect light at the pixel's mirrored hit (indirect.wgsl over the mirror record): the
// mirror record's weight (gbuffer.wgsl) times E there, after the mirror discontinuity
// filter when interleaved.
@group(1) @binding(7) var<storage, read> mirror_weight: array<vec4<f32>>;
@group(1) @binding(8) var<storage, read> mirror_irradiance: array<vec4<f32>>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= params.width || gid.y >= params.height) {
        return;
    }
    let pixel = gid.y * params.width + gid.x;
    compose_pixel(pixel, irradiance_in[pixel].xyz);
}

@compute @workgroup_size(8, 8)
fn main_upsampled(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= params.width || gid.y >= params.height) {
        return;
    }
    let pixel = gid.y * params.width + gid.x;
    var e = vec3<f32>(0.0);
    if (has_surface(gbuf_position[pixel])) {
        e = upsampled_irradiance(gid.x, gid.y, pixel);
    }
    compose_pixel(pixel, e);
}

// Writes pixel `pixel` of the chosen output, E there being `e`.
fn compose_pixel(pixel: u32, e: vec3<f32>) {
    var direct = direct_in[pixel].xyz;
    let mirrored = mirror_weight[pixel];
    if (has_weight(mirrored)) {
        direct += mirrored.xyz * mirror_irradiance[pixel].xyz;
    }
    let indirect = gbuf_albedo[pixel].xyz / PI * e;
    var c = direct + indirect;
    let hit = has_surface(gbuf_position[pixel]);
    switch params.output {
        case 1u: { c = direct; }
        case 2u: { c = indirect; }
        case 3u: { c = e; }
        case 4u: { c = select(vec3<f32>(0.0), 0.5 + 0.5 * gbuf_normal[pixel].xyz, hit); }
        case 5u: {
            let d = distance(gbuf_position[pixel].xyz, params.cam_eye) * params.depth_scale;
            c = select(vec3<f32>(0.0), vec3<f32>(d), hit);
        }
        default: {}
    }
    // Accumulation (--accumulate K): a running mean over frames with fresh VPL sets.
    let k = f32(params.accumulate_index);
    if (k > 0.0) {
        c = (color_out[pixel].xyz * k + c) / (k + 1.0);
    }
    color_out[pixel] = vec4<f32>(c, 1.0);
}
