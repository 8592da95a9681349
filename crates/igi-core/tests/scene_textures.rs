//! Tests of textures, vertex colours and alpha as the loaders read them (glTF and
//! OBJ/MTL): the texels, samplers, texture coordinate sets and transforms of glTF base
//! colour textures, per-triangle attributes on the right corners, alpha modes,
//! KHR_mesh_quantization, MTL maps and opacities, `[materials.NAME]` over textures, the
//! errors of hostile accessors, and every Khronos sample of `shared/gltf-samples`.

#[path = "common/test_dir.rs"]
mod test_dir;
use std::path::Path;
use test_dir::{expect_err, TestDir, CAMERA, LIGHT};

#[path = "common/gltf_builder.rs"]
mod gltf_builder;
use gltf_builder::*;

use glam::{Vec2, Vec3, Vec4};
use igi_core::scene::loader::load_scene;
use igi_core::scene::{Alpha, AlphaMode, Material, Scene, TriAttributes};
use igi_core::texture::{Filter, Sampler, UvTransform, Wrap};

// ---------------------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------------------

/// A scene with the test camera and light, one `[[mesh]]` per path, and `extra` TOML.
fn scene_toml(paths: &[&str], extra: &str) -> String {
    let meshes: String = paths
        .iter()
        .map(|p| format!("[[mesh]]\npath = \"{p}\"\n"))
        .collect();
    format!("{CAMERA}\n{meshes}\n{LIGHT}\n{extra}")
}

fn material<'a>(s: &'a Scene, name: &str) -> &'a Material {
    s.materials
        .iter()
        .find(|m| m.name == name)
        .unwrap_or_else(|| panic!("no material {name} in {:?}", s.materials))
}

/// The triangles of material `name`, with their attributes.
fn triangles_of<'a>(
    s: &'a Scene,
    name: &str,
) -> Vec<(&'a igi_core::scene::Triangle, &'a TriAttributes)> {
    let m = s.materials.iter().position(|m| m.name == name).unwrap() as u32;
    assert_eq!(s.attributes.len(), s.triangles.len());
    s.triangles
        .iter()
        .zip(&s.attributes)
        .filter(|(t, _)| t.material == m)
        .collect()
}

/// A PNG of `w` x `h` RGBA8 texels.
fn png_rgba(w: u32, h: u32, texels: &[[u8; 4]]) -> Vec<u8> {
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, w, h);
        enc.set_color(png::ColorType::Rgba);
        enc.set_depth(png::BitDepth::Eight);
        let mut wr = enc.write_header().expect("png header");
        wr.write_image_data(texels.as_flattened())
            .expect("png data");
    }
    out
}

/// A PNG of `w` x `h` grey texels.
fn png_grey(w: u32, h: u32, texels: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, w, h);
        enc.set_color(png::ColorType::Grayscale);
        enc.set_depth(png::BitDepth::Eight);
        let mut wr = enc.write_header().expect("png header");
        wr.write_image_data(texels).expect("png data");
    }
    out
}

const TEXELS: [[u8; 4]; 4] = [
    [255, 0, 0, 255],
    [0, 255, 0, 128],
    [0, 0, 255, 0],
    [10, 20, 30, 40],
];

fn close2(a: Vec2, b: Vec2) -> bool {
    (a - b).length() < 1e-6
}

/// Which vertex of `QUAD` (mapped by `world`) `p` is.
fn quad_vertex(p: Vec3, world: impl Fn(Vec3) -> Vec3) -> usize {
    (0..4)
        .find(|&i| (world(Vec3::from(QUAD[i])) - p).length() < 1e-5)
        .unwrap_or_else(|| panic!("{p} is no vertex of the quad"))
}

// ---------------------------------------------------------------------------------------
// glTF base colour textures and attributes
// ---------------------------------------------------------------------------------------

