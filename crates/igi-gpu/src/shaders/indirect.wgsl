// indirect.wgsl: indirect diffuse light at the primary hits (paper section 4, third
// stage): the incident term E(x) from every VPL through a shadow ray, stored without the
// albedo of x so that later filters do not blur texture and material edges.

@group(1) @binding(1) var<storage, read> vpls: array<Vpl>;
@group(1) @binding(2) var<storage, read> vpl_header: VplHeader;
@group(1) @binding(3) var<storage, read> gbuf_position: array<vec4<f32>>;
@group(1) @binding(4) var<storage, read> gbuf_normal: array<vec4<f32>>;
@group(1) @binding(5) var<storage, read> gbuf_geometric: array<vec4<f32>>;
@group(1) @binding(6) var<storage, read_write> irradiance_out: array<vec4<f32>>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= params.width || gid.y >= params.height) {
        return;
    }
    let pixel = gid.y * params.width + gid.x;
    let position = gbuf_position[pixel];
    var e = vec3<f32>(0.0);
    if (gather_first() > 0u) {
        e = irradiance_out[pixel].xyz;
    }
    if (position.w > 0.0) {
        e += vpl_irradiance(position.xyz, gbuf_geometric[pixel].xyz, gbuf_normal[pixel].xyz, gather_first(), gather_last(), 1u);
    }
    irradiance_out[pixel] = vec4<f32>(e, 1.0);
}
