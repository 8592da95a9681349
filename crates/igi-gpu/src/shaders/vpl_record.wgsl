// vpl_record.wgsl: the VPL list as the VPL pass writes it and the gathers and the viewer
// read it (layouts in layout.rs).

// A virtual point light: 64 bytes, see layout.rs.
struct Vpl {
    position: vec3<f32>, valid: u32,
    normal: vec3<f32>, bounce: u32,
    flux: vec3<f32>, _pad0: f32,
    albedo: vec3<f32>, _pad1: f32,
}

// Number of VPLs after compaction, and what they came from.
struct VplHeader {
    count: u32,
    path_count: u32,
    slots: u32,
    _pad: u32,
}
