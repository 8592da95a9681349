// upsample.wgsl: joint bilateral upsampling of the downsampled indirect term to full
// resolution (paper section 4.2), S(p) = 1/k sum_q I_q f(|p - q|) w(N_p . N_q) [x depth
// weight], f a spatial Gaussian over the 4 x 4 low-resolution neighbours, w the paper's
// cosine (to a power, 1 by default), and what it shares with the fused filter
// (filter.wgsl). compose.wgsl upsamples as it writes each pixel, which was faster than a
// pass of its own.
// Both passes that upsample (filter and compose) bind the G-buffer's shading normal and
// the low-resolution E at bindings 2 and 3 of group 1, declared here (binding 1 is the
// G-buffer's position in both).

#import params
#import gbuffer

@group(1) @binding(2) var<storage, read> gbuf_normal: array<vec4<f32>>;
// E at the indirect term's resolution (low_width x low_height), or at full resolution
// where compose's `main` reads it without upsampling.
@group(1) @binding(3) var<storage, read> irradiance_in: array<vec4<f32>>;

// E of low-resolution pixel i.
fn low_irradiance(i: u32) -> vec3<f32> {
    return irradiance_in[i].xyz;
}

// Low-resolution coordinate of full-resolution pixel p's centre, in the frame where
// low-res pixel c sits at its representative pixel's centre.
fn low_coordinate(p: u32) -> f32 {
    let s = f32(params.downsample);
    return (f32(p) - f32(params.downsample / 2u)) / s;
}

// Whether the primary ray of pixel q hit a surface, from the G-buffer's shading normal
// alone (gbuffer.wgsl): reading the position as well would cost every tap of the
// upsampler a second scattered read.
fn sample_has_surface(q: u32) -> bool {
    return normal_has_surface(gbuf_normal[q]);
}

// Range weight of the upsampler between full-resolution pixel p and sample q.
fn range_weight(p: u32, q: u32) -> f32 {
    let nq = gbuf_normal[q];
    if (!normal_has_surface(nq)) {
        return 0.0;
    }
    let np = gbuf_normal[p];
    var w = pow(max(dot(np.xyz, nq.xyz), 0.0), params.normal_power);
    if (params.upsample_depth != 0u) {
        let d = (normal_depth(np) - normal_depth(nq)) / (params.depth_threshold * normal_depth(np));
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
    let value = low_irradiance(u32(y) * params.low_width + u32(x));
    (*g).sum += w * value;
    (*g).weight += w;
    if (sample_has_surface(q) && d2 < (*g).nearest_d2) {
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

// E at full-resolution pixel (x, y), index `pixel`, where a surface was hit.
fn upsampled_irradiance(x: u32, y: u32, pixel: u32) -> vec3<f32> {
    let u = low_coordinate(x);
    let v = low_coordinate(y);
    let bx = i32(floor(u));
    let by = i32(floor(v));
    var g = new_gathered();
    let inv_two_sigma2 = 0.5 / (params.upsample_sigma * params.upsample_sigma);
    for (var j = -1; j <= 2; j += 1) {
        for (var i = -1; i <= 2; i += 1) {
            let sx = bx + i;
            let sy = by + j;
            if (!inside_low(sx, sy)) {
                continue;
            }
            let dx = f32(sx) - u;
            let dy = f32(sy) - v;
            let d2 = dx * dx + dy * dy;
            let w = exp(-d2 * inv_two_sigma2) * range_weight(pixel, representative_pixel(u32(sx), u32(sy)));
            gather_sample(&g, sx, sy, w, d2);
        }
    }
    return gathered_value(g);
}
