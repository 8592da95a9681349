//! Tests of the loaders at the edges of their contract (issue 37, "never wrong in
//! silence"): inputs whose declared sizes would cost far more than their bytes, messages
//! that quote huge file-provided text, valid files that were refused, and bad files that
//! were accepted. Each test writes its own files into a temporary directory.

#[path = "common/test_dir.rs"]
mod test_dir;

use test_dir::{expect_err, TestDir, CAMERA, LIGHT};

#[path = "common/gltf_builder.rs"]
mod gltf_builder;
use gltf_builder::*;

// ---------------------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------------------

/// A scene with the test camera and light, one `[[mesh]]` per path, and `extra` TOML.
fn scene_toml(paths: &[&str], extra: &str) -> String {
    let meshes: String = paths
        .iter()
        .map(|p| format!("[[mesh]]\npath = \"{p}\"\n"))
        .collect();
    format!("{CAMERA}\n{LIGHT}\n{meshes}\n{extra}")
}

// ---------------------------------------------------------------------------------------
// Messages quote file-provided text shortened
// ---------------------------------------------------------------------------------------

/// A message that quotes `long` (made of `c`): short, with the start of the text and its
/// full length, and never the whole text.
fn assert_quoted_short(msg: &str, c: char, long: usize) {
    assert!(
        msg.chars().count() < 1000,
        "message of {} characters",
        msg.chars().count()
    );
    assert!(
        msg.contains(&format!("({long} characters)")),
        "message does not give the text's length: {msg}"
    );
    assert!(msg.contains(&c.to_string().repeat(40)), "{msg}");
}

