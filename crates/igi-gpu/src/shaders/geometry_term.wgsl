// geometry_term.wgsl: the bounded geometry term G of the gathers.

#import params

// The bound on the distance part of G: the paper's smoothstep(0.8 m, 1.2 m, d) / d^2, or
// the classic clamp 1 / max(d^2, m^2).
fn bounded_inverse_square(dist2: f32) -> f32 {
    let m = params.min_dist;
    if (params.geometry_bound == 1u) {
        return 1.0 / max(dist2, m * m);
    }
    return smoothstep(0.8 * m, 1.2 * m, sqrt(dist2)) / dist2;
}
