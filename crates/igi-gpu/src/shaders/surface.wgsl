// surface.wgsl: what a closest hit of traverse.wgsl looks like to shading: its point,
// normals and material, from the scene's triangles.

#import scene
#import traverse
#import texture

// What a closest hit looks like to shading. Surfaces are two-sided: both normals face the
// side the ray came from.
struct SurfaceHit {
    position: vec3<f32>,
    geometric_normal: vec3<f32>,
    shading_normal: vec3<f32>,
    diffuse: vec3<f32>,
    mirror: vec3<f32>,
}

// 2^j for j in [-126, 127], exactly (the exponent field alone).
fn pow2(j: i32) -> f32 {
    return bitcast<f32>(u32(127 + j) << 23u);
}

// `e` times the power of two that brings its largest component into [0.5, 1): only
// exponents change, so a cross product of scaled edges rounds exactly as the plain one
// does, but cannot overflow (edges past ~1e19 square past the f32 range and normalize
// gave 0 or NaN). In two halves so that each factor is a normal f32. CPU twin:
// igi_core::scene::scale_pow2.
fn scale_pow2(e: vec3<f32>) -> vec3<f32> {
    let m = max(abs(e.x), max(abs(e.y), abs(e.z)));
    let k = 126 - i32((bitcast<u32>(m) >> 23u) & 0xffu);
    return e * pow2(k / 2) * pow2(k - k / 2);
}

// Unit normal on the side of the winding (CPU twin: igi_core::scene::geometric_normal,
// which also decides which triangles the loaders keep: all of them have one).
fn geometric_normal(v0: vec3<f32>, v1: vec3<f32>, v2: vec3<f32>) -> vec3<f32> {
    return normalize(cross(scale_pow2(v1 - v0), scale_pow2(v2 - v0)));
}

// The hit `hit` of the ray (origin, dir), seen by a ray cone `cone_width` wide there
// (which picks the texture's mip level: texture.wgsl's cone_lod; 0 reads level 0).
fn surface_at(origin: vec3<f32>, dir: vec3<f32>, hit: Hit, cone_width: f32) -> SurfaceHit {
    var s: SurfaceHit;
    let x = tri_rows[3u * hit.tri].xyz;
    let y = tri_rows[3u * hit.tri + 1u].xyz;
    let z = tri_rows[3u * hit.tri + 2u].xyz;
    let v0 = vec3<f32>(x.x, y.x, z.x);
    let v1 = vec3<f32>(x.y, y.y, z.y);
    let v2 = vec3<f32>(x.z, y.z, z.z);
    // Barycentric position: on the triangle, not origin + t dir, whose rounding can put
    // the point behind the surface.
    s.position = (1.0 - hit.u - hit.v) * v0 + hit.u * v1 + hit.v * v2;
    var ng = geometric_normal(v0, v1, v2);
    if (dot(ng, dir) > 0.0) {
        ng = -ng;
    }
    let sh = tri_shading[hit.tri];
    var ns = (1.0 - hit.u - hit.v) * sh.n0 + hit.u * sh.n1 + hit.v * sh.n2;
    let len = length(ns);
    ns = select(ng, ns / len, len > 1e-12);
    if (dot(ns, ng) < 0.0) {
        ns = -ns;
    }
    s.geometric_normal = ng;
    s.shading_normal = ns;
    let m = materials[sh.material];
    s.diffuse = m.diffuse;
    s.mirror = m.mirror;
    if (SURFACE_MAPS && (m.texture != NO_TEXTURE || (m.flags & MAT_VERTEX_COLORS) != 0u)) {
        let a = tri_attributes[hit.tri];
        var lod = 0.0;
        if (m.texture != NO_TEXTURE) {
            lod = cone_lod(m.texture, m, a, v0, v1, v2, cone_width, dot(dir, ng));
        }
        let c = surface_color(m, a, hit.u, hit.v, lod).xyz;
        s.diffuse *= c;
        s.mirror *= c;
    }
    return s;
}
