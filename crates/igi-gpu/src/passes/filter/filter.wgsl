// filter.wgsl: back from the interleaved, downsampled indirect term to a smooth
// full-resolution one (paper sections 4.2 and 4.3, and the combined pass of its future
// work). Two entry points, each its own pass:
// - discontinuity: at the indirect resolution, each pixel averages the n x m window
//   around it over the neighbours that are geometrically continuous with it (depth and
//   normal thresholds): every subset of the regular pattern is in every such window.
// - fused: discontinuity and upsampling at once from the raw interleaved term: for each
//   of the four low-res pixels around p (bilinear weights), the n x m window around it,
//   each sample weighed by its continuity with the full-resolution pixel p itself.
// Joint bilateral upsampling on its own (section 4.2) happens in compose.wgsl, as it
// writes each pixel (upsample.wgsl). G-buffer samples of low-resolution pixels are those
// of their representative pixels. Both entry points filter the G-buffer's E, or the
// mirror record's (gbuffer.wgsl).
// Bindings 2 and 3 of group 1 (the shading normal and the interleaved E, irradiance_in)
// are upsample.wgsl's.

#import params
#import gbuffer
#import upsample

@group(1) @binding(1) var<storage, read> gbuf_position: array<vec4<f32>>;
@group(1) @binding(4) var<storage, read_write> filter_out: array<vec4<f32>>;

// surface_pixel's answer outside the image or where no surface was hit.
const NO_PIXEL: u32 = 0xffffffffu;

// Whether full-resolution G-buffer samples a and b lie on one continuous surface.
fn continuous(a: u32, b: u32) -> bool {
    if (!has_surface(gbuf_position[b])) {
        return false;
    }
    let na = gbuf_normal[a];
    let nb = gbuf_normal[b];
    let depth_ok = abs(normal_depth(na) - normal_depth(nb)) <= params.depth_threshold * normal_depth(na);
    return depth_ok && dot(na.xyz, nb.xyz) >= params.normal_threshold;
}

// The n x m window around low-res pixel (x, y): offsets -(n/2) ..= (n-1)/2.
fn window_start(c: u32, size: u32) -> i32 {
    return i32(c) - i32(size / 2u);
}

@compute @workgroup_size(8, 8)
fn discontinuity(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= params.low_width || gid.y >= params.low_height) {
        return;
    }
    let low = gid.y * params.low_width + gid.x;
    let centre = representative_pixel(gid.x, gid.y);
    if (!has_surface(gbuf_position[centre])) {
        filter_out[low] = vec4<f32>(0.0, 0.0, 0.0, 1.0);
        return;
    }
    var sum = vec3<f32>(0.0);
    var weight = 0.0;
    let x0 = window_start(gid.x, params.interleave_n);
    let y0 = window_start(gid.y, params.interleave_m);
    for (var j = 0; j < i32(params.interleave_m); j += 1) {
        for (var i = 0; i < i32(params.interleave_n); i += 1) {
            let x = x0 + i;
            let y = y0 + j;
            if (x < 0 || y < 0 || x >= i32(params.low_width) || y >= i32(params.low_height)) {
                continue;
            }
            let q = representative_pixel(u32(x), u32(y));
            if (continuous(centre, q)) {
                sum += irradiance_in[u32(y) * params.low_width + u32(x)].xyz;
                weight += 1.0;
            }
        }
    }
    // The centre is always continuous with itself, so weight >= 1.
    filter_out[low] = vec4<f32>(sum / max(weight, 1.0), 1.0);
}

// The full-resolution pixel of `gid`, or NO_PIXEL outside the image or where no surface
// was hit (its E is written as zero here).
fn surface_pixel(gid: vec3<u32>) -> u32 {
    if (gid.x >= params.width || gid.y >= params.height) {
        return NO_PIXEL;
    }
    let pixel = gid.y * params.width + gid.x;
    if (!has_surface(gbuf_position[pixel])) {
        filter_out[pixel] = vec4<f32>(0.0, 0.0, 0.0, 1.0);
        return NO_PIXEL;
    }
    return pixel;
}

@compute @workgroup_size(8, 8)
fn fused(@builtin(global_invocation_id) gid: vec3<u32>) {
    let pixel = surface_pixel(gid);
    if (pixel == NO_PIXEL) {
        return;
    }
    let u = low_coordinate(gid.x);
    let v = low_coordinate(gid.y);
    let bx = i32(floor(u));
    let by = i32(floor(v));
    let fx = u - f32(bx);
    let fy = v - f32(by);
    var g = new_gathered();
    for (var cj = 0; cj <= 1; cj += 1) {
        for (var ci = 0; ci <= 1; ci += 1) {
            let bilinear = select(1.0 - fx, fx, ci == 1) * select(1.0 - fy, fy, cj == 1);
            let x0 = bx + ci - i32(params.interleave_n / 2u);
            let y0 = by + cj - i32(params.interleave_m / 2u);
            for (var j = 0; j < i32(params.interleave_m); j += 1) {
                for (var i = 0; i < i32(params.interleave_n); i += 1) {
                    let x = x0 + i;
                    let y = y0 + j;
                    if (!inside_low(x, y)) {
                        continue;
                    }
                    let q = representative_pixel(u32(x), u32(y));
                    var w = 0.0;
                    if (continuous(pixel, q)) {
                        w = bilinear * pow(max(dot(gbuf_normal[pixel].xyz, gbuf_normal[q].xyz), 0.0), params.normal_power);
                    }
                    let dx = f32(x) - u;
                    let dy = f32(y) - v;
                    gather_sample(&g, x, y, w, dx * dx + dy * dy);
                }
            }
        }
    }
    filter_out[pixel] = vec4<f32>(gathered_value(g), 1.0);
}
