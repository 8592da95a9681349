// indirect.wgsl: indirect diffuse light at the primary hits (paper section 4, third
// stage): the incident term E(x) from the VPLs through shadow rays, stored without the
// albedo of x so that later filters do not blur texture and material edges.
// With the paper's accelerations it runs at 1/downsample of the resolution per axis
// (section 4.2: one G-buffer sample stands for each block) and, with interleaved
// sampling (section 4.3), each pixel gathers only its subset of the VPLs, scaled by the
// number of subsets, so that the tile's average stays an unbiased estimate.

@group(1) @binding(1) var<storage, read> vpls: array<Vpl>;
@group(1) @binding(2) var<storage, read> vpl_header: VplHeader;
@group(1) @binding(3) var<storage, read> gbuf_position: array<vec4<f32>>;
@group(1) @binding(4) var<storage, read> gbuf_normal: array<vec4<f32>>;
@group(1) @binding(5) var<storage, read> gbuf_geometric: array<vec4<f32>>;
// At the indirect term's resolution (low_width x low_height).
@group(1) @binding(6) var<storage, read_write> irradiance_out: array<vec4<f32>>;

// The VPL subset of low-resolution pixel (x, y): its place in its n x m tile, through a
// permutation drawn for the tile (seeded Fisher-Yates) when the pattern is irregular.
fn interleave_subset(x: u32, y: u32) -> u32 {
    let n = params.interleave_n;
    let m = params.interleave_m;
    let local = (x % n) + n * (y % m);
    if (params.pattern == 0u) {
        return local;
    }
    var perm: array<u32, 64>;
    let count = n * m;
    for (var i = 0u; i < count; i += 1u) {
        perm[i] = i;
    }
    var h = hash_u32(params.seed ^ hash_u32((x / n) * 0x8da6b343u ^ (y / m) * 0xd8163841u));
    for (var i = count - 1u; i > 0u; i -= 1u) {
        h = hash_u32(h + 0x9e3779b9u);
        let j = h % (i + 1u);
        let t = perm[i];
        perm[i] = perm[j];
        perm[j] = t;
    }
    return perm[local];
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= params.low_width || gid.y >= params.low_height) {
        return;
    }
    let low = gid.y * params.low_width + gid.x;
    let pixel = representative_pixel(gid.x, gid.y);
    let position = gbuf_position[pixel];
    var e = vec3<f32>(0.0);
    if (gather_first() > 0u) {
        e = irradiance_out[low].xyz;
    }
    if (position.w > 0.0) {
        let subsets = params.interleave_n * params.interleave_m;
        let subset = interleave_subset(gid.x, gid.y);
        // First VPL of this pixel's subset within the dispatch's range.
        let begin = gather_first();
        let first = begin + (subset + subsets - begin % subsets) % subsets;
        let sum = vpl_irradiance(position.xyz, gbuf_geometric[pixel].xyz, gbuf_normal[pixel].xyz, first, gather_last(), subsets);
        e += f32(subsets) * sum;
    }
    irradiance_out[low] = vec4<f32>(e, 1.0);
}