/// The quad with TEXCOORD_0 (unused), TEXCOORD_1 and COLOR_0, placed twice: as it is and
/// mirrored (x -> -x). Its texture reads set 1 by KHR_texture_transform's texCoord.
fn textured_quad() -> (Gltf, [[f32; 2]; 4], [[f32; 4]; 4]) {
    let mut g = Gltf::default();
    let p = g.positions(&QUAD);
    let i = g.indices(&QUAD_INDICES);
    let uv1 = [[0.1, 0.2], [0.3, 0.4], [0.5, 0.6], [0.7, 0.8]];
    let col = [
        [1.0, 0.0, 0.0, 1.0],
        [0.0, 1.0, 0.0, 0.5],
        [0.0, 0.0, 1.0, 0.25],
        [0.5, 0.5, 0.5, 0.0],
    ];
    let t0 = g.vec2(&[[9.0, 9.0]; 4]);
    let t1 = g.vec2(&uv1);
    let c = g.vec4(&col);
    let png = g.view(&png_rgba(2, 2, &TEXELS));
    g.images.push(format!(
        r#"{{"bufferView": {png}, "mimeType": "image/png"}}"#
    ));
    g.samplers
        .push(r#"{"wrapS": 33648, "wrapT": 33071, "magFilter": 9728, "minFilter": 9986}"#.into());
    g.textures.push(r#"{"source": 0, "sampler": 0}"#.into());
    g.material(
        r#"{"name": "tex", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1.0], "metallicFactor": 0.0,
        "baseColorTexture": {"index": 0, "texCoord": 0, "extensions": {"KHR_texture_transform": {"offset": [0.1, 0.2], "rotation": 0.3, "scale": [2.0, 3.0], "texCoord": 1}}}}}"#,
    );
    g.extensions_used.push("KHR_texture_transform".into());
    g.extensions_required.push("KHR_texture_transform".into());
    g.mesh(&[format!(
        r#"{{"attributes": {{"POSITION": {p}, "TEXCOORD_0": {t0}, "TEXCOORD_1": {t1}, "COLOR_0": {c}}}, "indices": {i}, "material": 0}}"#
    )]);
    g.node(r#""mesh": 0"#);
    g.node(r#""mesh": 0, "scale": [-1.0, 1.0, 1.0]"#);
    g.roots = vec![0, 1];
    (g, uv1, col)
}

#[test]
fn gltf_texture_texels_sampler_transform_and_set() {
    let dir = TestDir::new("gltf-texture");
    let (g, _, _) = textured_quad();
    dir.write("t.gltf", g.gltf());
    let s = dir.load(&scene_toml(&["t.gltf"], "")).unwrap();
    let m = material(&s, "tex");
    assert_eq!(m.diffuse, Vec3::splat(0.5));
    assert!(m.vertex_colors);
    let t = m.texture.expect("a texture");
    assert_eq!(s.textures.len(), 1);
    let tex = &s.textures[t.texture as usize];
    assert_eq!((tex.width, tex.height, tex.srgb), (2, 2, true));
    assert_eq!(tex.levels[0].texels, TEXELS);
    assert_eq!(
        t.sampler,
        Sampler {
            wrap_s: Wrap::MirroredRepeat,
            wrap_t: Wrap::ClampToEdge,
            mag: Filter::Nearest,
            min: Filter::Nearest,
            mip: Some(Filter::Linear),
        }
    );
    assert_eq!(
        t.transform,
        UvTransform::from_offset_rotation_scale(Vec2::new(0.1, 0.2), 0.3, Vec2::new(2.0, 3.0))
    );
    // OPAQUE (the default) ignores alpha.
    assert_eq!(m.alpha, Alpha::OPAQUE);
}

#[test]
fn gltf_uvs_and_colours_land_on_their_corners_also_when_mirrored() {
    let dir = TestDir::new("gltf-corners");
    let (g, uv1, col) = textured_quad();
    dir.write("t.gltf", g.gltf());
    let s = dir.load(&scene_toml(&["t.gltf"], "")).unwrap();
    assert_eq!(s.triangles.len(), 4);
    assert_eq!(s.attributes.len(), 4);
    let mirror = |p: Vec3| Vec3::new(-p.x, p.y, p.z);
    for (k, (t, a)) in s.triangles.iter().zip(&s.attributes).enumerate() {
        let mirrored = k >= 2;
        for c in 0..3 {
            let i = if mirrored {
                quad_vertex(t.v[c], mirror)
            } else {
                quad_vertex(t.v[c], |p| p)
            };
            assert!(
                close2(a.uv[c], Vec2::from(uv1[i])),
                "triangle {k} corner {c}"
            );
            assert_eq!(a.color[c], Vec4::from(col[i]), "triangle {k} corner {c}");
        }
        if mirrored {
            // The corners were swapped (winding kept on the normals' side): the
            // attributes with them, not left in file order.
            let file_order = QUAD_INDICES[3 * (k - 2)..3 * (k - 2) + 3]
                .iter()
                .map(|&i| Vec2::from(uv1[i as usize]))
                .collect::<Vec<_>>();
            assert_ne!(a.uv.to_vec(), file_order, "triangle {k}");
        }
    }
}

#[test]
fn gltf_alpha_modes() {
    let dir = TestDir::new("gltf-alpha");
    let mut g = quad(None);
    let png = g.view(&png_rgba(2, 2, &TEXELS));
    g.images.push(format!(
        r#"{{"bufferView": {png}, "mimeType": "image/png"}}"#
    ));
    let uv = g.vec2(&[[0.0, 0.0]; 4]);
    let mats = [
        r#"{"name": "mask_tex", "alphaMode": "MASK", "alphaCutoff": 0.3, "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.9], "baseColorTexture": {"index": 0}}}"#,
        r#"{"name": "mask_default", "alphaMode": "MASK", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}"#,
        r#"{"name": "mask_solid", "alphaMode": "MASK", "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.8]}}"#,
        r#"{"name": "mask_gone", "alphaMode": "MASK", "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.2]}}"#,
        r#"{"name": "blend", "alphaMode": "BLEND", "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.7], "baseColorTexture": {"index": 0}}}"#,
        r#"{"name": "opaque", "alphaMode": "OPAQUE", "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.1], "baseColorTexture": {"index": 0}}}"#,
    ];
    let prims: Vec<String> = (0..mats.len())
        .map(|k| {
            g.material(mats[k]);
            format!(
                r#"{{"attributes": {{"POSITION": 0, "TEXCOORD_0": {uv}}}, "indices": 1, "material": {k}}}"#
            )
        })
        .collect();
    g.meshes[0] = format!(r#"{{"primitives": [{}]}}"#, prims.join(", "));
    g.node(r#""mesh": 0"#);
    dir.write("a.gltf", g.gltf());
    let s = dir.load(&scene_toml(&["a.gltf"], "")).unwrap();
    let mask = |cutoff, factor| Alpha {
        mode: AlphaMode::Mask { cutoff },
        factor,
    };
    assert_eq!(material(&s, "mask_tex").alpha, mask(0.3, 0.9));
    assert_eq!(material(&s, "mask_default").alpha, mask(0.5, 1.0));
    // Without texture or vertex colours a mask is all there or all gone.
    assert_eq!(material(&s, "mask_solid").alpha, Alpha::OPAQUE);
    assert_eq!(material(&s, "mask_gone").alpha, mask(0.5, 0.2));
    assert!(material(&s, "mask_gone").alpha_tested());
    // BLEND: a cut-out at 0.5 (with a warning).
    assert_eq!(material(&s, "blend").alpha, mask(0.5, 0.7));
    assert_eq!(material(&s, "opaque").alpha, Alpha::OPAQUE);
}

/// A view of `bytes` with a byteStride, as gltfpack writes quantized attributes.
fn strided(g: &mut Gltf, bytes: &[u8], stride: usize) -> usize {
    let v = g.view(bytes);
    g.views[v] = g.views[v].replace('}', &format!(r#", "byteStride": {stride}}}"#));
    v
}

#[test]
fn quantized_attributes_are_dequantized() {
    let dir = TestDir::new("quantized");
    let mut g = Gltf::default();
    // u16 positions (not normalized, de-quantized by the node's scale), VEC3 padded to 8.
    let pos: Vec<u8> = QUAD
        .iter()
        .flat_map(|p| {
            let q = p.map(|x| (x * 1000.0) as u16);
            [q[0], q[1], q[2], 0].into_iter().flat_map(u16::to_le_bytes)
        })
        .collect();
    let pv = strided(&mut g, &pos, 8);
    let p = g.accessor(format!(
        r#"{{"bufferView": {pv}, "componentType": 5123, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1000, 1000, 0]}}"#
    ));
    // i8 normalized normals (0, 0, 127), padded to 4.
    let nv = strided(&mut g, &[0u8, 0, 127, 0].repeat(4), 4);
    let n = g.accessor(format!(
        r#"{{"bufferView": {nv}, "componentType": 5120, "normalized": true, "count": 4, "type": "VEC3"}}"#
    ));
    // u16 normalized texture coordinates.
    let uv: Vec<u8> = [[0u16, 0], [65535, 0], [65535, 65535], [0, 32768]]
        .iter()
        .flatten()
        .flat_map(|x| x.to_le_bytes())
        .collect();
    let t = g.typed(&uv, 5123, "VEC2", 4, r#", "normalized": true"#);
    // A second mesh: i8 positions, i16 normalized coordinates (-32768 reads as -1).
    let pos8: Vec<u8> = [[-1i8, 0, 0, 0], [1, 0, 0, 0], [0, 1, 0, 0]]
        .iter()
        .flatten()
        .map(|&x| x as u8)
        .collect();
    let pv8 = strided(&mut g, &pos8, 4);
    let p8 = g.accessor(format!(
        r#"{{"bufferView": {pv8}, "componentType": 5120, "count": 3, "type": "VEC3", "min": [-1, 0, 0], "max": [1, 1, 0]}}"#
    ));
    let uv16: Vec<u8> = [[-32768i16, 32767], [16384, 0], [0, -16384]]
        .iter()
        .flatten()
        .flat_map(|x| x.to_le_bytes())
        .collect();
    let t16 = g.typed(&uv16, 5122, "VEC2", 3, r#", "normalized": true"#);
    let i = g.indices(&QUAD_INDICES);
    let png = g.view(&png_rgba(2, 2, &TEXELS));
    g.images.push(format!(
        r#"{{"bufferView": {png}, "mimeType": "image/png"}}"#
    ));
    g.material(r#"{"name": "q", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}"#);
    g.mesh(&[format!(
        r#"{{"attributes": {{"POSITION": {p}, "NORMAL": {n}, "TEXCOORD_0": {t}}}, "indices": {i}, "material": 0}}"#
    )]);
    g.mesh(&[format!(
        r#"{{"attributes": {{"POSITION": {p8}, "TEXCOORD_0": {t16}}}, "material": 0}}"#
    )]);
    g.node(r#""mesh": 0, "scale": [0.001, 0.001, 0.001]"#);
    g.node(r#""mesh": 1, "translation": [0.0, 0.0, 1.0]"#);
    g.roots = vec![0, 1];
    g.extensions_used.push("KHR_mesh_quantization".into());
    g.extensions_required.push("KHR_mesh_quantization".into());
    dir.write("q.glb", g.glb());
    let s = dir.load(&scene_toml(&["q.glb"], "")).unwrap();
    assert_eq!(s.triangles.len(), 3);
    let expect_uv = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 32768.0 / 65535.0]];
    for k in 0..2 {
        let (t, a) = (&s.triangles[k], &s.attributes[k]);
        for c in 0..3 {
            let i = QUAD_INDICES[3 * k + c] as usize;
            assert!((t.v[c] - Vec3::from(QUAD[i])).length() < 1e-6, "{}", t.v[c]);
            assert_eq!(t.n[c], Vec3::Z);
            assert!(close2(a.uv[c], Vec2::from(expect_uv[i])), "{}", a.uv[c]);
        }
    }
    let (t, a) = (&s.triangles[2], &s.attributes[2]);
    assert_eq!(
        t.v,
        [
            Vec3::new(-1.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(0.0, 1.0, 1.0)
        ]
    );
    assert_eq!(a.uv[0], Vec2::new(-1.0, 1.0));
    assert!(close2(a.uv[1], Vec2::new(16384.0 / 32767.0, 0.0)));
    assert!(close2(a.uv[2], Vec2::new(0.0, -16384.0 / 32767.0)));
}

#[test]
fn gltf_vertex_colours_of_integer_types() {
    let dir = TestDir::new("colours");
    let mut g = quad(None);
    let c8: Vec<u8> = [
        [255u8, 0, 0, 255],
        [0, 255, 0, 0],
        [0, 0, 255, 51],
        [255; 4],
    ]
    .concat();
    let c8 = g.typed(&c8, 5121, "VEC4", 4, r#", "normalized": true"#);
    let c16: Vec<u8> = [
        [65535u16, 0, 0, 0],
        [0, 65535, 0, 0],
        [0, 0, 65535, 0],
        [0; 4],
    ]
    .iter()
    .flatten()
    .flat_map(|x| x.to_le_bytes())
    .collect();
    let v16 = strided(&mut g, &c16, 8);
    let c16 = g.accessor(format!(
        r#"{{"bufferView": {v16}, "componentType": 5123, "normalized": true, "count": 4, "type": "VEC3"}}"#
    ));
    g.material(r#"{"name": "vc"}"#);
    g.meshes[0] = format!(
        r#"{{"primitives": [{{"attributes": {{"POSITION": 0, "COLOR_0": {c8}}}, "indices": 1, "material": 0}},
        {{"attributes": {{"POSITION": 0, "COLOR_0": {c16}}}, "indices": 1, "material": 0}},
        {{"attributes": {{"POSITION": 0}}, "indices": 1, "material": 0}}]}}"#
    );
    g.node(r#""mesh": 0"#);
    dir.write("c.gltf", g.gltf());
    let s = dir.load(&scene_toml(&["c.gltf"], "")).unwrap();
    assert!(material(&s, "vc").vertex_colors);
    let a = &s.attributes;
    assert_eq!(a.len(), 6);
    // Triangle 0 is vertices 0, 1, 2.
    assert_eq!(a[0].color[0], Vec4::new(1.0, 0.0, 0.0, 1.0));
    assert_eq!(a[0].color[1], Vec4::new(0.0, 1.0, 0.0, 0.0));
    assert_eq!(a[0].color[2], Vec4::new(0.0, 0.0, 1.0, 0.2));
    // VEC3: alpha 1.
    assert_eq!(a[2].color[1], Vec4::new(0.0, 1.0, 0.0, 1.0));
    // The primitive without COLOR_0: colour 1.
    assert_eq!(a[4], TriAttributes::NONE);
    assert_eq!(a[5], TriAttributes::NONE);
}

// ---------------------------------------------------------------------------------------
// Hostile glTF
// ---------------------------------------------------------------------------------------

#[test]
fn hostile_attribute_accessors_get_one_clear_error() {
    let dir = TestDir::new("hostile-attrs");
    let textured = r#"{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}"#;
    // (attributes beyond POSITION, make extra accessors, expected words)
    type Extra = fn(&mut Gltf) -> String;
    let cases: [(Extra, &[&str]); 6] = [
        (
            |g| {
                format!(
                    r#""COLOR_0": {}"#,
                    g.typed(&[0u8; 16], 5126, "SCALAR", 4, "")
                )
            },
            &[
                "COLOR_0 (accessor",
                "is Scalar of F32; expected Vec3 or Vec4 of F32 or U8 or U16",
            ],
        ),
        (
            |_| r#""TEXCOORD_0": 99"#.to_string(),
            &["TEXCOORD_0", "index out of bounds"],
        ),
        (
            |g| {
                let v = g.view(&[0u8; 8]);
                let a = g.accessor(format!(
                    r#"{{"bufferView": {v}, "componentType": 5126, "count": 4, "type": "VEC2"}}"#
                ));
                format!(r#""TEXCOORD_0": {a}"#)
            },
            &["TEXCOORD_0 (accessor", "do not fit in buffer view"],
        ),
        (
            |g| format!(r#""COLOR_0": {}"#, g.typed(&[0u8; 16], 5121, "VEC4", 4, "")),
            &["COLOR_0 (accessor", "U8 components must be normalized"],
        ),
        (
            |g| format!(r#""TEXCOORD_0": {}"#, g.vec2(&[[0.0, 0.0]; 3])),
            &["TEXCOORD_0 has 3 elements but POSITION has 4"],
        ),
        (
            |g| {
                format!(
                    r#""TEXCOORD_0": {}"#,
                    g.typed(&[0u8; 32], 5125, "VEC2", 4, "")
                )
            },
            &["TEXCOORD_0 (accessor", "of U32"],
        ),
    ];
    for (k, (extra, words)) in cases.iter().enumerate() {
        let mut g = Gltf::default();
        let p = g.positions(&QUAD);
        let i = g.indices(&QUAD_INDICES);
        let png = g.view(&png_rgba(2, 2, &TEXELS));
        g.images.push(format!(
            r#"{{"bufferView": {png}, "mimeType": "image/png"}}"#
        ));
        g.material(textured);
        let more = extra(&mut g);
        g.mesh(&[format!(
            r#"{{"attributes": {{"POSITION": {p}, {more}}}, "indices": {i}, "material": 0}}"#
        )]);
        g.node(r#""mesh": 0"#);
        let name = format!("h{k}.gltf");
        dir.write(&name, g.gltf());
        expect_err(dir.load(&scene_toml(&[&name], "")), &name, words);
    }
    // A negative alphaCutoff, a baseColorFactor alpha outside [0, 1].
    for (k, (mat, words)) in [
        (
            r#"{"alphaMode": "MASK", "alphaCutoff": -1}"#,
            &["alphaCutoff -1 must be a number >= 0"][..],
        ),
        (
            r#"{"pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 2]}}"#,
            &["baseColorFactor alpha 2 must be in [0, 1]"][..],
        ),
    ]
    .iter()
    .enumerate()
    {
        let mut g = quad(Some(0));
        g.material(mat);
        g.node(r#""mesh": 0"#);
        let name = format!("m{k}.gltf");
        dir.write(&name, g.gltf());
        expect_err(dir.load(&scene_toml(&[&name], "")), &name, words);
    }
}

#[test]
fn extensions_read_now_are_accepted_when_required_and_others_still_refused() {
    let dir = TestDir::new("required-read");
    for ext in [
        "KHR_texture_transform",
        "KHR_mesh_quantization",
        "KHR_materials_unlit",
        "EXT_mesh_gpu_instancing",
    ] {
        let mut g = quad(None);
        g.node(r#""mesh": 0"#);
        g.extensions_used.push(ext.into());
        g.extensions_required.push(ext.into());
        dir.write("r.gltf", g.gltf());
        let s = dir.load(&scene_toml(&["r.gltf"], ""));
        assert!(s.is_ok(), "{ext}: {}", s.err().unwrap());
    }
    let mut g = quad(None);
    g.node(r#""mesh": 0"#);
    g.extensions_used = vec!["KHR_mesh_quantization".into(), "KHR_texture_basisu".into()];
    g.extensions_required = g.extensions_used.clone();
    dir.write("r.gltf", g.gltf());
    let msg = expect_err(
        dir.load(&scene_toml(&["r.gltf"], "")),
        "r.gltf",
        &["KHR_texture_basisu (KTX2"],
    );
    assert!(!msg.contains("KHR_mesh_quantization"), "{msg}");
}

#[test]
fn unlit_materials_are_diffuse_of_their_base_colour() {
    let dir = TestDir::new("unlit");
    let mut g = quad(Some(0));
    g.material(
        r#"{"name": "u", "extensions": {"KHR_materials_unlit": {}}, "pbrMetallicRoughness": {"baseColorFactor": [0.2, 0.4, 0.6, 1], "metallicFactor": 1.0, "roughnessFactor": 0.0}}"#,
    );
    g.node(r#""mesh": 0"#);
    g.extensions_used.push("KHR_materials_unlit".into());
    dir.write("u.gltf", g.gltf());
    let s = dir.load(&scene_toml(&["u.gltf"], "")).unwrap();
    let m = material(&s, "u");
    // Smooth metal would be a mirror; unlit shows its colour as a diffuse surface.
    assert_eq!(m.diffuse, Vec3::new(0.2, 0.4, 0.6));
    assert_eq!(m.mirror, Vec3::ZERO);
}

// ---------------------------------------------------------------------------------------
// OBJ and MTL
// ---------------------------------------------------------------------------------------

const OBJ: &str = "mtllib m.mtl
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 0.25
usemtl tex
f 1/1 2/2 3/3
usemtl shared
f 1/1 3/3 4/4
usemtl missing
f 1/1 2/2 3/3
usemtl glass
f 1 2 3
usemtl badsize
f 1 2 3
usemtl plain
f 1 3 4
";

const MTL: &str = "newmtl tex
map_Kd -clamp on -o 0.25 0.5 -s 2 2 tex.png
map_d mask.png
d 0.75
newmtl shared
Kd 0.5 0.5 0.5
map_Kd tex.png
newmtl missing
Kd 0.2 0.3 0.4
map_Kd nothere.png
newmtl glass
Kd 1 1 1
Tr 0.8
newmtl badsize
map_Kd tex.png
map_d small.png
newmtl plain
Kd 0.1 0.1 0.1
";

fn obj_dir(tag: &str) -> TestDir {
    let dir = TestDir::new(tag);
    dir.write("m.obj", OBJ);
    dir.write("m.mtl", MTL);
    dir.write("tex.png", png_rgba(2, 2, &TEXELS));
    dir.write("mask.png", png_grey(2, 2, &[0, 100, 200, 255]));
    dir.write("small.png", png_grey(1, 1, &[0]));
    dir
}

#[test]
fn obj_vt_map_kd_map_d_and_d() {
    let dir = obj_dir("obj-maps");
    let s = dir.load(&scene_toml(&["m.obj"], "")).unwrap();
    let tex = material(&s, "tex");
    // map_Kd without Kd: the texture alone.
    assert_eq!(tex.diffuse, Vec3::ONE);
    let t = tex.texture.expect("a texture");
    assert_eq!(t.sampler.wrap_s, Wrap::ClampToEdge);
    assert_eq!(t.sampler.wrap_t, Wrap::ClampToEdge);
    // MTL U = 2u + 0.25, V = 2v + 0.5 (v up) on coordinates stored as (u, 1 - v).
    let (u, v) = (0.3, 0.1);
    let got = t.transform.apply(Vec2::new(u, 1.0 - v));
    assert!(
        close2(got, Vec2::new(2.0 * u + 0.25, 1.0 - (2.0 * v + 0.5))),
        "{got}"
    );
    // Colour from map_Kd, alpha from map_d's grey (it has no alpha channel).
    let texels = &s.textures[t.texture as usize].levels[0].texels;
    let expect: Vec<[u8; 4]> = TEXELS
        .iter()
        .zip([0, 100, 200, 255])
        .map(|(&[r, g, b, _], a)| [r, g, b, a])
        .collect();
    assert_eq!(texels, &expect);
    assert_eq!(
        tex.alpha,
        Alpha {
            mode: AlphaMode::Mask { cutoff: 0.5 },
            factor: 0.75
        }
    );
    // vt with v' = 1 - v, on the corners of the face.
    let tri = triangles_of(&s, "tex");
    assert_eq!(tri.len(), 1);
    assert_eq!(
        tri[0].1.uv,
        [
            Vec2::new(0.0, 1.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(1.0, 0.0)
        ]
    );
    assert_eq!(tri[0].1.color, [Vec4::ONE; 3]);
    let shared = triangles_of(&s, "shared");
    assert_eq!(shared[0].1.uv[2], Vec2::new(0.0, 0.75));

    // The same file without map_d: its own texture (alpha 255: MTL's opacity is d and
    // map_d), the image decoded once and listed once.
    let sh = material(&s, "shared");
    assert_eq!(sh.diffuse, Vec3::splat(0.5));
    let st = sh.texture.expect("a texture");
    assert_ne!(st.texture, t.texture);
    assert_eq!(st.sampler, Sampler::DEFAULT);
    assert!(s.textures[st.texture as usize].levels[0]
        .texels
        .iter()
        .all(|t| t[3] == 255));
    assert_eq!(sh.alpha, Alpha::OPAQUE);
    let listed = |name: &str| s.files.iter().filter(|f| f.ends_with(name)).count();
    assert_eq!(listed("tex.png"), 1, "{:?}", s.files);
    assert_eq!(listed("mask.png"), 1);

    // A missing file: a warning, and the factor.
    let missing = material(&s, "missing");
    assert_eq!(missing.texture, None);
    assert_eq!(missing.diffuse, Vec3::new(0.2, 0.3, 0.4));
    // Tr 0.8 is d 0.2: below the cutoff, no texture: cut out everywhere.
    let glass = material(&s, "glass").alpha;
    assert_eq!(glass.mode, AlphaMode::Mask { cutoff: 0.5 });
    assert!((glass.factor - 0.2).abs() < 1e-6, "{glass:?}");
    // map_d of another size than map_Kd: ignored, and with d 1 the material is opaque.
    let bad = material(&s, "badsize");
    assert!(bad.texture.is_some());
    assert_eq!(bad.alpha, Alpha::OPAQUE);
    // A face without vt of a textured material: uv 0.
    assert_eq!(triangles_of(&s, "badsize")[0].1.uv, [Vec2::ZERO; 3]);
    assert_eq!(material(&s, "plain").texture, None);
    // Only the used textures are kept: tex + mask, tex alone, tex for badsize.
    assert_eq!(
        s.textures.len(),
        2,
        "badsize shares tex.png alone with 'shared'"
    );
    assert_eq!(bad.texture.unwrap().texture, st.texture);
}

#[test]
fn mtl_textures_are_shared_across_obj_files_and_missing_ones_load() {
    let dir = obj_dir("obj-shared");
    std::fs::create_dir_all(dir.path("sub")).unwrap();
    // Another OBJ in another folder whose MTL names the same image by another path.
    dir.write(
        "sub/o.obj",
        "mtllib o.mtl\nv 0 0 1\nv 1 0 1\nv 0 1 1\nvt 0 0\nusemtl other\nf 1/1 2/1 3/1\n",
    );
    dir.write("sub/o.mtl", "newmtl other\nmap_Kd ../tex.png\n");
    let s = dir.load(&scene_toml(&["m.obj", "sub/o.obj"], "")).unwrap();
    let other = material(&s, "other").texture.unwrap().texture;
    assert_eq!(other, material(&s, "shared").texture.unwrap().texture);
    let listed: Vec<_> = s.files.iter().filter(|f| f.ends_with("tex.png")).collect();
    assert_eq!(listed.len(), 1, "{listed:?}");

    // Every map missing: the scene loads, materials keep their factors.
    std::fs::remove_file(dir.path("tex.png")).unwrap();
    std::fs::remove_file(dir.path("mask.png")).unwrap();
    std::fs::remove_file(dir.path("small.png")).unwrap();
    let s = dir.load(&scene_toml(&["m.obj"], "")).unwrap();
    assert!(s.textures.is_empty());
    assert!(s.attributes.is_empty(), "no material uses attributes");
    assert_eq!(material(&s, "tex").diffuse, Vec3::ONE);
    // map_d missing too: d alone decides (0.75: a cut-out, but all there).
    assert_eq!(material(&s, "tex").alpha, Alpha::OPAQUE);
}

#[test]
fn mtl_opacities_out_of_range_are_errors() {
    let dir = TestDir::new("mtl-d");
    dir.write(
        "m.obj",
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n",
    );
    for (line, words) in [
        ("d 1.5", &["m.mtl:3", "d must be in [0, 1]"][..]),
        ("Tr -0.1", &["m.mtl:3", "Tr must be in [0, 1]"][..]),
        ("Tr x", &["m.mtl:3", "Tr needs a number"][..]),
    ] {
        dir.write("m.mtl", format!("newmtl a\nKd 1 1 1\n{line}\n"));
        expect_err(dir.load(&scene_toml(&["m.obj"], "")), "m.mtl", words);
    }
}

// ---------------------------------------------------------------------------------------
// [materials.NAME] over textures
// ---------------------------------------------------------------------------------------

#[test]
fn toml_colours_replace_textures_and_texture_false_takes_the_mean() {
    let dir = obj_dir("toml-over");
    let toml = "[materials.tex]\ndiffuse = [0.5, 0.5, 0.5]\n\
                [materials.shared]\ntexture = false\n\
                [materials.badsize]\ntexture = true\n";
    let s = dir.load(&scene_toml(&["m.obj"], toml)).unwrap();
    // A colour set in the scene file: no texture; map_d went with it, d stays.
    let tex = material(&s, "tex");
    assert_eq!(tex.texture, None);
    assert_eq!(tex.diffuse, Vec3::splat(0.5));
    assert_eq!(
        tex.alpha,
        Alpha::OPAQUE,
        "d 0.75 over the cutoff, nothing varies"
    );
    // texture = false: the factor times the texture's mean, opaque.
    let shared = material(&s, "shared");
    assert_eq!(shared.texture, None);
    let first = load_scene(&dir.write("plain.toml", scene_toml(&["m.obj"], ""))).unwrap();
    let t = material(&first, "shared").texture.unwrap();
    let mean = first.textures[t.texture as usize].mean().truncate();
    assert!(
        (shared.diffuse - 0.5 * mean).length() < 1e-6,
        "{}",
        shared.diffuse
    );
    assert_eq!(shared.alpha, Alpha::OPAQUE);
    // texture = true is what a material has anyway.
    assert!(material(&s, "badsize").texture.is_some());
    // The replaced textures are not kept: only badsize's remains.
    assert_eq!(s.textures.len(), 1);
}

#[test]
fn toml_mirror_drops_vertex_colours_and_attributes_follow_the_materials() {
    let dir = TestDir::new("toml-vc");
    let mut g = quad(None);
    let c = g.vec4(&[[0.5; 4]; 4]);
    g.material(r#"{"name": "vc"}"#);
    g.meshes[0] = format!(
        r#"{{"primitives": [{{"attributes": {{"POSITION": 0, "COLOR_0": {c}}}, "indices": 1, "material": 0}}]}}"#
    );
    g.node(r#""mesh": 0"#);
    dir.write("c.gltf", g.gltf());
    dir.write("p.obj", "v 0 0 1\nv 1 0 1\nv 0 1 1\nusemtl p\nf 1 2 3\n");
    let with = dir
        .load(&scene_toml(
            &["p.obj", "c.gltf"],
            "[materials.p]\ndiffuse = [0.5, 0.5, 0.5]\n",
        ))
        .unwrap();
    assert!(material(&with, "vc").vertex_colors);
    // One entry per triangle, NONE for the OBJ's, the glTF's after it.
    assert_eq!(with.attributes.len(), 3);
    assert_eq!(with.attributes[0], TriAttributes::NONE);
    assert_eq!(with.attributes[1].color, [Vec4::splat(0.5); 3]);
    let without = dir
        .load(&scene_toml(
            &["p.obj", "c.gltf"],
            "[materials.p]\ndiffuse = [0.5, 0.5, 0.5]\n[materials.vc]\ndiffuse = [0.5, 0.5, 0.5]\nmirror = [0.1, 0.1, 0.1]\n",
        ))
        .unwrap();
    let vc = material(&without, "vc");
    assert!(!vc.vertex_colors);
    assert_eq!(vc.mirror, Vec3::splat(0.1));
    assert!(without.attributes.is_empty());
}

// ---------------------------------------------------------------------------------------
// The Khronos samples
// ---------------------------------------------------------------------------------------

/// Every sample of `shared/gltf-samples` loads through its `scene.toml` (Box-Draco is
/// refused, naming Draco), and those that exercise textures, vertex colours, alpha and
/// texture transforms get them.
#[test]
fn every_gltf_sample_loads() {
    let samples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/gltf-samples");
    if !samples.is_dir() {
        eprintln!("skipped: {} is absent", samples.display());
        return;
    }
    let mut names: Vec<String> = std::fs::read_dir(&samples)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.path().join("scene.toml").is_file())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert!(names.len() >= 14, "{names:?}");
    for name in &names {
        let r = load_scene(&samples.join(name).join("scene.toml"));
        if name == "Box-Draco" {
            let e = r.expect_err("Draco is refused").to_string();
            assert!(e.contains("Draco"), "{e}");
            continue;
        }
        let s = r.unwrap_or_else(|e| panic!("{name}: {e}"));
        let textured = s.materials.iter().filter(|m| m.texture.is_some()).count();
        let masked = s.materials.iter().filter(|m| m.alpha_tested()).count();
        eprintln!(
            "{name}: {} triangles, {} materials, {textured} textured, {masked} alpha-tested, {} textures",
            s.triangles.len(),
            s.materials.len(),
            s.textures.len()
        );
        assert!(s.attributes.is_empty() || s.attributes.len() == s.triangles.len());
        assert_eq!(
            s.attributes.is_empty(),
            !s.materials.iter().any(|m| m.uses_attributes()),
            "{name}"
        );
        for m in &s.materials {
            if let Some(t) = m.texture {
                assert!((t.texture as usize) < s.textures.len(), "{name}");
            }
        }
        match name.as_str() {
            "BoxTextured" | "TextureCoordinateTest" | "MultiUVTest" => {
                assert!(textured > 0, "{name}")
            }
            "VertexColorTest" => assert!(s.materials.iter().any(|m| m.vertex_colors)),
            "AlphaBlendModeTest" => assert!(masked > 0),
            "TextureTransformTest" => assert!(s.materials.iter().any(|m| m
                .texture
                .is_some_and(|t| t.transform != UvTransform::IDENTITY))),
            "TextureSettingsTest" => assert!(s
                .materials
                .iter()
                .any(|m| m.texture.is_some_and(|t| t.sampler != Sampler::DEFAULT))),
            _ => {}
        }
    }
}
