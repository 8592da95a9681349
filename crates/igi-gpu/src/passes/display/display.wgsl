// display.wgsl: the viewer's last step, after the paper's frame: the composed linear image
// onto the window (exposure, clamp and sRGB as `Image::to_srgb8` does for PNG files), and
// optionally the frame's VPLs as dots. Not a stage of the frame: `igi render` never runs it.
//
// The render pass's viewport is the image's rectangle in the window (letterboxed), so
// clip space spans the image; fragment positions are window pixels.

#import params
#import vpl_record

struct DisplayParams {
    // The image's rectangle in the target: x, y, width, height in target pixels.
    viewport: vec4<f32>,
    image_width: u32, image_height: u32, exposure: f32,
    // 1 when the target format stores values as given (encode sRGB here), 0 for an sRGB
    // format (the hardware encodes).
    encode_srgb: u32,
    // Half the side of a VPL dot, in target pixels.
    dot_radius: f32, _pad0: u32, _pad1: u32, _pad2: u32,
}

@group(1) @binding(1) var<uniform> display: DisplayParams;
@group(1) @binding(2) var<storage, read> color_in: array<vec4<f32>>;
@group(1) @binding(3) var<storage, read> vpls: array<Vpl>;
@group(1) @binding(4) var<storage, read> vpl_header: VplHeader;

fn srgb_encode(v: f32) -> f32 {
    if (v <= 0.0031308) {
        return 12.92 * v;
    }
    return 1.055 * pow(v, 1.0 / 2.4) - 0.055;
}

fn to_target(c: vec3<f32>) -> vec4<f32> {
    let v = clamp(c, vec3<f32>(0.0), vec3<f32>(1.0));
    if (display.encode_srgb == 1u) {
        return vec4<f32>(srgb_encode(v.x), srgb_encode(v.y), srgb_encode(v.z), 1.0);
    }
    return vec4<f32>(v, 1.0);
}

// One triangle covering the viewport.
@vertex
fn vs_image(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

// Nearest image pixel of each target pixel (the image may be smaller: a render scale).
@fragment
fn fs_image(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let size = vec2<f32>(f32(display.image_width), f32(display.image_height));
    let rel = (frag.xy - display.viewport.xy) / display.viewport.zw;
    let p = vec2<u32>(clamp(floor(rel * size), vec2<f32>(0.0), size - 1.0));
    let c = color_in[p.y * display.image_width + p.x].xyz * display.exposure;
    return to_target(c);
}

struct DotOut {
    @builtin(position) position: vec4<f32>,
    @location(0) color: vec3<f32>,
}

// VPL `instance` as a square of 2 dot_radius pixels; VPLs behind the camera and unused
// slots (instance >= count) become degenerate triangles outside clip space.
@vertex
fn vs_vpl(@builtin(vertex_index) i: u32, @builtin(instance_index) instance: u32) -> DotOut {
    var out: DotOut;
    out.position = vec4<f32>(2.0, 2.0, 2.0, 1.0);
    out.color = vec3<f32>(0.0);
    if (instance >= vpl_header.count) {
        return out;
    }
    let v = vpls[instance];
    let d = v.position - params.cam_eye;
    let z = dot(d, params.cam_forward);
    if (z <= 0.0) {
        return out;
    }
    let ndc = vec2<f32>(
        dot(d, params.cam_right) / (z * params.tan_half_fov_y * params.aspect),
        dot(d, params.cam_up) / (z * params.tan_half_fov_y),
    );
    // Corners of two triangles: (-1,-1) (1,-1) (-1,1), (-1,1) (1,-1) (1,1).
    let corner = array<vec2<f32>, 6>(
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, -1.0), vec2<f32>(-1.0, 1.0),
        vec2<f32>(-1.0, 1.0), vec2<f32>(1.0, -1.0), vec2<f32>(1.0, 1.0),
    );
    let offset = corner[i % 6u] * display.dot_radius * 2.0 / display.viewport.zw;
    out.position = vec4<f32>(ndc + offset, 0.0, 1.0);
    // First-bounce VPLs yellow, later bounces orange.
    out.color = select(vec3<f32>(1.0, 0.45, 0.1), vec3<f32>(1.0, 0.9, 0.2), v.bounce <= 1u);
    return out;
}

@fragment
fn fs_vpl(in: DotOut) -> @location(0) vec4<f32> {
    return to_target(in.color);
}
