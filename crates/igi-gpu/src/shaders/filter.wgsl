// filter.wgsl: back from the interleaved, downsampled indirect term to a smooth
// full-resolution one (paper sections 4.2 and 4.3, and the combined pass of its future
// work). Three entry points, each its own pass:
// - discontinuity: at the indirect resolution, each pixel averages the n x m window
//   around it over the neighbours that are geometrically continuous with it (depth and
//   normal thresholds): every subset of the regular pattern is in every such window.
// - upsample: joint bilateral upsampling to full resolution,
//   S(p) = 1/k sum_q I_q f(|p - q|) w(N_p . N_q) [x depth weight], f a spatial Gaussian
//   over low-resolution neighbours, w the paper's cosine (to a power, 1 by default).
// - fused: both at once from the raw interleaved term: for each of the four low-res
//   pixels around p (bilinear weights), the n x m window around it, each sample weighed
//   by its continuity with the full-resolution pixel p itself.
// G-buffer samples of low-resolution pixels are those of their representative pixels.

@group(1) @binding(1) var<storage, read> gbuf_position: array<vec4<f32>>;
@group(1) @binding(2) var<storage, read> gbuf_normal: array<vec4<f32>>;
@group(1) @binding(3) var<storage, read> filter_in: array<vec4<f32>>;
@group(1) @binding(4) var<storage, read_write> filter_out: array<vec4<f32>>;

// Whether full-resolution G-buffer samples a and b lie on one continuous surface.
fn continuous(a: u32, b: u32) -> bool {
    if (gbuf_position[b].w <= 0.0) {
        return false;
    }
    let na = gbuf_normal[a];
    let nb = gbuf_normal[b];
    let depth_ok = abs(na.w - nb.w) <= params.depth_threshold * na.w;
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
    if (gbuf_position[centre].w <= 0.0) {
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
                sum += filter_in[u32(y) * params.low_width + u32(x)].xyz;
                weight += 1.0;
            }
        }
    }
    // The centre is always continuous with itself, so weight >= 1.
    filter_out[low] = vec4<f32>(sum / max(weight, 1.0), 1.0);
}

// Low-resolution coordinate of full-resolution pixel p's centre, in the frame where
// low-res pixel c sits at its representative pixel's centre.
fn low_coordinate(p: u32) -> f32 {
    let s = f32(params.downsample);
    return (f32(p) - f32(params.downsample / 2u)) / s;
}

// Range weight of the upsampler between full-resolution pixel p and sample q.
fn range_weight(p: u32, q: u32) -> f32 {
    if (gbuf_position[q].w <= 0.0) {
        return 0.0;
    }
    let np = gbuf_normal[p];
    let nq = gbuf_normal[q];
    var w = pow(max(dot(np.xyz, nq.xyz), 0.0), params.normal_power);
    if (params.upsample_depth != 0u) {
        let d = (np.w - nq.w) / (params.depth_threshold * np.w);
        w *= exp(-0.5 * d * d);
    }
    return w;
}

// What a full-resolution pixel gathers from low-resolution samples: the weighted sum,
// and the nearest surface sample as the fallback where every weight is zero (a thin
// feature between samples, every neighbour facing away).
struct Gathered {
    sum: vec3<f32>,
    weight: f32,
    nearest: vec3<f32>,
    nearest_d2: f32,
}

fn new_gathered() -> Gathered {
    return Gathered(vec3<f32>(0.0), 0.0, vec3<f32>(0.0), 1e30);
}

// Add low-resolution sample (x, y), inside the image, with weight w, at squared
// distance d2 (low-resolution pixels) from the pixel being filtered.
fn gather_sample(g: ptr<function, Gathered>, x: i32, y: i32, w: f32, d2: f32) {
    let q = representative_pixel(u32(x), u32(y));
    let value = filter_in[u32(y) * params.low_width + u32(x)].xyz;
    (*g).sum += w * value;
    (*g).weight += w;
    if (gbuf_position[q].w > 0.0 && d2 < (*g).nearest_d2) {
        (*g).nearest_d2 = d2;
        (*g).nearest = value;
    }
}

fn gathered_value(g: Gathered) -> vec3<f32> {
    if (g.weight > 1e-6) {
        return g.sum / g.weight;
    }
    return g.nearest;
}

fn inside_low(x: i32, y: i32) -> bool {
    return x >= 0 && y >= 0 && x < i32(params.low_width) && y < i32(params.low_height);
}

// The full-resolution pixel of `gid`, or NO_HIT outside the image or where no surface
// was hit (its E is written as zero here).
fn surface_pixel(gid: vec3<u32>) -> u32 {
    if (gid.x >= params.width || gid.y >= params.height) {
        return NO_HIT;
    }
    let pixel = gid.y * params.width + gid.x;
    if (gbuf_position[pixel].w <= 0.0) {
        filter_out[pixel] = vec4<f32>(0.0, 0.0, 0.0, 1.0);
        return NO_HIT;
    }
    return pixel;
}

@compute @workgroup_size(8, 8)
fn upsample(@builtin(global_invocation_id) gid: vec3<u32>) {
    let pixel = surface_pixel(gid);
    if (pixel == NO_HIT) {
        return;
    }
    let u = low_coordinate(gid.x);
    let v = low_coordinate(gid.y);
    let bx = i32(floor(u));
    let by = i32(floor(v));
    var g = new_gathered();
    let inv_two_sigma2 = 0.5 / (params.upsample_sigma * params.upsample_sigma);
    for (var j = -1; j <= 2; j += 1) {
        for (var i = -1; i <= 2; i += 1) {
            let x = bx + i;
            let y = by + j;
            if (!inside_low(x, y)) {
                continue;
            }
            let dx = f32(x) - u;
            let dy = f32(y) - v;
            let d2 = dx * dx + dy * dy;
            let w = exp(-d2 * inv_two_sigma2) * range_weight(pixel, representative_pixel(u32(x), u32(y)));
            gather_sample(&g, x, y, w, d2);
        }
    }
    filter_out[pixel] = vec4<f32>(gathered_value(g), 1.0);
}

@compute @workgroup_size(8, 8)
fn fused(@builtin(global_invocation_id) gid: vec3<u32>) {
    let pixel = surface_pixel(gid);
    if (pixel == NO_HIT) {
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
