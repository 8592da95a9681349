//! Tests of glTF 2.0 meshes in scenes (`igi_core::scene::gltf`, through the loader):
//! geometry under node transforms, materials, KHR_lights_punctual point lights, `.glb`
//! against `.gltf`, textures, and errors.
//!
//! Every test writes its own glTF files with [`Gltf`] (`tests/common/gltf_builder.rs`), a
//! small builder of the JSON (with the binary data as a base64 `data:` URI, an external
//! `.bin` file, or a GLB's BIN chunk) from f32/u16 arrays. Every error test checks that
//! the message is one line and names the file at fault.

#[path = "common/test_dir.rs"]
mod test_dir;
use std::path::Path;
use test_dir::{expect_err, TestDir, CAMERA, LIGHT};

use igi_core::scene::gltf::{load_gltf, LUMENS_PER_WATT};
use igi_core::scene::Scene;
use igi_core::Vec3;

#[path = "common/gltf_builder.rs"]
mod gltf_builder;
use gltf_builder::*;

// ---------------------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------------------

/// A scene with the test camera, one `[[mesh]]` of `path`, and `extra` TOML.
fn scene_toml(path: &str, extra: &str) -> String {
    format!("{CAMERA}\n[[mesh]]\npath = \"{path}\"\n\n{extra}")
}

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).length() < 1e-5
}

fn assert_close(a: Vec3, b: Vec3) {
    assert!(close(a, b), "{a} != {b}");
}

/// The material of triangle `t` in `s`.
fn material_of(s: &Scene, t: usize) -> &igi_core::scene::Material {
    &s.materials[s.triangles[t].material as usize]
}

fn material<'a>(s: &'a Scene, name: &str) -> &'a igi_core::scene::Material {
    s.materials
        .iter()
        .find(|m| m.name == name)
        .unwrap_or_else(|| panic!("no material {name} in {:?}", s.materials))
}

/// Every triangle's vertices, in order.
fn vertices(s: &Scene) -> Vec<Vec3> {
    s.triangles.iter().flat_map(|t| t.v).collect()
}

// ---------------------------------------------------------------------------------------
// Geometry
// ---------------------------------------------------------------------------------------