#[test]
fn huge_names_are_shortened_in_messages() {
    const LONG: usize = 150_000;
    let name = "n".repeat(LONG);
    let dir = TestDir::new("long-names");
    let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

    // A material that is defined nowhere (the name appears twice in the message).
    dir.write("undefined.obj", format!("{tri}usemtl {name}\nf 1 2 3\n"));
    let msg = expect_err(
        dir.load(&scene_toml(&["undefined.obj"], "")),
        "undefined.obj:4",
        &["defined nowhere"],
    );
    assert_quoted_short(&msg, 'n', LONG);

    // A [materials.NAME] table with a bad value.
    dir.write("m.obj", format!("{tri}usemtl m\nf 1 2 3\n"));
    let extra = format!(
        "[materials.m]\ndiffuse = [0.5, 0.5, 0.5]\n[materials.{name}]\ndiffuse = [2.0, 0.0, 0.0]\n"
    );
    let msg = expect_err(
        dir.load(&scene_toml(&["m.obj"], &extra)),
        "scene.toml",
        &["must be in [0, 1]"],
    );
    assert_quoted_short(&msg, 'n', LONG);

    // An unknown key of the scene file (the toml crate's message quotes it).
    let msg = expect_err(
        dir.load(&scene_toml(&["m.obj"], &format!("{name} = 1\n"))),
        "scene.toml",
        &["unknown field"],
    );
    assert_quoted_short(&msg, 'n', LONG);

    // A face index that is not a number.
    dir.write("face.obj", format!("{tri}f 1 2 {name}\n"));
    let msg = expect_err(
        dir.load(&scene_toml(&["face.obj"], "")),
        "face.obj:4",
        &["cannot read face index"],
    );
    assert_quoted_short(&msg, 'n', LONG);

    // Paths that the files name: a mesh, a material library.
    let msg = expect_err(
        dir.load(&scene_toml(&[&format!("{name}.obj")], "")),
        "cannot read mesh",
        &[],
    );
    assert!(msg.chars().count() < 1000, "{msg}");
    dir.write(
        "lib.obj",
        format!("mtllib {name}.mtl\n{tri}usemtl m\nf 1 2 3\n"),
    );
    let msg = expect_err(
        dir.load(&scene_toml(&["lib.obj"], "")),
        "material library",
        &[],
    );
    assert!(msg.chars().count() < 1000, "{msg}");

    // glTF: a material name, a required extension, a buffer URI.
    let mut g = quad(Some(0));
    g.material(&format!(
        r#"{{"name": "{name}", "pbrMetallicRoughness": {{"metallicFactor": 2.0}}}}"#
    ));
    g.node(r#""mesh": 0"#);
    dir.write("material.gltf", g.gltf());
    let msg = expect_err(
        dir.load(&scene_toml(&["material.gltf"], "")),
        "material.gltf",
        &["metallicFactor 2"],
    );
    assert_quoted_short(&msg, 'n', LONG);

    let mut g = quad(None);
    g.node(r#""mesh": 0"#);
    let json =
        g.json(Bin::DataUri)
            .replacen('{', &format!(r#"{{"extensionsRequired": ["{name}"], "#), 1);
    dir.write("extension.gltf", json);
    let msg = expect_err(
        dir.load(&scene_toml(&["extension.gltf"], "")),
        "extension.gltf",
        &["extensionsRequired"],
    );
    assert_quoted_short(&msg, 'n', LONG);

    let json = g.json(Bin::File(&format!("{name}.bin")));
    dir.write("uri.gltf", json);
    let msg = expect_err(dir.load(&scene_toml(&["uri.gltf"], "")), "glTF buffer", &[]);
    assert!(msg.chars().count() < 1000, "{msg}");
}

// ---------------------------------------------------------------------------------------
// Valid files that were refused
// ---------------------------------------------------------------------------------------

#[test]
fn obj_and_mtl_with_old_mac_line_ends_load() {
    let dir = TestDir::new("cr");
    let mtl =
        "newmtl red\nKd 0.5 0.1 0.1\nnewmtl mirror\nKd 0.1 0.1 0.1\nKs 0.8 0.8 0.8\nillum 3\n";
    let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvn 0 0 1\nusemtl red\nf 1//1 2//1 3//1\nusemtl mirror\nf 2 4 3\n";
    for (tag, end) in [("cr", "\r"), ("crlf", "\r\n"), ("lf", "\n")] {
        dir.write("m.mtl", mtl.replace('\n', end));
        dir.write("m.obj", obj.replace('\n', end));
        let s = dir
            .load(&scene_toml(&["m.obj"], ""))
            .unwrap_or_else(|e| panic!("{tag}: {e}"));
        assert_eq!(s.triangles.len(), 2, "{tag}");
        let names: Vec<&str> = s.materials.iter().map(|m| m.name.as_str()).collect();
        assert_eq!(names, ["red", "mirror"], "{tag}");
        assert_eq!(s.materials[0].diffuse, igi_core::Vec3::new(0.5, 0.1, 0.1));
        assert_eq!(s.materials[1].mirror, igi_core::Vec3::splat(0.8));
        assert_eq!(
            s.triangles[0].n[0],
            igi_core::Vec3::Z,
            "{tag}: the vn normal"
        );
    }
    // Lone CRs, CRLFs and LFs mixed in one file; line numbers count each line end.
    dir.write("m.mtl", mtl);
    let mixed = "mtllib m.mtl\r\nv 0 0 0\rv 1 0 0\nv 0 1 0\r\nusemtl red\rf 1 2 3\rf 1 2 9\n";
    dir.write("m.obj", mixed);
    expect_err(
        dir.load(&scene_toml(&["m.obj"], "")),
        "m.obj:7",
        &["face index 9 out of range"],
    );
    dir.write("m.obj", mixed.replace("f 1 2 9", "f 1 3 2"));
    let s = dir.load(&scene_toml(&["m.obj"], "")).unwrap();
    assert_eq!(s.triangles.len(), 2);
}

/// `"extras": VALUE` added to every object of `json` that the glTF schema lets have extras
/// and that the builder writes (the root, asset, scene, node, mesh, primitive, accessor,
/// buffer view, buffer, material, KHR_lights_punctual light).
fn with_extras(json: &str, value: &str) -> String {
    let tag = format!(r#""extras": {value}, "#);
    let mut out = json.replacen('{', &format!("{{{tag}"), 1);
    for key in [
        r#""asset": {"#,
        r#""nodes": [{"#,
        r#""primitives": [{"#,
        r#""accessors": [{"#,
        r#""bufferViews": [{"#,
        r#""buffers": [{"#,
        r#""materials": [{"#,
        r#""meshes": [{"#,
    ] {
        out = out.replacen(key, &format!("{key}{tag}"), 1);
    }
    out = out.replacen(r#""type": "point""#, &format!(r#"{tag}"type": "point""#), 1);
    out.replace(r#""scenes": [{"#, &format!(r#""scenes": [{{{tag}"#))
}

#[test]
fn extras_of_any_json_type_are_accepted() {
    let dir = TestDir::new("extras");
    let mut g = quad(Some(0));
    g.material(r#"{"name": "m", "pbrMetallicRoughness": {"metallicFactor": 0.0}}"#);
    g.light(r#"{"type": "point", "intensity": 683.0}"#);
    g.node(r#""mesh": 0, "children": [1]"#);
    g.node(
        r#""translation": [0.0, 0.0, 2.0], "extensions": {"KHR_lights_punctual": {"light": 0}}"#,
    );
    let plain = g.json(Bin::DataUri);
    dir.write("plain.gltf", &plain);
    let expected = dir.load(&scene_toml(&["plain.gltf"], "")).unwrap();
    for value in [
        "[1, 2, {\"a\": null}]",
        "\"a string\"",
        "null",
        "-3.5e2",
        "true",
        "{\"extras\": \"nested application data\"}",
    ] {
        let json = with_extras(&plain, value);
        assert!(json.matches("\"extras\"").count() >= 11, "{json}");
        dir.write("extras.gltf", &json);
        let s = dir
            .load(&scene_toml(&["extras.gltf"], ""))
            .unwrap_or_else(|e| panic!("extras {value}: {e}"));
        assert_eq!(s.triangles, expected.triangles, "extras {value}");
        assert_eq!(s.materials, expected.materials, "extras {value}");
        assert_eq!(s.lights, expected.lights, "extras {value}");
    }
    // In a GLB too.
    let mut glb_g = quad(None);
    glb_g.node(r#""mesh": 0"#);
    let glb = glb_g.glb();
    let json_len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    let json = std::str::from_utf8(&glb[20..20 + json_len]).unwrap();
    let mut new_json = with_extras(json.trim_end(), "\"s\"").into_bytes();
    while !new_json.len().is_multiple_of(4) {
        new_json.push(b' ');
    }
    let mut out = Vec::new();
    out.extend_from_slice(&glb[..8]);
    let total = glb.len() - json_len + new_json.len();
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(new_json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&new_json);
    out.extend_from_slice(&glb[20 + json_len..]);
    dir.write("extras.glb", out);
    let s = dir.load(&scene_toml(&["extras.glb"], "")).unwrap();
    assert_eq!(s.triangles.len(), 2);

    // A file whose extras are fine but that has another fault still says which.
    let bad = with_extras(&plain, "\"s\"").replacen(
        r#""componentType": 5126"#,
        r#""componentType": "float""#,
        1,
    );
    dir.write("bad.gltf", bad);
    expect_err(
        dir.load(&scene_toml(&["bad.gltf"], "")),
        "bad.gltf",
        &["invalid glTF JSON", "\"float\""],
    );
}

// ---------------------------------------------------------------------------------------
// Bad files that were accepted
// ---------------------------------------------------------------------------------------

#[test]
fn sparse_indices_out_of_order_or_range_are_refused() {
    let dir = TestDir::new("sparse");
    for component in [5121, 5123, 5125] {
        // Strictly increasing and in range: the quad.
        dir.write("ok.gltf", sparse_quad(&[1, 2, 3], component).gltf());
        let s = dir.load(&scene_toml(&["ok.gltf"], "")).unwrap();
        assert_eq!(s.triangles.len(), 2, "component type {component}");
        let cases: [(&[u32], &[&str]); 4] = [
            (
                &[1, 3, 2],
                &[
                    "element 2 is 2",
                    "not greater than element 1 (3)",
                    "strictly increasing",
                ],
            ),
            (
                &[1, 1, 2],
                &["element 1 is 1", "not greater than element 0 (1)"],
            ),
            (
                &[3, 2, 1],
                &["element 1 is 2", "not greater than element 0 (3)"],
            ),
            (
                &[1, 2, 4],
                &["element 2 is 4", "out of range", "4 elements"],
            ),
        ];
        for (indices, needles) in cases {
            dir.write("bad.gltf", sparse_quad(indices, component).gltf());
            let msg = expect_err(
                dir.load(&scene_toml(&["bad.gltf"], "")),
                "bad.gltf",
                needles,
            );
            assert!(
                msg.contains("mesh 0 primitive 0 POSITION (accessor 0) sparse indices"),
                "{msg}"
            );
        }
    }
}

/// The quad under a node of rotation `q` (x, y, z, w).
fn rotated_quad(q: [f32; 4]) -> Vec<u8> {
    let mut g = quad(None);
    g.node(&format!(
        r#""mesh": 0, "rotation": [{:?}, {:?}, {:?}, {:?}]"#,
        q[0], q[1], q[2], q[3]
    ));
    g.gltf()
}

#[test]
fn rotations_far_from_unit_length_are_refused_and_near_ones_normalised() {
    let dir = TestDir::new("rotation");
    let (s, c) = (0.5f32.sin(), 0.5f32.cos()); // 1 radian about z
    dir.write("unit.gltf", rotated_quad([0.0, 0.0, s, c]));
    let unit = dir.load(&scene_toml(&["unit.gltf"], "")).unwrap();
    // The quad's corner (1, 0, 0) goes to (cos 1, sin 1, 0).
    let corner = unit.triangles[0].v[1];
    assert!((corner - igi_core::Vec3::new(1f32.cos(), 1f32.sin(), 0.0)).length() < 1e-6);

    // Within the tolerance: the same rotation (normalised), not one that scales by |q|^2.
    for k in [1.0 - 0.007, 1.0 + 0.007, 1.0 + 1e-4] {
        dir.write("near.gltf", rotated_quad([0.0, 0.0, s * k, c * k]));
        let near = dir.load(&scene_toml(&["near.gltf"], "")).unwrap();
        for (a, b) in near.triangles.iter().zip(&unit.triangles) {
            for (p, q) in a.v.iter().zip(&b.v) {
                assert!((*p - *q).length() < 1e-6, "length {k}: {p} != {q}");
            }
        }
    }

    // Beyond it: an error naming the node and the length.
    for (q, length) in [
        ([0.0, 0.0, 0.0, 2.0], "2.000000"),
        ([0.0, 0.0, 0.0, 0.0], "0.000000"),
        ([0.5, 0.5, 0.5, 0.48], "0.99015"),
        ([1.0, 1.0, 1.0, 1.0], "2.000000"),
    ] {
        dir.write("far.gltf", rotated_quad(q));
        expect_err(
            dir.load(&scene_toml(&["far.gltf"], "")),
            "far.gltf",
            &[
                "node 0",
                "rotation",
                &format!("has length {length}"),
                "unit quaternion",
            ],
        );
    }
    // A rotation that is not finite is refused as before: by the node check, or by the
    // JSON reader where the workspace's serde_json features make it refuse a number
    // past the f32 range (as `cargo test --workspace` builds it).
    let mut g = quad(None);
    g.node(r#""mesh": 0, "rotation": [0.0, 0.0, 0.0, 1e39]"#);
    dir.write("inf.gltf", g.gltf());
    let msg = expect_err(dir.load(&scene_toml(&["inf.gltf"], "")), "inf.gltf", &[]);
    assert!(
        (msg.contains("node 0") && msg.contains("not finite"))
            || msg.contains("number out of range"),
        "{msg}"
    );
}

// ---------------------------------------------------------------------------------------
// Work and memory bounded by the input's size
// ---------------------------------------------------------------------------------------

/// A mesh of `prims` primitives that all use one indices accessor of `tris` triangles of
/// the quad's vertices, placed by `nodes` nodes: `nodes * prims * tris` triangles from a
/// file of a few kilobytes (plus 6 bytes a triangle).
fn instanced(nodes: usize, prims: usize, tris: usize) -> Gltf {
    let mut g = Gltf::default();
    let p = g.positions(&QUAD);
    let i = g.indices(&QUAD_INDICES[..3].repeat(tris));
    let prim = primitive(p, Some(i), "");
    g.mesh(&vec![prim; prims]);
    for _ in 0..nodes {
        g.node(r#""mesh": 0"#);
    }
    g.roots = (0..nodes).collect();
    g
}

#[test]
fn node_trees_beyond_the_triangle_limit_are_refused_before_they_are_made() {
    use igi_core::scene::loader::MAX_TRIANGLES;
    let dir = TestDir::new("instances");
    // 2^12 triangles x 2^6 primitives x 2^6 nodes is the limit, 2^24; one node more is
    // past it. The file is 40 KB; before the check it made 17 M triangles (1.3 GB) and
    // a larger such file aborted on a failed allocation.
    let (prims, tris) = (64, 4096);
    let nodes = MAX_TRIANGLES / (prims * tris) + 1;
    dir.write("many.gltf", instanced(nodes, prims, tris).gltf());
    let msg = expect_err(
        dir.load(&scene_toml(&["many.gltf"], "")),
        "many.gltf",
        &[
            &format!(
                "its node tree would make {} triangles",
                nodes * prims * tris
            ),
            &format!(
                "mesh 0 placed {nodes} times by nodes and instances, {} triangles each",
                prims * tris
            ),
            &format!("more than the {MAX_TRIANGLES} triangles a scene may have"),
        ],
    );
    assert!(msg.len() < 300, "{msg}");

    // Counted over the scene's meshes: two files each within the limit, not together.
    let all = MAX_TRIANGLES / (prims * tris);
    dir.write("one.gltf", instanced(1, prims, tris).gltf());
    dir.write("all.gltf", instanced(all, prims, tris).gltf());
    assert_eq!(
        dir.load(&scene_toml(&["one.gltf"], ""))
            .unwrap()
            .triangles
            .len(),
        prims * tris
    );
    expect_err(
        dir.load(&scene_toml(&["one.gltf", "all.gltf"], "")),
        "all.gltf",
        &[
            &format!("would make {MAX_TRIANGLES} triangles"),
            &format!("and the scene's earlier meshes {}", prims * tris),
            &format!("more than the {MAX_TRIANGLES} triangles"),
        ],
    );

    // Declared counts near the top of usize add up without overflow.
    let mut g = Gltf::default();
    let p = g.positions(&QUAD);
    let iv = g.view(&[0, 0, 0, 0]);
    let huge = g.accessor(format!(
        r#"{{"componentType": 5125, "count": {}, "type": "SCALAR", "sparse": {{"count": 1, "indices": {{"bufferView": {iv}, "componentType": 5125}}, "values": {{"bufferView": {iv}}}}}}}"#,
        usize::MAX
    ));
    g.mesh(&[primitive(p, Some(huge), ""), primitive(p, Some(huge), "")]);
    g.node(r#""mesh": 0"#);
    g.node(r#""mesh": 0"#);
    g.roots = vec![0, 1];
    dir.write("huge.gltf", g.gltf());
    expect_err(
        dir.load(&scene_toml(&["huge.gltf"], "")),
        "huge.gltf",
        &[&format!("would make {} triangles", usize::MAX)],
    );

    // A node that two parents list (a DAG, which places a subtree once per path, so a
    // count that doubles with each level) is refused as not a tree, before any triangle.
    let mut g = instanced(0, 1, 1);
    g.node(r#""children": [1, 1]"#);
    g.node(r#""children": [2, 2]"#);
    g.node(r#""mesh": 0"#);
    g.roots = vec![0];
    dir.write("dag.gltf", g.gltf());
    expect_err(
        dir.load(&scene_toml(&["dag.gltf"], "")),
        "dag.gltf",
        &["node 2 is reached twice", "must be a tree"],
    );
}

#[test]
fn accessors_without_a_buffer_view_are_bounded() {
    use igi_core::scene::gltf::MAX_VIEWLESS_ELEMENTS;
    let dir = TestDir::new("viewless");
    // POSITION without a buffer view: zeros, with one sparse value.
    let viewless = |g: &mut Gltf, count: usize| {
        let (iv, vv) = (g.view(&[0, 0, 0, 0]), g.view(&[0; 12]));
        g.accessor(format!(
            r#"{{"componentType": 5126, "count": {count}, "type": "VEC3", "min": [0, 0, 0], "max": [0, 0, 0], "sparse": {{"count": 1, "indices": {{"bufferView": {iv}, "componentType": 5125}}, "values": {{"bufferView": {vv}}}}}}}"#
        ))
    };
    let mut g = Gltf::default();
    let p = viewless(&mut g, MAX_VIEWLESS_ELEMENTS + 1);
    let i = g.indices(&QUAD_INDICES);
    g.mesh(&[primitive(p, Some(i), "")]);
    g.node(r#""mesh": 0"#);
    dir.write("big.gltf", g.gltf());
    expect_err(
        dir.load(&scene_toml(&["big.gltf"], "")),
        "big.gltf",
        &[
            "mesh 0 primitive 0 POSITION (accessor 0)",
            &format!("no bufferView and a count of {}", MAX_VIEWLESS_ELEMENTS + 1),
            &format!("at most {MAX_VIEWLESS_ELEMENTS} of their elements"),
        ],
    );

    // Two such accessors within the limit each, beyond it together.
    let mut g = Gltf::default();
    let a = viewless(&mut g, MAX_VIEWLESS_ELEMENTS / 2 + 1);
    let b = viewless(&mut g, MAX_VIEWLESS_ELEMENTS / 2 + 1);
    let i = g.indices(&QUAD_INDICES);
    g.mesh(&[primitive(a, Some(i), ""), primitive(b, Some(i), "")]);
    g.node(r#""mesh": 0"#);
    dir.write("two.gltf", g.gltf());
    expect_err(
        dir.load(&scene_toml(&["two.gltf"], "")),
        "two.gltf",
        &[
            "primitive 1 POSITION (accessor 1)",
            &format!(
                "{} of them taken by the accessors read before",
                MAX_VIEWLESS_ELEMENTS / 2 + 1
            ),
        ],
    );
}

#[test]
fn an_image_named_by_many_entries_is_read_once() {
    let dir = TestDir::new("images");
    dir.write("t.png", PNG);
    // 600 image entries naming one PNG, each the texture of its own material.
    let n = 600;
    let mut g = Gltf::default();
    let p = g.positions(&QUAD);
    let i = g.indices(&QUAD_INDICES);
    let prims: Vec<String> = (0..n)
        .map(|k| {
            g.images.push(r#"{"uri": "t.png"}"#.to_string());
            g.material(&format!(
                r#"{{"pbrMetallicRoughness": {{"baseColorTexture": {{"index": {k}}}, "metallicFactor": 0.0}}}}"#
            ));
            primitive(p, Some(i), &format!(r#", "material": {k}"#))
        })
        .collect();
    g.mesh(&prims);
    g.node(r#""mesh": 0"#);
    dir.write("images.gltf", g.gltf());
    let s = dir.load(&scene_toml(&["images.gltf"], "")).unwrap();
    assert_eq!(s.materials.len(), n);
    // The files a scene read: the scene, the glTF, and the PNG once (it was read, and
    // listed, once per image entry).
    let pngs = s.files.iter().filter(|f| f.ends_with("t.png")).count();
    assert_eq!(pngs, 1, "{:?}", s.files);
}

include!("common/tiny_png.rs");

// ---------------------------------------------------------------------------------------
// Scenes that 32-bit floats cannot trace
// ---------------------------------------------------------------------------------------

#[test]
fn a_small_scene_far_from_the_origin_is_refused_and_a_far_one_near_it_loads() {
    let dir = TestDir::new("far");
    let quad = |offset: f64, size: f64| {
        let v = |x: f64, y: f64| format!("v {} {} 0\n", offset + x * size, offset + y * size);
        format!(
            "{}{}{}{}f 1 2 3\nf 1 3 4\n",
            v(0.0, 0.0),
            v(1.0, 0.0),
            v(1.0, 1.0),
            v(0.0, 1.0)
        )
    };
    let toml = |mesh: &str| {
        format!("{CAMERA}\n{LIGHT}\n[[mesh]]\npath = \"{mesh}\"\ndefault_material = \"white\"\n[materials.white]\ndiffuse = [0.5, 0.5, 0.5]\n")
    };
    // A 1-unit square a million units out: f32 points are 0.06 apart there.
    dir.write("far.obj", quad(1e6, 1.0));
    expect_err(
        dir.load(&toml("far.obj")),
        "scene.toml",
        &["nearer the origin", "1.000e6"],
    );
    // The same square at the origin, and at 1e-9 or 1e12 of its size, loads.
    for size in [1.0, 1e-9, 1e12] {
        dir.write("near.obj", quad(0.0, size));
        let s = dir.load(&toml("near.obj")).unwrap();
        assert_eq!(s.triangles.len(), 2, "{size}");
    }
}

// ---------------------------------------------------------------------------------------
// Required extensions igi does not read are named
// ---------------------------------------------------------------------------------------

#[test]
fn required_extensions_igi_cannot_read_are_named() {
    let dir = TestDir::new("required");
    // A Draco file as exporters write it: accessors without buffer views, the data in
    // the primitive's extension. The validation alone would say "missing data" of them.
    let file = |required: &[&str]| {
        let names = required
            .iter()
            .map(|e| format!("\"{e}\""))
            .collect::<Vec<_>>()
            .join(",");
        format!(
            r#"{{"asset":{{"version":"2.0"}},"extensionsUsed":[{names}],"extensionsRequired":[{names}],
"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1,"extensions":{{"KHR_draco_mesh_compression":{{"bufferView":0,"attributes":{{"POSITION":0}}}}}}}}]}}],
"accessors":[{{"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},{{"componentType":5123,"count":3,"type":"SCALAR"}}],
"bufferViews":[{{"buffer":0,"byteLength":4}}],"buffers":[{{"byteLength":4,"uri":"data:application/octet-stream;base64,AAAAAA=="}}]}}"#
        )
    };
    let toml = scene_toml(&["m.gltf"], "[materials.x]\ndiffuse = [0.5, 0.5, 0.5]\n");
    dir.write("m.gltf", file(&["KHR_draco_mesh_compression"]));
    let msg = expect_err(
        dir.load(&toml),
        "m.gltf",
        &[
            "requires (extensionsRequired) the glTF extension KHR_draco_mesh_compression",
            "Draco",
        ],
    );
    assert!(!msg.contains("missing data"), "{msg}");
    // Several at once, in one line, an unknown one by its name alone.
    dir.write(
        "m.gltf",
        file(&[
            "KHR_texture_basisu",
            "EXT_meshopt_compression",
            "VENDOR_thing",
        ]),
    );
    expect_err(
        dir.load(&toml),
        "m.gltf",
        &[
            "extensions KHR_texture_basisu (KTX2",
            "EXT_meshopt_compression (meshoptimizer",
            "VENDOR_thing, which igi does not read",
        ],
    );
}

/// EXT_mesh_gpu_instancing counts toward the triangle limit before any instance is read:
/// a few hundred bytes that place a quad 2^25 times are refused.
#[test]
fn instances_beyond_the_triangle_limit_are_refused_before_they_are_made() {
    let dir = TestDir::new("instances");
    let quad = r#"{"asset":{"version":"2.0"},"extensionsUsed":["EXT_mesh_gpu_instancing"],
"scene":0,"scenes":[{"nodes":[0]}],
"nodes":[{"mesh":0,"extensions":{"EXT_mesh_gpu_instancing":{"attributes":{"TRANSLATION":2}}}}],
"meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],
"buffers":[{"byteLength":60,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAACAPwAAgD8AAAAAAAAAAAAAgD8AAAAAAAABAAIAAAACAAMA"}],
"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":48},{"buffer":0,"byteOffset":48,"byteLength":12}],
"accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},
{"bufferView":1,"componentType":5123,"count":6,"type":"SCALAR"},
{"bufferView":0,"componentType":5126,"count":COUNT,"type":"VEC3"}]}"#;
    let toml = scene_toml(&["m.gltf"], "[materials.x]\ndiffuse = [0.5, 0.5, 0.5]\n");
    dir.write("m.gltf", quad.replace("COUNT", "33554432"));
    expect_err(
        dir.load(&toml),
        "m.gltf",
        &["would make 67108864 triangles", "placed 33554432 times"],
    );
    // Three instances (at the quad's first three vertices) load.
    dir.write("m.gltf", quad.replace("COUNT", "3"));
    let s = dir.load(&toml).unwrap();
    assert_eq!(s.triangles.len(), 6);
}