#[test]
fn quad_with_translation_and_scale() {
    let dir = TestDir::new("quad-ts");
    let mut g = quad(None);
    g.node(r#""mesh": 0, "translation": [1.0, 2.0, 3.0], "scale": [2.0, 2.0, 2.0]"#);
    dir.write("quad.gltf", g.gltf());
    let s = dir.load(&scene_toml("quad.gltf", LIGHT)).unwrap();
    assert_eq!(s.triangles.len(), 2);
    let expect: Vec<Vec3> = QUAD_INDICES
        .iter()
        .map(|&i| Vec3::from(QUAD[i as usize]) * 2.0 + Vec3::new(1.0, 2.0, 3.0))
        .collect();
    for (a, b) in vertices(&s).into_iter().zip(expect) {
        assert_close(a, b);
    }
    for t in &s.triangles {
        // No NORMAL: the geometric normal, +z for this winding.
        assert_eq!(t.n, [Vec3::Z; 3]);
    }
    // No material: glTF's default material (base colour 1, rough: all diffuse).
    assert_eq!(s.materials.len(), 1);
    assert_eq!(s.materials[0].name, "gltf:default");
    assert_eq!(s.materials[0].diffuse, Vec3::ONE);
    assert_eq!(s.materials[0].mirror, Vec3::ZERO);
    assert!(s.files.iter().any(|f| f.ends_with("quad.gltf")));
}

#[test]
fn node_hierarchy_multiplies_down_the_tree() {
    let dir = TestDir::new("hierarchy");
    let mut g = Gltf::default();
    let p = g.positions(&QUAD);
    let n = g.normals(&[[0.0, 0.0, 1.0]; 4]);
    let i = g.indices(&QUAD_INDICES);
    g.mesh(&[format!(
        r#"{{"attributes": {{"POSITION": {p}, "NORMAL": {n}}}, "indices": {i}}}"#
    )]);
    // Parent: translate (0, 0, 5) after a rotation of 90 degrees about +y; child:
    // translate (1, 0, 0). World = T(0, 0, 5) R_y(90) T(1, 0, 0).
    let h = std::f32::consts::FRAC_1_SQRT_2;
    g.node(&format!(
        r#""children": [1], "translation": [0.0, 0.0, 5.0], "rotation": [0.0, {h}, 0.0, {h}]"#
    ));
    g.node(r#""mesh": 0, "translation": [1.0, 0.0, 0.0]"#);
    dir.write("tree.gltf", g.gltf());
    let s = dir.load(&scene_toml("tree.gltf", LIGHT)).unwrap();
    assert_eq!(s.triangles.len(), 2);
    // R_y(90): x -> -z, z -> x.
    let world = |p: [f32; 3]| {
        let q = Vec3::from(p) + Vec3::X;
        Vec3::new(q.z, q.y, -q.x) + Vec3::new(0.0, 0.0, 5.0)
    };
    let expect: Vec<Vec3> = QUAD_INDICES
        .iter()
        .map(|&i| world(QUAD[i as usize]))
        .collect();
    for (a, b) in vertices(&s).into_iter().zip(expect) {
        assert_close(a, b);
    }
    for t in &s.triangles {
        for n in t.n {
            assert_close(n, Vec3::X); // +z rotated
        }
        assert_close(t.cross().normalize(), Vec3::X);
    }
}

#[test]
fn mirrored_node_keeps_winding_and_normals_consistent() {
    let dir = TestDir::new("mirror-node");
    let mut g = Gltf::default();
    let p = g.positions(&QUAD);
    let n = g.normals(&[[0.0, 0.0, 1.0]; 4]);
    let i = g.indices(&QUAD_INDICES);
    g.mesh(&[format!(
        r#"{{"attributes": {{"POSITION": {p}, "NORMAL": {n}}}, "indices": {i}}}"#
    )]);
    // Non-uniform scale with a negative determinant: normals by the inverse transpose.
    g.node(r#""mesh": 0, "scale": [-1.0, 2.0, 1.0]"#);
    dir.write("m.gltf", g.gltf());
    let s = dir.load(&scene_toml("m.gltf", LIGHT)).unwrap();
    assert_eq!(s.triangles.len(), 2);
    for t in &s.triangles {
        for v in t.v {
            assert!(v.x <= 0.0 && v.y >= 0.0 && v.z == 0.0, "{v}");
        }
        // Two vertices swapped: the geometric normal is on the side of the shading normals.
        assert_close(t.cross().normalize(), Vec3::Z);
        assert_eq!(t.n, [Vec3::Z; 3]);
    }
    assert_close(s.triangles[0].v[1], Vec3::new(-1.0, 2.0, 0.0));
    assert_close(s.triangles[0].v[2], Vec3::new(-1.0, 0.0, 0.0));
}

#[test]
fn strips_fans_points_and_non_indexed_primitives() {
    let dir = TestDir::new("modes");
    let mut g = Gltf::default();
    // Non-indexed TRIANGLES: the vertices in threes.
    let tri = g.positions(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    // A strip and a fan over the quad's corners (strip order 0 1 3 2).
    let strip = g.positions(&[QUAD[0], QUAD[1], QUAD[3], QUAD[2]]);
    let fan = g.positions(&QUAD);
    // Points, and a degenerate triangle (all on a line).
    let line = g.positions(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]]);
    g.mesh(&[
        primitive(tri, None, ""),
        primitive(strip, None, r#", "mode": 5"#),
        primitive(fan, None, r#", "mode": 6"#),
        primitive(line, None, r#", "mode": 0"#),
        primitive(line, None, ""),
    ]);
    g.node(r#""mesh": 0"#);
    dir.write("modes.gltf", g.gltf());
    let s = dir.load(&scene_toml("modes.gltf", LIGHT)).unwrap();
    assert_eq!(s.triangles.len(), 1 + 2 + 2);
    for t in &s.triangles {
        // Every triangle of a strip or fan is counter-clockwise, like the source.
        assert_close(t.cross().normalize(), Vec3::Z);
    }
    let area: f32 = s.triangles.iter().map(|t| t.area()).sum();
    assert!((area - 2.5).abs() < 1e-6, "{area}");
}

#[test]
fn sparse_positions_without_a_buffer_view() {
    let dir = TestDir::new("sparse");
    // Zeros, with vertices 1 to 3 replaced by the quad's: the quad again.
    let g = sparse_quad(&[1, 2, 3], 5123);
    dir.write("sparse.gltf", g.gltf());
    let s = dir.load(&scene_toml("sparse.gltf", LIGHT)).unwrap();
    let expect: Vec<Vec3> = QUAD_INDICES
        .iter()
        .map(|&i| Vec3::from(QUAD[i as usize]))
        .collect();
    assert_eq!(vertices(&s), expect);
}

// ---------------------------------------------------------------------------------------
// Materials
// ---------------------------------------------------------------------------------------

/// Four materials on four copies of the quad: red plastic, smooth chrome, rough gold, and
/// an unnamed half-metallic one.
fn materials_gltf() -> Gltf {
    let mut g = Gltf::default();
    let p = g.positions(&QUAD);
    let i = g.indices(&QUAD_INDICES);
    g.material(
        r#"{"name": "red", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.1, 0.1, 1.0], "metallicFactor": 0.0}}"#,
    );
    g.material(
        r#"{"name": "chrome", "pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.9, 0.9, 1.0], "metallicFactor": 1.0, "roughnessFactor": 0.1}}"#,
    );
    g.material(
        r#"{"name": "gold", "pbrMetallicRoughness": {"baseColorFactor": [1.0, 0.8, 0.3, 1.0], "roughnessFactor": 0.5}}"#,
    );
    g.material(
        r#"{"pbrMetallicRoughness": {"baseColorFactor": [0.6, 0.6, 0.6, 1.0], "metallicFactor": 0.5, "roughnessFactor": 0.0}, "emissiveFactor": [1.0, 1.0, 1.0]}"#,
    );
    let prims: Vec<String> = (0..4)
        .map(|m| primitive(p, Some(i), &format!(r#", "material": {m}"#)))
        .collect();
    g.mesh(&prims);
    g.node(r#""mesh": 0"#);
    g
}

#[test]
fn materials_from_metallic_roughness() {
    let dir = TestDir::new("materials");
    dir.write("mats.gltf", materials_gltf().gltf());
    let s = dir.load(&scene_toml("mats.gltf", LIGHT)).unwrap();
    assert_eq!(s.triangles.len(), 8);
    let names: Vec<&str> = s.materials.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["red", "chrome", "gold", "gltf:mats:3"]);
    assert_eq!(material_of(&s, 0).name, "red");
    assert_eq!(material_of(&s, 7).name, "gltf:mats:3");

    // baseColorFactor -> diffuse for a dielectric.
    let red = material(&s, "red");
    assert_close(red.diffuse, Vec3::new(0.8, 0.1, 0.1));
    assert_eq!(red.mirror, Vec3::ZERO);
    // Smooth metal: a mirror of the base colour.
    let chrome = material(&s, "chrome");
    assert_eq!(chrome.diffuse, Vec3::ZERO);
    assert_close(chrome.mirror, Vec3::splat(0.9));
    // Rough metal (metallic 1 by default, roughness 0.5): diffuse, no mirror.
    let gold = material(&s, "gold");
    assert_close(gold.diffuse, Vec3::new(1.0, 0.8, 0.3));
    assert_eq!(gold.mirror, Vec3::ZERO);
    // Half metallic and smooth: split; emission ignored.
    let half = material(&s, "gltf:mats:3");
    assert_close(half.diffuse, Vec3::splat(0.3));
    assert_close(half.mirror, Vec3::splat(0.3));
}

#[test]
fn toml_overrides_gltf_materials_key_by_key() {
    let dir = TestDir::new("override");
    dir.write("mats.gltf", materials_gltf().gltf());
    let extra = format!(
        "{LIGHT}\n[materials.red]\nmirror = [0.1, 0.0, 0.0]\n\n[materials.\"gltf:mats:3\"]\ndiffuse = [0.2, 0.2, 0.2]\n"
    );
    let s = dir.load(&scene_toml("mats.gltf", &extra)).unwrap();
    let red = material(&s, "red");
    assert_close(red.diffuse, Vec3::new(0.8, 0.1, 0.1)); // from the glTF
    assert_close(red.mirror, Vec3::new(0.1, 0.0, 0.0)); // from the TOML
    let half = material(&s, "gltf:mats:3");
    assert_close(half.diffuse, Vec3::splat(0.2));
    assert_close(half.mirror, Vec3::splat(0.3));

    // An override that breaks diffuse + mirror <= 1 names the glTF value's origin.
    let extra = format!("{LIGHT}\n[materials.chrome]\ndiffuse = [0.5, 0.5, 0.5]\n");
    expect_err(
        dir.load(&scene_toml("mats.gltf", &extra)),
        "scene.toml",
        &["'chrome'", "mirror of glTF material 'chrome'", "mats.gltf"],
    );
}

#[test]
fn default_material_of_the_mesh_applies_to_primitives_without_one() {
    let dir = TestDir::new("default-material");
    let mut g = quad(None);
    g.node(r#""mesh": 0"#);
    dir.write("q.gltf", g.gltf());
    let toml = format!(
        "{CAMERA}\n[[mesh]]\npath = \"q.gltf\"\ndefault_material = \"grey\"\n\n{LIGHT}\n[materials.grey]\ndiffuse = [0.5, 0.5, 0.5]\n"
    );
    let s = dir.load(&toml).unwrap();
    assert_eq!(s.materials.len(), 1);
    assert_eq!(s.materials[0].name, "grey");
    assert_eq!(s.materials[0].diffuse, Vec3::splat(0.5));
}

/// A 2x2 RGB8 PNG of the given sRGB texels.
fn png_2x2(texels: [[u8; 3]; 4]) -> Vec<u8> {
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, 2, 2);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let mut w = enc.write_header().expect("png header");
        w.write_image_data(texels.as_flattened()).expect("png data");
    }
    out
}

#[test]
fn base_color_texture_becomes_a_texture() {
    let dir = TestDir::new("texture");
    let texels = [[255, 0, 0], [0, 255, 0], [0, 0, 255], [128, 64, 32]];
    dir.write("tex.png", png_2x2(texels));
    dir.write("bad.png", b"not a png at all");
    let mut g = Gltf::default();
    let p = g.positions(&QUAD);
    let i = g.indices(&QUAD_INDICES);
    let uv = g.view(&[0u8; 32]);
    let uv = g.accessor(format!(
        r#"{{"bufferView": {uv}, "componentType": 5126, "count": 4, "type": "VEC2"}}"#
    ));
    g.images.push(r#"{"uri": "tex.png"}"#.to_string());
    g.images.push(r#"{"uri": "bad.png"}"#.to_string());
    // The same PNG again, embedded in the buffer.
    let v = g.view(&png_2x2(texels));
    g.images
        .push(format!(r#"{{"bufferView": {v}, "mimeType": "image/png"}}"#));
    g.material(
        r#"{"name": "textured", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 1.0, 1.0, 1.0], "baseColorTexture": {"index": 0}, "metallicFactor": 0.0}}"#,
    );
    g.material(
        r#"{"name": "undecodable", "pbrMetallicRoughness": {"baseColorFactor": [0.25, 0.5, 0.75, 1.0], "baseColorTexture": {"index": 1}, "metallicFactor": 0.0}}"#,
    );
    g.material(
        r#"{"name": "embedded", "pbrMetallicRoughness": {"baseColorTexture": {"index": 2}, "metallicFactor": 0.0}}"#,
    );
    let attrs = format!(r#""attributes": {{"POSITION": {p}, "TEXCOORD_0": {uv}}}"#);
    g.mesh(&[0, 1, 2].map(|m| format!(r#"{{{attrs}, "indices": {i}, "material": {m}}}"#)));
    g.node(r#""mesh": 0"#);
    dir.write("tex.gltf", g.gltf());
    let s = dir.load(&scene_toml("tex.gltf", LIGHT)).unwrap();

    // The factor stays the material's colour; the texture multiplies it where shaded.
    let m = material(&s, "textured");
    assert_eq!(m.diffuse, Vec3::new(0.5, 1.0, 1.0));
    assert_eq!(m.mirror, Vec3::ZERO);
    let t = &s.textures[m.texture.expect("a texture").texture as usize];
    assert!(t.srgb);
    let rgba: Vec<[u8; 4]> = texels.iter().map(|&[r, g, b]| [r, g, b, 255]).collect();
    assert_eq!(t.levels[0].texels, rgba);
    // An image that cannot be decoded: a warning, and the factor alone.
    let bad = material(&s, "undecodable");
    assert_eq!(bad.texture, None);
    assert_close(bad.diffuse, Vec3::new(0.25, 0.5, 0.75));
    let embedded = material(&s, "embedded");
    let e = &s.textures[embedded.texture.expect("a texture").texture as usize];
    assert_eq!(e.levels[0].texels, rgba);
    assert_eq!(s.textures.len(), 2, "the file and the buffer view");
    assert!(s.files.iter().any(|f| f.ends_with("tex.png")));
}

// ---------------------------------------------------------------------------------------
// Lights
// ---------------------------------------------------------------------------------------

#[test]
fn point_light_in_w_per_sr_at_its_node() {
    let dir = TestDir::new("light");
    let mut g = quad(None);
    g.light(r#"{"type": "point", "color": [1.0, 0.5, 0.25], "intensity": 683.0}"#);
    g.light(r#"{"type": "point", "intensity": 100.0, "range": 2.0}"#);
    g.node(r#""mesh": 0, "children": [1]"#);
    g.node(r#""translation": [1.0, 0.0, 0.0], "children": [2, 3], "scale": [3.0, 3.0, 3.0]"#);
    g.node(
        r#""translation": [0.0, 1.0, 0.0], "extensions": {"KHR_lights_punctual": {"light": 0}}"#,
    );
    g.node(
        r#""translation": [0.0, 0.0, 1.0], "extensions": {"KHR_lights_punctual": {"light": 1}}"#,
    );
    dir.write("lit.gltf", g.gltf());

    // Its lights are added to the TOML's.
    let s = dir.load(&scene_toml("lit.gltf", LIGHT)).unwrap();
    assert_eq!(s.lights.len(), 3);
    assert_eq!(s.lights[0].position, Vec3::new(0.0, 0.0, 3.0)); // the TOML's first
    assert_close(s.lights[1].position, Vec3::new(1.0, 3.0, 0.0));
    assert_close(s.lights[1].intensity, Vec3::new(1.0, 0.5, 0.25));
    assert_close(s.lights[2].position, Vec3::new(1.0, 0.0, 3.0));
    assert_close(s.lights[2].intensity, Vec3::splat(100.0 / LUMENS_PER_WATT));

    // A scene whose only lights are the glTF's passes the "at least one light" check.
    let s = dir.load(&scene_toml("lit.gltf", "")).unwrap();
    assert_eq!(s.lights.len(), 2);
}

#[test]
fn spot_and_directional_lights_are_skipped() {
    let dir = TestDir::new("spot");
    let mut g = quad(None);
    g.light(r#"{"type": "spot", "intensity": 10.0, "spot": {"outerConeAngle": 0.5}}"#);
    g.light(r#"{"type": "directional", "intensity": 3.0}"#);
    g.light(r#"{"type": "point", "intensity": 6.83}"#);
    g.node(r#""mesh": 0, "children": [1, 2, 3]"#);
    for l in 0..3 {
        g.node(&format!(
            r#""translation": [0.0, {l}.0, 2.0], "extensions": {{"KHR_lights_punctual": {{"light": {l}}}}}"#
        ));
    }
    dir.write("spot.gltf", g.gltf());
    let s = dir.load(&scene_toml("spot.gltf", "")).unwrap();
    assert_eq!(s.lights.len(), 1);
    assert_close(s.lights[0].position, Vec3::new(0.0, 2.0, 2.0));
    assert_close(s.lights[0].intensity, Vec3::splat(0.01));

    // Only a spot light, and no [[point_light]]: no light.
    let mut g = quad(None);
    g.light(r#"{"type": "spot", "intensity": 10.0, "spot": {}}"#);
    g.node(r#""mesh": 0, "extensions": {"KHR_lights_punctual": {"light": 0}}"#);
    dir.write("spot-only.gltf", g.gltf());
    expect_err(
        dir.load(&scene_toml("spot-only.gltf", "")),
        "scene.toml",
        &["[[point_light]]", "at least one light"],
    );
}

// ---------------------------------------------------------------------------------------
// .glb
// ---------------------------------------------------------------------------------------

#[test]
fn glb_equals_gltf() {
    let dir = TestDir::new("glb");
    let mut g = materials_gltf();
    g.light(r#"{"type": "point", "color": [1.0, 1.0, 1.0], "intensity": 50.0}"#);
    g.nodes[0] = r#"{"mesh": 0, "children": [1], "rotation": [0.0, 0.0, 0.38268343, 0.9238795]}"#
        .to_string();
    g.node(
        r#""translation": [0.5, 0.5, 2.0], "extensions": {"KHR_lights_punctual": {"light": 0}}"#,
    );
    dir.write("m.gltf", g.gltf());
    dir.write("m.glb", g.glb());
    // The same document with its buffer in a .bin file.
    dir.write("ext.gltf", g.json(Bin::File("ext.bin")));
    dir.write("ext.bin", &g.bin);
    let a = dir.load(&scene_toml("m.gltf", "")).unwrap();
    let b = dir.load(&scene_toml("m.glb", "")).unwrap();
    let c = dir.load(&scene_toml("ext.gltf", "")).unwrap();
    assert_eq!(a.triangles.len(), 8);
    assert_eq!(a.lights.len(), 1);
    for other in [&b, &c] {
        assert_eq!(a.triangles, other.triangles);
        assert_eq!(a.lights, other.lights);
        // Unnamed materials are named after the file's stem: "m" for both.
        let names = |s: &Scene| -> Vec<String> {
            s.materials
                .iter()
                .map(|m| m.name.replace("ext", "m"))
                .collect()
        };
        assert_eq!(names(&a), names(other));
    }
    assert!(c.files.iter().any(|f| f.ends_with("ext.bin")));
    // The extension's case does not matter, and load_gltf reads the file directly.
    dir.write("M2.GLB", g.glb());
    let direct = load_gltf(&dir.path("M2.GLB")).unwrap();
    assert_eq!(direct.triangles.len(), 8);
    let s = dir.load(&scene_toml("M2.GLB", "")).unwrap();
    assert_eq!(s.triangles, a.triangles);
}

// ---------------------------------------------------------------------------------------
// Errors
// ---------------------------------------------------------------------------------------

#[test]
fn error_missing_gltf_file() {
    let dir = TestDir::new("missing");
    expect_err(
        dir.load(&scene_toml("nothere.gltf", LIGHT)),
        "nothere.gltf",
        &["cannot read mesh", "scene.toml"],
    );
}

#[test]
fn error_missing_buffer_file() {
    let dir = TestDir::new("missing-bin");
    let mut g = quad(None);
    g.node(r#""mesh": 0"#);
    dir.write("q.gltf", g.json(Bin::File("gone.bin")));
    let msg = expect_err(
        dir.load(&scene_toml("q.gltf", LIGHT)),
        "gone.bin",
        &["buffer 0 of", "q.gltf"],
    );
    assert!(msg.contains("glTF buffer"), "{msg}");
    // A buffer file shorter than its byteLength.
    dir.write("gone.bin", &g.bin[..10]);
    expect_err(
        dir.load(&scene_toml("q.gltf", LIGHT)),
        "q.gltf",
        &["buffer 0", "byteLength"],
    );
}

#[test]
fn error_junk_bytes() {
    let dir = TestDir::new("junk");
    let junk: &[u8] = b"\x00\x01\x02 this is not glTF \xff\xfe";
    for name in ["junk.gltf", "junk.glb"] {
        dir.write(name, junk);
        expect_err(
            dir.load(&scene_toml(name, LIGHT)),
            name,
            &["not a glTF file"],
        );
    }
    // JSON, but not glTF.
    dir.write("other.gltf", "{\"hello\": 1}");
    expect_err(
        dir.load(&scene_toml("other.gltf", LIGHT)),
        "other.gltf",
        &["invalid glTF JSON", "asset"],
    );
    // GLB headers that lie: a length under 12, a length past the end, a truncated chunk.
    let mut g = quad(None);
    g.node(r#""mesh": 0"#);
    let glb = g.glb();
    let mut short = glb.clone();
    short[8..12].copy_from_slice(&4u32.to_le_bytes());
    let mut long = glb.clone();
    long[8..12].copy_from_slice(&100_000u32.to_le_bytes());
    let truncated = glb[..glb.len() - 8].to_vec();
    for (name, bytes) in [
        ("short.glb", short),
        ("long.glb", long),
        ("truncated.glb", truncated),
        ("tiny.glb", b"glTF\x02\x00".to_vec()),
    ] {
        dir.write(name, bytes);
        expect_err(dir.load(&scene_toml(name, LIGHT)), name, &["GLB"]);
    }
}

#[test]
fn error_index_out_of_range() {
    let dir = TestDir::new("index-range");
    let mut g = Gltf::default();
    let p = g.positions(&QUAD);
    let i = g.indices(&[0, 1, 2, 0, 2, 7]);
    g.mesh(&[primitive(p, Some(i), "")]);
    g.node(r#""mesh": 0"#);
    dir.write("bad.gltf", g.gltf());
    expect_err(
        dir.load(&scene_toml("bad.gltf", LIGHT)),
        "bad.gltf",
        &[
            "mesh 0 primitive 0",
            "index 7",
            "out of range",
            "4 vertices",
        ],
    );
}

#[test]
fn error_bad_accessor_references() {
    let dir = TestDir::new("accessor-refs");
    // Indices and POSITION naming accessors that do not exist (the gltf crate's
    // validation, and our check before it for POSITION).
    for (name, prim) in [
        ("indices.gltf", primitive(0, Some(99), "")),
        ("position.gltf", primitive(42, Some(1), "")),
    ] {
        let mut g = Gltf::default();
        g.positions(&QUAD);
        g.indices(&QUAD_INDICES);
        g.mesh(&[prim]);
        g.node(r#""mesh": 0"#);
        dir.write(name, g.gltf());
        expect_err(
            dir.load(&scene_toml(name, LIGHT)),
            name,
            &["invalid glTF", "meshes[0].primitives[0]", "out of bounds"],
        );
    }
    // An accessor that reads past its buffer view, one of the wrong type, one with a
    // stride smaller than its elements, and a view past its buffer.
    let cases = [
        (
            "count.gltf",
            r#"{"bufferView": 1, "componentType": 5123, "count": 60, "type": "SCALAR"}"#,
            "",
            "do not fit",
        ),
        (
            "type.gltf",
            r#"{"bufferView": 1, "componentType": 5126, "count": 1, "type": "SCALAR"}"#,
            "",
            "expected Scalar of U8 or U16 or U32",
        ),
        (
            "stride.gltf",
            r#"{"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}"#,
            "stride",
            "byteStride 4, smaller than one element",
        ),
        (
            "view.gltf",
            r#"{"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}"#,
            "view",
            "lies outside buffer 0",
        ),
    ];
    for (name, indices, tweak, needle) in cases {
        let mut g = Gltf::default();
        let p = g.positions(&QUAD);
        g.indices(&QUAD_INDICES);
        let bad = g.accessor(indices.to_string());
        match tweak {
            // POSITION's view: 12-byte elements with a stride of 4.
            "stride" => g.views[0] = g.views[0].replace('}', r#", "byteStride": 4}"#),
            "view" => g
                .views
                .push(r#"{"buffer": 0, "byteOffset": 40, "byteLength": 1000}"#.into()),
            _ => {}
        }
        g.mesh(&[primitive(p, Some(bad), "")]);
        g.node(r#""mesh": 0"#);
        dir.write(name, g.gltf());
        expect_err(dir.load(&scene_toml(name, LIGHT)), name, &[needle]);
    }
}

#[test]
fn error_non_finite_position() {
    let dir = TestDir::new("nan");
    let mut g = Gltf::default();
    let p = g.positions(&[
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [f32::NAN, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ]);
    let i = g.indices(&QUAD_INDICES);
    g.mesh(&[primitive(p, Some(i), "")]);
    g.node(r#""mesh": 0"#);
    dir.write("nan.gltf", g.gltf());
    expect_err(
        dir.load(&scene_toml("nan.gltf", LIGHT)),
        "nan.gltf",
        &["vertex 2", "not finite"],
    );
}

#[test]
fn error_node_cycle_and_bad_values() {
    let dir = TestDir::new("cycle");
    let mut g = quad(None);
    g.node(r#""mesh": 0, "children": [1]"#);
    g.node(r#""children": [0]"#);
    dir.write("cycle.gltf", g.gltf());
    expect_err(
        dir.load(&scene_toml("cycle.gltf", LIGHT)),
        "cycle.gltf",
        &["node 0", "tree"],
    );

    let mut g = quad(Some(0));
    g.material(r#"{"name": "hot", "pbrMetallicRoughness": {"metallicFactor": 2.0}}"#);
    g.node(r#""mesh": 0"#);
    dir.write("metal.gltf", g.gltf());
    expect_err(
        dir.load(&scene_toml("metal.gltf", LIGHT)),
        "metal.gltf",
        &["'hot'", "metallicFactor 2"],
    );

    let mut g = quad(None);
    g.light(r#"{"type": "point", "intensity": -1.0}"#);
    g.node(r#""mesh": 0, "extensions": {"KHR_lights_punctual": {"light": 0}}"#);
    dir.write("neg.gltf", g.gltf());
    expect_err(
        dir.load(&scene_toml("neg.gltf", LIGHT)),
        "neg.gltf",
        &["light 0", "intensity -1"],
    );
}

#[test]
fn error_messages_name_the_file_for_load_gltf() {
    let dir = TestDir::new("direct");
    let p = dir.write("x.glb", b"glTF");
    let e = load_gltf(&p).unwrap_err().to_string();
    assert!(e.contains("x.glb") && !e.contains('\n'), "{e}");
    let e = load_gltf(Path::new("/nonexistent/y.gltf")).unwrap_err();
    assert!(e.to_string().contains("y.gltf"), "{e}");
}

#[test]
fn corrupted_files_give_errors_not_panics() {
    use rand::{Rng, SeedableRng};
    let dir = TestDir::new("corrupt");
    let mut g = materials_gltf();
    g.light(r#"{"type": "point", "intensity": 5.0}"#);
    g.nodes[0] = r#"{"mesh": 0, "children": [1], "scale": [1.0, -1.0, 1.0]}"#.to_string();
    g.node(
        r#""translation": [0.5, 0.5, 2.0], "extensions": {"KHR_lights_punctual": {"light": 0}}"#,
    );
    let originals = [
        ("c.glb", g.glb()),
        ("c.gltf", g.json(Bin::DataUri).into_bytes()),
    ];
    let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
    // Digits are the likeliest to make a still-valid document with odd numbers in it.
    let replacements = b"0123456789-.e,]}\"x\x00\xff";
    let (mut ok, mut err) = (0, 0);
    for (name, original) in &originals {
        for _ in 0..400 {
            let mut bytes = original.clone();
            for _ in 0..rng.random_range(1..4) {
                let at = rng.random_range(0..bytes.len());
                bytes[at] = if rng.random_bool(0.5) {
                    replacements[rng.random_range(0..replacements.len())]
                } else {
                    rng.random()
                };
            }
            let p = dir.write(name, &bytes);
            match load_gltf(&p) {
                Ok(_) => ok += 1,
                Err(e) => {
                    let msg = e.to_string();
                    assert!(!msg.contains("internal error"), "{msg}");
                    assert!(!msg.contains('\n') && msg.contains(name), "{msg}");
                    err += 1;
                }
            }
        }
    }
    eprintln!("{ok} corrupted files loaded, {err} refused");
    assert!(err > 0);
}

// ---------------------------------------------------------------------------------------
// What a file holds that igi does not render is said
// ---------------------------------------------------------------------------------------

/// The Khronos samples of `../shared/gltf-samples` list, in `GltfMesh::ignored`, what
/// their upstream READMEs say they exercise and igi does not render.
#[test]
fn features_igi_does_not_render_are_listed() {
    let samples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/gltf-samples");
    if !samples.is_dir() {
        eprintln!("skipped: {} is absent", samples.display());
        return;
    }
    let ignored = |name: &str| {
        let glb = samples
            .join(name)
            .join("glTF-Binary")
            .join(format!("{name}.glb"));
        load_gltf(&glb)
            .unwrap_or_else(|e| panic!("{name}: {e}"))
            .ignored
            .join(", ")
    };
    let cases = [
        ("MultiUVTest", "a second texture coordinate set"),
        ("NormalTangentTest", "normal maps"),
    ];
    for (name, what) in cases {
        let list = ignored(name);
        assert!(list.contains(what), "{name}: {list:?}");
    }
    // Rendered now: vertex colours, alpha modes, texture transforms.
    for (name, what) in [
        ("VertexColorTest", "COLOR_0"),
        ("AlphaBlendModeTest", "alpha"),
        ("TextureTransformTest", "KHR_texture_transform"),
    ] {
        let list = match name {
            "TextureTransformTest" => {
                load_gltf(&samples.join("TextureTransformTest/glTF/TextureTransformTest.gltf"))
                    .unwrap_or_else(|e| panic!("{name}: {e}"))
                    .ignored
                    .join(", ")
            }
            _ => ignored(name),
        };
        assert!(!list.contains(what), "{name}: {list:?}");
    }
    assert_eq!(
        ignored("Box"),
        "",
        "the plain box holds nothing igi ignores"
    );
}

/// SimpleInstancing (EXT_mesh_gpu_instancing): 125 boxes, each where its instance's
/// translation, rotation and scale put it, under the node's transform.
#[test]
fn gpu_instancing_places_every_instance() {
    let glb = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/gltf-samples/SimpleInstancing/glTF-Binary/SimpleInstancing.glb");
    if !glb.is_file() {
        eprintln!("skipped: {} is absent", glb.display());
        return;
    }
    let mesh = load_gltf(&glb).unwrap();
    assert_eq!(mesh.triangles.len(), 125 * 12, "125 boxes of 12 triangles");
    assert!(!mesh.ignored.join(", ").contains("EXT_mesh_gpu_instancing"));
    // The boxes lie apart: their centroids (12 triangles each, in instance order) are
    // 125 distinct points.
    let centres: Vec<Vec3> = mesh
        .triangles
        .chunks(12)
        .map(|c| c.iter().flat_map(|t| t.v).sum::<Vec3>() / 36.0)
        .collect();
    for (i, a) in centres.iter().enumerate() {
        for b in &centres[i + 1..] {
            assert!(a.distance(*b) > 1e-3, "two instances at {a}");
        }
    }
}
