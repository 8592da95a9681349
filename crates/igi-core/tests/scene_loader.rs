//! Tests of the scene loader (`igi_core::scene::loader`: the TOML contract of
//! `shared/SCENE_FORMAT.md` with OBJ/MTL meshes) and of the built-in Cornell box.
//!
//! Test data is written by each test into its own temporary directory. The shared scenes
//! (`shared/scenes/...`) are used when present and skipped, with a message, when not.
//! Every error test checks that the message is one line and names the file at fault.

#[path = "common/test_dir.rs"]
mod test_dir;
use std::path::{Path, PathBuf};
use std::time::Instant;
use test_dir::{expect_err, TestDir, LIGHT};

use igi_core::scene::builtin::{builtin_scene, BUILTIN_NAMES};
use igi_core::scene::loader::{load_scene, load_scene_str, SceneError, DEFAULT_FILM};
use igi_core::scene::Scene;
use igi_core::Vec3;

// ---------------------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------------------

const CAMERA: &str = "[camera]
eye = [0.0, 0.0, 5.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
fov_y_deg = 40.0
";

/// A `[[mesh]]` table.
fn mesh(path: &str) -> String {
    format!("[[mesh]]\npath = \"{path}\"\n")
}

/// A scene with the test camera and light, `meshes` and anything `extra`.
fn scene_toml(meshes: &str, extra: &str) -> String {
    format!("{CAMERA}\n{meshes}\n{LIGHT}\n{extra}")
}

/// One triangle in the z = 0 plane, counter-clockwise seen from +z, with material `m`.
fn triangle_obj(m: &str) -> String {
    format!("v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl {m}\nf 1 2 3\n")
}

/// A dir with `mesh.obj` = `obj` and a scene that uses it, with `extra` TOML.
fn load_obj(tag: &str, obj: &str, extra: &str) -> Result<Scene, SceneError> {
    let dir = TestDir::new(tag);
    dir.write("mesh.obj", obj);
    dir.load(&scene_toml(&mesh("mesh.obj"), extra))
}

/// `[materials.NAME]` with a grey diffuse albedo.
fn grey(name: &str) -> String {
    format!("[materials.{name}]\ndiffuse = [0.5, 0.5, 0.5]\n")
}

/// The 1-based line of `text` that contains `needle`.
fn line_of(text: &str, needle: &str) -> usize {
    text.lines()
        .position(|l| l.contains(needle))
        .expect("needle in text")
        + 1
}

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).length() < 1e-5
}

/// Pixel coordinates of world point `p` for the scene's camera (right-handed look-at:
/// image right = forward x up, image down = -up; pixel (0, 0) top left).
fn project(s: &Scene, p: Vec3) -> (f32, f32) {
    let c = &s.camera;
    let f = (c.target - c.eye).normalize();
    let r = f.cross(c.up).normalize();
    let u = r.cross(f);
    let d = p - c.eye;
    let z = d.dot(f);
    assert!(z > 0.0, "point behind the camera");
    let t = (c.fov_y_deg.to_radians() * 0.5).tan();
    let aspect = s.film.width as f32 / s.film.height as f32;
    let x_ndc = d.dot(r) / (z * t * aspect);
    let y_ndc = d.dot(u) / (z * t);
    (
        (x_ndc + 1.0) * 0.5 * s.film.width as f32,
        (1.0 - y_ndc) * 0.5 * s.film.height as f32,
    )
}

fn centroid(s: &Scene, material: &str) -> Vec3 {
    let m = s
        .materials
        .iter()
        .position(|m| m.name == material)
        .expect("material present") as u32;
    let pts: Vec<Vec3> = s
        .triangles
        .iter()
        .filter(|t| t.material == m)
        .flat_map(|t| t.v)
        .collect();
    pts.iter().copied().sum::<Vec3>() / pts.len() as f32
}

/// Number of triangles after fanning the `f` lines of an OBJ text.
fn fanned_faces(obj: &str) -> usize {
    obj.lines()
        .filter_map(|l| {
            let mut w = l.split_whitespace();
            (w.next() == Some("f")).then(|| w.count().saturating_sub(2))
        })
        .sum()
}

fn shared(rel: &str) -> Option<PathBuf> {
    let p = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/scenes"
    ))
    .join(rel);
    if p.exists() {
        Some(p)
    } else {
        eprintln!("skipped: {} is absent", p.display());
        None
    }
}

/// Checks what every loaded scene must satisfy.
fn check_invariants(s: &Scene) {
    assert!(!s.triangles.is_empty());
    assert!(!s.lights.is_empty());
    for t in &s.triangles {
        assert!((t.material as usize) < s.materials.len());
        assert!(t.area() > 0.0);
        for n in t.n {
            assert!((n.length() - 1.0).abs() < 1e-4, "normal not unit: {n}");
        }
    }
    for m in &s.materials {
        for c in 0..3 {
            assert!(m.diffuse[c] >= 0.0 && m.mirror[c] >= 0.0);
            assert!(m.diffuse[c] + m.mirror[c] <= 1.0 + 1e-6);
        }
    }
    let mut names: Vec<&str> = s.materials.iter().map(|m| m.name.as_str()).collect();
    names.sort_unstable();
    names.dedup();
    assert_eq!(names.len(), s.materials.len(), "material names not unique");
}

// ---------------------------------------------------------------------------------------
// Shared scenes
// ---------------------------------------------------------------------------------------

#[test]
fn shared_cornell_box_loads() {
    let Some(path) = shared("cornell-box/scene.toml") else {
        return;
    };
    let s = load_scene(&path).expect("cornell box loads");
    check_invariants(&s);
    let obj = std::fs::read_to_string(path.with_file_name("CornellBox-Original.obj")).unwrap();
    assert_eq!(s.triangles.len(), fanned_faces(&obj));
    assert_eq!(s.triangles.len(), 36);
    assert_eq!(s.materials.len(), 8);
    assert_eq!(s.lights.len(), 1);
    assert_eq!((s.film.width, s.film.height), (512, 512));
    assert_eq!(s.files.len(), 3, "toml, obj, mtl: {:?}", s.files);
    let left = centroid(&s, "leftWall");
    let red = &s.materials[s
        .materials
        .iter()
        .position(|m| m.name == "leftWall")
        .unwrap()];
    assert!(close(red.diffuse, Vec3::new(0.63, 0.065, 0.05)));
    assert!(
        project(&s, left).0 < s.film.width as f32 / 2.0,
        "red wall not on the left"
    );
    assert!(project(&s, centroid(&s, "rightWall")).0 > s.film.width as f32 / 2.0);
}

#[test]
fn shared_conference_loads() {
    let Some(path) = shared("conference/scene.toml") else {
        return;
    };
    let t0 = Instant::now();
    let s = load_scene(&path).expect("conference loads");
    let dt = t0.elapsed();
    eprintln!(
        "conference: {} triangles, {} materials, loaded in {:.1} ms",
        s.triangles.len(),
        s.materials.len(),
        dt.as_secs_f64() * 1e3
    );
    check_invariants(&s);
    // The OBJ's faces fan out to 331179 triangles; 53627 of them have zero area (three
    // collinear vertices, exactly, counted independently in f64) and are dropped.
    let obj = std::fs::read_to_string(path.with_file_name("conference.obj")).unwrap();
    assert_eq!(fanned_faces(&obj), 331_179);
    assert_eq!(s.triangles.len(), 331_179 - 53_627);
    assert_eq!(s.materials.len(), 7);
    assert_eq!(s.lights.len(), 4);
    let table = s.materials.iter().find(|m| m.name == "table_top").unwrap();
    assert!(close(table.mirror, Vec3::new(0.25, 0.157143, 0.085714)));
    let diffuse = load_scene(&path.with_file_name("conference-diffuse.toml")).unwrap();
    let table = diffuse
        .materials
        .iter()
        .find(|m| m.name == "table_top")
        .unwrap();
    assert_eq!(table.mirror, Vec3::ZERO);
    assert!(close(table.diffuse, Vec3::new(0.35, 0.22, 0.12)));
}

// ---------------------------------------------------------------------------------------
// Built-in Cornell box
// ---------------------------------------------------------------------------------------

#[test]
fn builtin_names_resolve() {
    for name in BUILTIN_NAMES {
        let s = builtin_scene(name).expect("listed name resolves");
        assert_eq!(s.source, format!("builtin:{name}"));
        check_invariants(&s);
    }
    assert!(builtin_scene("no-such-scene").is_none());
}

#[test]
fn builtin_cornell_red_wall_on_left() {
    let s = builtin_scene("cornell-box").unwrap();
    let half = s.film.width as f32 / 2.0;
    let (red_x, _) = project(&s, centroid(&s, "red"));
    let (green_x, _) = project(&s, centroid(&s, "green"));
    assert!(red_x < half, "red wall at x = {red_x}");
    assert!(green_x > half, "green wall at x = {green_x}");
    // Not upside down: the ceiling light is in the top half.
    let (_, light_y) = project(&s, s.lights[0].position);
    assert!(light_y < s.film.height as f32 / 2.0);
}

#[test]
fn builtin_cornell_geometry() {
    let s = builtin_scene("cornell-box").unwrap();
    // Floor, ceiling, back, left and right walls, and 5 quads per block (no bottoms):
    // 15 quads, 30 triangles. The front (z = 0) is open, as published.
    assert_eq!(s.triangles.len(), 30);
    assert_eq!((s.film.width, s.film.height), (512, 512));
    let (lo, hi) = s.bounds();
    assert!(close(lo, Vec3::ZERO));
    assert!(close(hi, Vec3::new(0.556, 0.5488, 0.5592)));
    // 39.3 degrees: 35 mm lens on a 25 mm film.
    assert!((s.camera.fov_y_deg - 39.3076).abs() < 1e-3);
    // The box's shell: every wall triangle lies on one of the five planes.
    let shell = s
        .triangles
        .iter()
        .filter(|t| {
            t.v.iter().all(|v| v.y.abs() < 1e-6)
                || t.v.iter().all(|v| (v.y - 0.5488).abs() < 1e-6)
                || t.v.iter().all(|v| (v.z - 0.5592).abs() < 1e-6)
                || t.v.iter().all(|v| v.x.abs() < 1e-6)
                || t.material == 1
        })
        .count();
    assert_eq!(shell, 10);
    let area: f32 = s.triangles.iter().map(|t| t.area()).sum();
    assert!(area > 1.0 && area < 2.5, "total area {area} m^2");
}

#[test]
fn builtin_cornell_light_inside_box() {
    let s = builtin_scene("cornell-box").unwrap();
    assert_eq!(s.lights.len(), 1);
    let p = s.lights[0].position;
    let (lo, hi) = s.bounds();
    assert!(p.cmpgt(lo).all() && p.cmplt(hi).all(), "light at {p}");
    // Just below the ceiling, above the tall block (330 mm).
    assert!(p.y < 0.5488 && p.y > 0.33);
    let i = s.lights[0].intensity;
    assert!(i.x > 0.2 && i.x < 0.5 && i.x == i.y && i.y == i.z);
}

// ---------------------------------------------------------------------------------------
// Geometry
// ---------------------------------------------------------------------------------------

#[test]
fn load_scene_str_from_memory() {
    let dir = TestDir::new("str");
    dir.write("m.obj", triangle_obj("a"));
    let toml = scene_toml(&mesh("m.obj"), &grey("a"));
    let s = load_scene_str(&toml, &dir.0, "in-memory.toml").unwrap();
    assert_eq!(s.source, "in-memory.toml");
    assert_eq!(s.files, vec![dir.path("m.obj")]);
    assert_eq!(s.triangles.len(), 1);
    let e = load_scene_str(&toml, Path::new("/nonexistent-dir"), "in-memory.toml");
    expect_err(e, "in-memory.toml", &["cannot read mesh", "m.obj"]);
}

#[test]
fn negative_indices() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf -3 -2 -1\nv 0 0 1\nv 1 0 1\nv 0 1 1\nf -3 -2 -1\nf 1 -2 -1\n";
    let s = load_obj("neg", obj, &grey("a")).unwrap();
    assert_eq!(s.triangles.len(), 3);
    assert_eq!(s.triangles[0].v, [Vec3::ZERO, Vec3::X, Vec3::Y]);
    assert_eq!(
        s.triangles[1].v,
        [Vec3::Z, Vec3::new(1.0, 0.0, 1.0), Vec3::new(0.0, 1.0, 1.0)]
    );
    assert_eq!(
        s.triangles[2].v,
        [
            Vec3::ZERO,
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(0.0, 1.0, 1.0)
        ]
    );
}

#[test]
fn polygons_are_fanned() {
    // A convex pentagon and a quad: fans (0,1,2), (0,2,3), (0,3,4) keep the winding.
    let obj = "v 0 0 0\nv 2 0 0\nv 3 1 0\nv 1 3 0\nv -1 1 0\nusemtl a\nf 1 2 3 4 5\nf 1 2 3 4\n";
    let s = load_obj("fan", obj, &grey("a")).unwrap();
    assert_eq!(s.triangles.len(), 5);
    let p = [
        Vec3::ZERO,
        Vec3::new(2.0, 0.0, 0.0),
        Vec3::new(3.0, 1.0, 0.0),
        Vec3::new(1.0, 3.0, 0.0),
        Vec3::new(-1.0, 1.0, 0.0),
    ];
    assert_eq!(s.triangles[0].v, [p[0], p[1], p[2]]);
    assert_eq!(s.triangles[1].v, [p[0], p[2], p[3]]);
    assert_eq!(s.triangles[2].v, [p[0], p[3], p[4]]);
    assert_eq!(s.triangles[3].v, [p[0], p[1], p[2]]);
    assert_eq!(s.triangles[4].v, [p[0], p[2], p[3]]);
    // Shoelace area of the pentagon: 7.
    let area: f32 = s.triangles[..3].iter().map(|t| t.area()).sum();
    assert!((area - 7.0).abs() < 1e-5, "area {area}");
    for t in &s.triangles {
        assert_eq!(t.n, [Vec3::Z; 3]);
    }
}

#[test]
fn missing_normals_use_the_geometric_normal() {
    // Clockwise seen from +z: the geometric normal is -z, and unit length.
    let obj = "v 0 0 0\nv 0 10 0\nv 10 0 0\nusemtl a\nf 1 2 3\n";
    let s = load_obj("geo-n", obj, &grey("a")).unwrap();
    assert_eq!(s.triangles[0].n, [Vec3::NEG_Z; 3]);
}

#[test]
fn vn_normals_are_used_and_normalized() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 2\nvn 1 0 1\nvn 0 -3 4\nusemtl a\nf 1//1 2//2 3//3\nvt 0 0\nf 1/1/2 2/1/2 3/1/2\n";
    let s = load_obj("vn", obj, &grey("a")).unwrap();
    assert_eq!(s.triangles.len(), 2);
    let n = s.triangles[0].n;
    assert!(close(n[0], Vec3::Z));
    assert!(close(n[1], Vec3::new(1.0, 0.0, 1.0).normalize()));
    assert!(close(n[2], Vec3::new(0.0, -0.6, 0.8)));
    for n in s.triangles[1].n {
        assert!(close(n, Vec3::new(1.0, 0.0, 1.0).normalize()));
    }
}

#[test]
fn faces_without_vn_in_a_file_with_normals_use_the_geometric_normal() {
    // The second face has no vn indices (and the third only some): tobj alone would give
    // them another vertex's normal.
    let obj =
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 1 0 0\nusemtl a\nf 1//1 2//1 3//1\nf 1 2 3\nf 1//1 2 3//1\n";
    let s = load_obj("mixed-vn", obj, &grey("a")).unwrap();
    assert_eq!(s.triangles.len(), 3);
    assert_eq!(s.triangles[0].n, [Vec3::X; 3]);
    assert_eq!(s.triangles[1].n, [Vec3::Z; 3]);
    assert_eq!(s.triangles[2].n, [Vec3::Z; 3]);
}

#[test]
fn zero_length_vn_falls_back_to_the_geometric_normal() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 0\nvn 0 1 0\nusemtl a\nf 1//1 2//2 3//2\n";
    let s = load_obj("zero-vn", obj, &grey("a")).unwrap();
    assert_eq!(s.triangles[0].n, [Vec3::Z, Vec3::Y, Vec3::Y]);
}

#[test]
fn degenerate_triangles_are_dropped() {
    // Collinear, repeated vertex, and a good one.
    let obj = "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\nf 1 1 2\nf 1 2 4\n";
    let s = load_obj("degenerate", obj, &grey("a")).unwrap();
    assert_eq!(s.triangles.len(), 1);
    assert_eq!(s.triangles[0].v, [Vec3::ZERO, Vec3::X, Vec3::Y]);
}

#[test]
fn points_lines_and_polylines_make_no_triangles() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1\nf 1 2\nl 1 2\nl 1 2 3\nf 1 2 3\n";
    let s = load_obj("lines", obj, &grey("a")).unwrap();
    assert_eq!(s.triangles.len(), 1);
}

#[test]
fn latin1_comments_are_accepted() {
    let mut obj = b"# caf\xe9 cr\xe8me\n".to_vec();
    obj.extend_from_slice(triangle_obj("a").as_bytes());
    let dir = TestDir::new("latin1");
    dir.write("m.obj", obj);
    let s = dir.load(&scene_toml(&mesh("m.obj"), &grey("a"))).unwrap();
    assert_eq!(s.triangles.len(), 1);
}

#[test]
fn groups_objects_and_comments_are_accepted() {
    let obj = "# comment\n\no first\ng part\nv 0 0 0\nv 1 0 0\nv 0 1 0\ns 1\nusemtl a\nf 1 2 3\n\r\ng other\nusemtl b\nf 3 2 1\r\n";
    let s = load_obj("groups", obj, &format!("{}{}", grey("a"), grey("b"))).unwrap();
    assert_eq!(s.triangles.len(), 2);
    assert_eq!(s.materials.len(), 2);
    assert_eq!(s.triangles[1].material, 1);
}

// ---------------------------------------------------------------------------------------
// Materials
// ---------------------------------------------------------------------------------------

const MTL: &str = "# test materials
newmtl shiny
Kd 0.5 0.4 0.3
Ks 0.2 0.2 0.2
illum 3

newmtl plain
Ka 0.1 0.1 0.1 # ambient, ignored
Kd 0.6 0.6 0.6
Ks 0.9 0.9 0.9
Ns 10
illum 2

newmtl five
Kd 0.1 0.1 0.1
Ks 0.3 0.3 0.3
illum 5

newmtl seven
Kd 0.1 0.1 0.1
Ks 0.4 0.4 0.4
illum 7

newmtl noillum
Kd 0.2 0.2 0.2
Ks 0.5 0.5 0.5
";

/// An OBJ with one triangle per named material, using `mtllib lib`.
fn obj_with(lib: &str, materials: &[&str]) -> String {
    let mut s = format!("mtllib {lib}\nv 0 0 0\nv 1 0 0\nv 0 1 0\n");
    for m in materials {
        s.push_str(&format!("usemtl {m}\nf 1 2 3\n"));
    }
    s
}

fn material<'a>(s: &'a Scene, name: &str) -> &'a igi_core::scene::Material {
    s.materials
        .iter()
        .find(|m| m.name == name)
        .unwrap_or_else(|| panic!("no material {name}"))
}

#[test]
fn mtl_mirror_only_with_illum_3_5_7() {
    let dir = TestDir::new("illum");
    dir.write("m.mtl", MTL);
    dir.write(
        "m.obj",
        obj_with("m.mtl", &["shiny", "plain", "five", "seven", "noillum"]),
    );
    let s = dir.load(&scene_toml(&mesh("m.obj"), "")).unwrap();
    assert_eq!(s.materials.len(), 5);
    assert!(close(
        material(&s, "shiny").diffuse,
        Vec3::new(0.5, 0.4, 0.3)
    ));
    assert!(close(material(&s, "shiny").mirror, Vec3::splat(0.2)));
    assert!(close(material(&s, "plain").diffuse, Vec3::splat(0.6)));
    assert_eq!(material(&s, "plain").mirror, Vec3::ZERO);
    assert!(close(material(&s, "five").mirror, Vec3::splat(0.3)));
    assert!(close(material(&s, "seven").mirror, Vec3::splat(0.4)));
    assert_eq!(material(&s, "noillum").mirror, Vec3::ZERO);
    assert_eq!(s.files.len(), 3);
}

#[test]
fn material_override_key_by_key() {
    let dir = TestDir::new("override");
    dir.write("m.mtl", MTL);
    dir.write("m.obj", obj_with("m.mtl", &["shiny", "plain", "toml_only"]));
    let extra = "[materials.shiny]
mirror = [0.1, 0.1, 0.1]

[materials.plain]
diffuse = [0.2, 0.3, 0.4]

[materials.toml_only]
mirror = [0.7, 0.7, 0.7]
";
    let s = dir.load(&scene_toml(&mesh("m.obj"), extra)).unwrap();
    // A key the table leaves out keeps the MTL's value.
    assert!(close(
        material(&s, "shiny").diffuse,
        Vec3::new(0.5, 0.4, 0.3)
    ));
    assert!(close(material(&s, "shiny").mirror, Vec3::splat(0.1)));
    assert!(close(
        material(&s, "plain").diffuse,
        Vec3::new(0.2, 0.3, 0.4)
    ));
    assert_eq!(material(&s, "plain").mirror, Vec3::ZERO);
    // Defined only in the TOML (no MTL has it): a missing key is 0.
    assert_eq!(material(&s, "toml_only").diffuse, Vec3::ZERO);
    assert!(close(material(&s, "toml_only").mirror, Vec3::splat(0.7)));
    // Each triangle has its material.
    let names: Vec<&str> = s
        .triangles
        .iter()
        .map(|t| s.materials[t.material as usize].name.as_str())
        .collect();
    assert_eq!(names, ["shiny", "plain", "toml_only"]);
}

#[test]
fn default_material_for_faces_without_usemtl() {
    let dir = TestDir::new("default");
    dir.write(
        "m.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nusemtl red\nf 1 2 3\n",
    );
    let toml = scene_toml(
        "[[mesh]]\npath = \"m.obj\"\ndefault_material = \"white\"\n",
        "[materials.white]\ndiffuse = [0.8, 0.8, 0.8]\n[materials.red]\ndiffuse = [0.8, 0.1, 0.1]\n",
    );
    let s = dir.load(&toml).unwrap();
    assert_eq!(s.triangles.len(), 2);
    assert_eq!(s.materials[s.triangles[0].material as usize].name, "white");
    assert_eq!(s.materials[s.triangles[1].material as usize].name, "red");
}

#[test]
fn materials_are_shared_across_meshes_and_unused_ones_dropped() {
    let dir = TestDir::new("dedupe");
    dir.write("m.mtl", MTL);
    dir.write("a.obj", obj_with("m.mtl", &["shiny"]));
    dir.write("b.obj", obj_with("m.mtl", &["plain", "shiny"]));
    let extra = "[materials.shiny]\ndiffuse = [0.3, 0.3, 0.3]\n[materials.unused]\ndiffuse = [0.1, 0.1, 0.1]\n";
    let meshes = format!("{}{}", mesh("a.obj"), mesh("b.obj"));
    let s = dir.load(&scene_toml(&meshes, extra)).unwrap();
    assert_eq!(s.triangles.len(), 3);
    let names: Vec<&str> = s.materials.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["shiny", "plain"]);
    assert!(close(material(&s, "shiny").diffuse, Vec3::splat(0.3)));
    assert_eq!(s.triangles[0].material, s.triangles[2].material);
    // The MTL is read once.
    assert_eq!(s.files.len(), 4, "{:?}", s.files);
}

#[test]
fn missing_mtl_is_fine_when_the_toml_defines_the_materials() {
    let dir = TestDir::new("mtl-missing-ok");
    dir.write("m.obj", obj_with("gone.mtl", &["a"]));
    let s = dir.load(&scene_toml(&mesh("m.obj"), &grey("a"))).unwrap();
    assert_eq!(s.materials.len(), 1);
}

#[test]
fn film_and_up_have_defaults() {
    let dir = TestDir::new("defaults");
    dir.write("m.obj", triangle_obj("a"));
    let toml = format!(
        "[camera]\neye = [0, 0, 5]\ntarget = [0, 0, 0]\nfov_y_deg = 40\n{}{LIGHT}{}",
        mesh("m.obj"),
        grey("a")
    );
    let s = dir.load(&toml).unwrap();
    assert_eq!(s.film, DEFAULT_FILM);
    assert_eq!((s.film.width, s.film.height), (800, 600));
    assert_eq!(s.camera.up, Vec3::Y);
    let s = dir.load(&format!("{toml}[film]\nwidth = 64\n")).unwrap();
    assert_eq!((s.film.width, s.film.height), (64, 600));
}

// ---------------------------------------------------------------------------------------
// Errors: files
// ---------------------------------------------------------------------------------------

#[test]
fn error_missing_toml_file() {
    let dir = TestDir::new("no-toml");
    let msg = expect_err(
        load_scene(&dir.path("nope.toml")),
        "nope.toml",
        &["cannot read scene file", "No such file or directory"],
    );
    assert!(!msg.contains("os error"), "{msg}");
}

#[test]
fn error_missing_obj() {
    let dir = TestDir::new("no-obj");
    let r = dir.load(&scene_toml(&mesh("x.obj"), ""));
    let msg = expect_err(
        r,
        "x.obj",
        &[
            "cannot read mesh",
            "referenced by",
            "scene.toml",
            "No such file or directory",
        ],
    );
    assert!(!msg.contains("os error"), "{msg}");
}

#[test]
fn error_undefined_material_with_missing_mtl_names_the_mtl() {
    let dir = TestDir::new("mtl-missing");
    dir.write("m.obj", obj_with("gone.mtl", &["a"]));
    let r = dir.load(&scene_toml(&mesh("m.obj"), ""));
    expect_err(
        r,
        "m.obj:5",
        &[
            "'a'",
            "cannot read material library",
            "gone.mtl",
            "No such file",
        ],
    );
}

#[test]
fn error_binary_junk_as_toml() {
    let dir = TestDir::new("junk-toml");
    let p = dir.write(
        "scene.toml",
        [0x89u8, b'P', b'N', b'G', 0, 0xff, 0xfe, 0x10],
    );
    expect_err(load_scene(&p), "scene.toml:1", &["not a text file"]);
    // Text, but not TOML.
    let r = dir.load("\u{1}\u{2} garbage ]]] = \u{7f}\n");
    expect_err(r, "scene.toml:1:", &[]);
}

#[test]
fn error_binary_junk_as_obj() {
    let dir = TestDir::new("junk-obj");
    dir.write("m.obj", [b'v', b' ', 0xff, 0xfe, 0, 1, 2, 3, b'\n']);
    let r = dir.load(&scene_toml(&mesh("m.obj"), ""));
    expect_err(r, "m.obj:1", &["not a text file"]);
    // Random bytes without NUL: read as text with replacement characters; no line is
    // OBJ, so there is nothing to render.
    dir.write(
        "m.obj",
        [0x89u8, b'P', b'N', b'G', b'\r', b'\n', 0xff, 0x1a, b'\n'],
    );
    let r = dir.load(&scene_toml(&mesh("m.obj"), ""));
    expect_err(r, "scene.toml", &["no triangles"]);
    // Valid UTF-8 junk: tobj skips unknown lines, so there is nothing to render.
    dir.write("m.obj", "\u{1}\u{2} zzz\nxx yy\n\u{7f}\n");
    let r = dir.load(&scene_toml(&mesh("m.obj"), ""));
    expect_err(r, "scene.toml", &["no triangles"]);
}

#[test]
fn error_no_triangles() {
    let r = load_obj("no-tris", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n", "");
    expect_err(r, "scene.toml", &["the scene has no triangles"]);
}

// ---------------------------------------------------------------------------------------
// Errors: TOML
// ---------------------------------------------------------------------------------------

/// A valid scene text (one triangle of material `a`) and its directory.
fn valid_scene(tag: &str) -> (TestDir, String) {
    let dir = TestDir::new(tag);
    dir.write("m.obj", triangle_obj("a"));
    let toml = scene_toml(&mesh("m.obj"), &grey("a"));
    assert!(dir.load(&toml).is_ok());
    (dir, toml)
}

/// Loads `valid_scene` with `from` replaced by `to`; the message must name scene.toml at
/// the line of `to`'s first line (when `line` is true) and contain `needles`.
fn bad_toml(tag: &str, from: &str, to: &str, line: bool, needles: &[&str]) -> String {
    let (dir, toml) = valid_scene(tag);
    assert!(toml.contains(from), "{from:?} not in the scene");
    let text = toml.replacen(from, to, 1);
    let file = if line {
        let first = to.lines().next().unwrap();
        format!("scene.toml:{}:", line_of(&text, first))
    } else {
        "scene.toml".to_string()
    };
    expect_err(dir.load(&text), &file, needles)
}

#[test]
fn error_toml_syntax_has_line_and_column() {
    bad_toml(
        "syntax",
        "fov_y_deg = 40.0",
        "fov_y_deg = = 40.0",
        true,
        &[],
    );
    bad_toml("syntax2", "[camera]", "[camera", true, &[]);
}

#[test]
fn error_unknown_key_is_named() {
    bad_toml(
        "unknown",
        "fov_y_deg = 40.0",
        "fov_y_deg = 40.0\nfovy = 3",
        false,
        &["fovy"],
    );
    bad_toml("unknown-top", "[[mesh]]", "[[meshes]]", true, &["meshes"]);
    bad_toml(
        "unknown-mat",
        "diffuse = [0.5, 0.5, 0.5]",
        "kd = [0.5, 0.5, 0.5]",
        true,
        &["kd", "materials.a"],
    );
}

#[test]
fn error_wrong_type() {
    bad_toml(
        "type",
        "fov_y_deg = 40.0",
        "fov_y_deg = \"wide\"",
        true,
        &["camera.fov_y_deg", "invalid type"],
    );
    bad_toml(
        "len",
        "eye = [0.0, 0.0, 5.0]",
        "eye = [0.0, 5.0]",
        true,
        &["camera.eye", "length"],
    );
    bad_toml(
        "film-neg",
        "[[mesh]]",
        "[film]\nwidth = -4\n[[mesh]]",
        false,
        &["film.width"],
    );
}

#[test]
fn error_missing_camera() {
    let (dir, toml) = valid_scene("no-camera");
    let text = toml.replace(CAMERA, "");
    expect_err(dir.load(&text), "scene.toml", &["camera"]);
    bad_toml("no-fov", "fov_y_deg = 40.0", "", false, &["fov_y_deg"]);
}

#[test]
fn error_light_intensity_negative_or_nan() {
    bad_toml(
        "neg-i",
        "intensity = [1.0, 1.0, 1.0]",
        "intensity = [1.0, -1.0, 1.0]",
        true,
        &["intensity"],
    );
    bad_toml(
        "nan-i",
        "intensity = [1.0, 1.0, 1.0]",
        "intensity = [nan, 1.0, 1.0]",
        true,
        &["intensity", "NaN"],
    );
    bad_toml(
        "inf-pos",
        "position = [0.0, 0.0, 3.0]",
        "position = [0.0, inf, 3.0]",
        true,
        &["position"],
    );
}

#[test]
fn error_albedo_above_one() {
    bad_toml(
        "albedo",
        "diffuse = [0.5, 0.5, 0.5]",
        "diffuse = [0.5, 1.5, 0.5]",
        true,
        &["materials.a.diffuse", "[0, 1]"],
    );
    bad_toml(
        "albedo-neg",
        "diffuse = [0.5, 0.5, 0.5]",
        "mirror = [-0.1, 0.0, 0.0]",
        true,
        &["materials.a.mirror"],
    );
}

#[test]
fn error_diffuse_plus_mirror_above_one() {
    bad_toml(
        "sum",
        "diffuse = [0.5, 0.5, 0.5]",
        "diffuse = [0.5, 0.5, 0.5]\nmirror = [0.2, 0.6, 0.2]",
        false,
        &["'a'", "exceeds 1", "green"],
    );
    // Exactly 1 with values written with few digits is fine.
    let (dir, toml) = valid_scene("sum-ok");
    let text = toml.replace(
        "diffuse = [0.5, 0.5, 0.5]",
        "diffuse = [0.35, 0.7, 0.1]\nmirror = [0.65, 0.3, 0.9]",
    );
    assert!(dir.load(&text).is_ok());
}

#[test]
fn error_diffuse_plus_mirror_above_one_from_mtl() {
    let dir = TestDir::new("sum-mtl");
    dir.write(
        "m.mtl",
        "newmtl hot\nKd 0.8 0.8 0.8\nKs 0.5 0.5 0.5\nillum 3\n",
    );
    dir.write("m.obj", obj_with("m.mtl", &["hot"]));
    let r = dir.load(&scene_toml(&mesh("m.obj"), ""));
    expect_err(r, "m.mtl:1", &["'hot'", "exceeds 1", "[materials.hot]"]);
    // A TOML override fixes it.
    let r = dir.load(&scene_toml(
        &mesh("m.obj"),
        "[materials.hot]\nmirror = [0.2, 0.2, 0.2]\n",
    ));
    assert!(r.is_ok());
}

#[test]
fn error_fov_out_of_range() {
    for (i, fov) in ["0.0", "180.0", "-5.0", "nan", "1000.0"].iter().enumerate() {
        bad_toml(
            &format!("fov{i}"),
            "fov_y_deg = 40.0",
            &format!("fov_y_deg = {fov}"),
            true,
            &["fov_y_deg"],
        );
    }
}

#[test]
fn error_eye_equals_target() {
    bad_toml(
        "eye-target",
        "target = [0.0, 0.0, 0.0]",
        "target = [0.0, 0.0, 5.0]",
        true,
        &["camera.target", "camera.eye"],
    );
}

#[test]
fn error_up_parallel_to_view() {
    bad_toml(
        "up",
        "up = [0.0, 1.0, 0.0]",
        "up = [0.0, 0.0, -3.0]",
        true,
        &["camera.up", "parallel"],
    );
    bad_toml(
        "up-zero",
        "up = [0.0, 1.0, 0.0]",
        "up = [0.0, 0.0, 0.0]",
        true,
        &["camera.up"],
    );
}

#[test]
fn error_film_zero() {
    bad_toml(
        "film0",
        "[[mesh]]",
        "[film]\nwidth = 0\nheight = 10\n[[mesh]]",
        false,
        &["film.width"],
    );
}

#[test]
fn error_no_mesh_or_no_light() {
    let (dir, toml) = valid_scene("no-mesh");
    expect_err(
        dir.load(&toml.replace(&mesh("m.obj"), "")),
        "scene.toml",
        &["[[mesh]]"],
    );
    expect_err(
        dir.load(&toml.replace(LIGHT, "")),
        "scene.toml",
        &["[[point_light]]"],
    );
}

// ---------------------------------------------------------------------------------------
// Errors: materials
// ---------------------------------------------------------------------------------------

#[test]
fn error_undefined_material() {
    let r = load_obj("undef", &triangle_obj("nowhere"), "");
    expect_err(r, "mesh.obj:4", &["'nowhere'", "defined nowhere"]);
}

#[test]
fn error_face_without_material() {
    let r = load_obj("no-mat", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "");
    expect_err(r, "mesh.obj:4", &["no material", "default_material"]);
}

#[test]
fn error_undefined_default_material() {
    let dir = TestDir::new("undef-default");
    dir.write("m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    let toml = scene_toml(
        "[[mesh]]\npath = \"m.obj\"\ndefault_material = \"ghost\"\n",
        "",
    );
    let line = line_of(&toml, "ghost");
    expect_err(
        dir.load(&toml),
        &format!("scene.toml:{line}:"),
        &["'ghost'", "default_material"],
    );
}

#[test]
fn error_bad_mtl_lines_have_line_numbers_and_do_not_panic() {
    // tobj's own MTL reader panics on a colour with fewer than three numbers.
    for (i, (bad, needle)) in [
        ("Kd 0.5", "Kd"),
        ("Ks 0.1 x 0.3", "Ks"),
        ("illum two", "illum"),
        ("newmtl", "newmtl"),
    ]
    .iter()
    .enumerate()
    {
        let dir = TestDir::new(&format!("bad-mtl{i}"));
        dir.write("m.mtl", format!("newmtl a\nKd 0.5 0.5 0.5\n{bad}\n"));
        dir.write("m.obj", obj_with("m.mtl", &["a"]));
        let r = dir.load(&scene_toml(&mesh("m.obj"), ""));
        expect_err(r, "m.mtl:3", &[needle]);
    }
}

// ---------------------------------------------------------------------------------------
// Errors: OBJ
// ---------------------------------------------------------------------------------------

#[test]
fn error_obj_index_out_of_range() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\nf 1 2 999\n";
    let r = load_obj("range", obj, &grey("a"));
    expect_err(
        r,
        "mesh.obj:6",
        &["face index 999 out of range", "the file has 3 vertices"],
    );
    // Negative: relative to the vertices declared so far.
    let obj = "v 0 0 0\nv 1 0 0\nusemtl a\nf -1 -2 -3\nv 0 1 0\n";
    let r = load_obj("range-neg", obj, &grey("a"));
    expect_err(r, "mesh.obj:4", &["-3", "out of range"]);
    // Normals and texture coordinates too (tobj would overflow on these).
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nusemtl a\nf 1//1 2//1 3//2\n";
    let r = load_obj("range-vn", obj, &grey("a"));
    expect_err(r, "mesh.obj:6", &["normals"]);
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nusemtl a\nf 1/1 2/-5 3/1\n";
    let r = load_obj("range-vt", obj, &grey("a"));
    expect_err(r, "mesh.obj:6", &["texture coordinates"]);
}

#[test]
fn forward_references_within_the_file_are_accepted() {
    let obj = "usemtl a\nf 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n";
    let s = load_obj("forward", obj, &grey("a")).unwrap();
    assert_eq!(s.triangles.len(), 1);
}

#[test]
fn error_obj_zero_index() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\nf 0 1 2\n";
    let r = load_obj("zero", obj, &grey("a"));
    expect_err(r, "mesh.obj:6", &["face index 0"]);
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nusemtl a\nf 1/0 2/1 3/1\n";
    let r = load_obj("zero-vt", obj, &grey("a"));
    expect_err(r, "mesh.obj:6", &["texture coordinate index 0"]);
}

#[test]
fn error_obj_unparseable_numbers() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1.0.0 0\nusemtl a\nf 1 2 3\n";
    let r = load_obj("bad-v", obj, &grey("a"));
    expect_err(r, "mesh.obj:3", &["v 0 1.0.0 0"]);
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0\nusemtl a\nf 1 2 3\n";
    let r = load_obj("bad-vn", obj, &grey("a"));
    expect_err(r, "mesh.obj:4", &["normal"]);
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 x3\n";
    let r = load_obj("bad-f", obj, &grey("a"));
    expect_err(r, "mesh.obj:5", &["x3"]);
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1/1/1/1 2 3\n";
    let r = load_obj("bad-f4", obj, &grey("a"));
    expect_err(r, "mesh.obj:5", &["1/1/1/1"]);
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl\nf 1 2 3\n";
    let r = load_obj("bad-usemtl", obj, &grey("a"));
    expect_err(r, "mesh.obj:4", &["usemtl"]);
}

#[test]
fn error_obj_nan_coordinate() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv nan 0 0\nv 0 0 1\nusemtl a\nf 1 2 3\nf 1 2 4\n";
    let r = load_obj("nan", obj, &grey("a"));
    expect_err(r, "mesh.obj:8", &["vertex 4", "line 4", "not finite"]);
    // An unused one is harmless.
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv inf 0 0\nusemtl a\nf 1 2 3\n";
    assert!(load_obj("nan-unused", obj, &grey("a")).is_ok());
}

/// `igi view --camera` prints the camera as a `[camera]` table: it reads back to the very
/// same camera, through the camera parser and inside a whole scene file.
#[test]
fn camera_toml_round_trips() {
    use igi_core::scene::{camera_toml, parse_camera_toml, Camera};
    let camera = Camera {
        eye: glam::Vec3::new(0.1, -2.5e-3, 7.123_456_7),
        target: glam::Vec3::new(1.0 / 3.0, 2.0, -4.0),
        up: glam::Vec3::new(0.0, 0.0, 1.0),
        fov_y_deg: 47.3,
    };
    let text = camera_toml(&camera);
    assert!(text.starts_with("[camera]\n"), "{text}");
    assert_eq!(parse_camera_toml(&text, "camera").unwrap(), camera);
    // Bare keys (no table header) too.
    let bare = text.replacen("[camera]\n", "", 1);
    assert_eq!(parse_camera_toml(&bare, "camera").unwrap(), camera);
    let scene = format!(
        "{text}\n[[point_light]]\nposition = [0.0, 1.0, 0.0]\nintensity = [1.0, 1.0, 1.0]\n"
    );
    let test_dir = TestDir::new("camera");
    let dir = &test_dir.0;
    std::fs::write(dir.join("tri.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let scene = format!(
        "{scene}\n[[mesh]]\npath = \"tri.obj\"\ndefault_material = \"grey\"\n\n{}",
        grey("grey")
    );
    std::fs::write(dir.join("scene.toml"), scene).unwrap();
    let loaded = igi_core::scene::load_scene(&dir.join("scene.toml")).unwrap();
    assert_eq!(loaded.camera, camera);
}

#[test]
fn camera_toml_errors_name_the_key() {
    use igi_core::scene::parse_camera_toml;
    let e = parse_camera_toml(
        "eye = [0, 0, 0]\ntarget = [0, 0, 0]\nfov_y_deg = 40\n",
        "--camera",
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("--camera") && e.contains("view direction is undefined"),
        "{e}"
    );
    let e = parse_camera_toml("eye = [0, 0, 0]\ntarget = [0, 0, 1]\n", "--camera")
        .unwrap_err()
        .to_string();
    assert!(e.contains("fov_y_deg"), "{e}");
    let e = parse_camera_toml(
        "[camera]\neye = [0, 0, 0]\ntarget = [0, 0, 1]\nfov_y_deg = 40\nzoom = 2\n",
        "--camera",
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("zoom"), "{e}");
}

// ---------------------------------------------------------------------------------------
// Unusual but valid (or clearly invalid) input: lights, large triangles, vector lengths,
// OBJ comments, values beyond the f32 range
// ---------------------------------------------------------------------------------------

#[test]
fn light_of_zero_power_loads_and_unrepresentable_power_is_refused() {
    // A light that emits nothing is valid (the renderer never chooses it).
    let (dir, toml) = valid_scene("light-zero");
    let s = dir
        .load(&toml.replace("intensity = [1.0, 1.0, 1.0]", "intensity = [0.0, 0.0, 0.0]"))
        .expect("a light of zero intensity is valid");
    assert_eq!(s.lights[0].intensity, Vec3::ZERO);
    // 4 pi (r + g + b) beyond f32::MAX: named with the light's value as written.
    bad_toml(
        "light-1e37",
        "intensity = [1.0, 1.0, 1.0]",
        "intensity = [1e37, 1e37, 1e37]",
        true,
        &[
            "point_light.intensity",
            "[1e37, 1e37, 1e37]",
            "32-bit floats",
        ],
    );
    // Each light in range, their sum not.
    let bright = "[[point_light]]\nposition = [0.0, 0.0, 3.0]\nintensity = [1e37, 0.0, 0.0]\n";
    let (dir, toml) = valid_scene("light-sum");
    assert!(dir.load(&format!("{toml}\n{bright}")).is_ok());
    let r = dir.load(&format!("{toml}\n{bright}\n{bright}\n{bright}"));
    expect_err(r, "scene.toml", &["4 lights' total power", "32-bit floats"]);
}

/// The bound an editor (the viewer's light panel) puts on a light's channel is the one
/// loading checks: a scene with that value loads, and one 1% above it is refused.
#[test]
fn max_light_intensity_is_what_loading_accepts() {
    let bright = "[[point_light]]\nposition = [0.0, 0.0, 3.0]\nintensity = [1e37, 2e36, 0.0]\n";
    let (dir, toml) = valid_scene("light-max");
    let text = format!("{toml}\n{bright}");
    let scene = dir.load(&text).expect("valid");
    let (index, channel) = (1, 2);
    let max = igi_core::scene::max_light_intensity(&scene.lights, index, channel);
    assert!(max > 1e36, "room left: {max:e}");
    let with = |x: f32| {
        let light = format!("intensity = [1e37, 2e36, {x:e}]");
        text.replace("intensity = [1e37, 2e36, 0.0]", &light)
    };
    let at_max = dir.load(&with(max)).expect("the bound itself loads");
    assert_eq!(at_max.lights[index].intensity[channel], max);
    let r = dir.load(&with(max * 1.01));
    expect_err(r, "scene.toml", &["power", "32-bit floats"]);
    // A light whose others use up the range has none left.
    let lights = [scene.lights.clone(), vec![scene.lights[1]; 3]].concat();
    assert_eq!(igi_core::scene::max_light_intensity(&lights, 0, 0), 0.0);
}

#[test]
fn large_valid_triangles_are_kept_and_degenerate_ones_dropped() {
    // Edges of 2e10 (and 2e30): the f32 cross product overflows, the triangle is fine.
    for e in ["1e10", "1e18", "1e30"] {
        let obj = format!("v -{e} -{e} 0\nv {e} -{e} 0\nv 0 {e} 0\nusemtl a\nf 1 2 3\n");
        let s = load_obj(&format!("big-{e}"), &obj, &grey("a")).expect(e);
        assert_eq!(s.triangles.len(), 1, "{e}");
        assert_eq!(s.triangles[0].n, [Vec3::Z; 3], "{e}");
        if e == "1e10" {
            // Base 2e10, height 2e10 (the f32 cross product of it was infinite).
            let area = s.triangles[0].area();
            assert!((area / 2e20 - 1.0).abs() < 1e-6, "area {area}");
        }
    }
    // Zero area (collinear, repeated vertex) at every scale is still dropped.
    for (tag, obj) in [
        (
            "collinear",
            "v 0 0 0\nv 1e10 1e10 0\nv 2e10 2e10 0\nusemtl a\nf 1 2 3\n",
        ),
        (
            "repeated",
            "v 1e20 0 0\nv 1e20 0 0\nv 0 1e20 0\nusemtl a\nf 1 2 3\n",
        ),
        ("flat", "v 0 0 0\nv 1 0 0\nv 2 0 0\nusemtl a\nf 1 2 3\n"),
    ] {
        expect_err(
            load_obj(tag, obj, &grey("a")),
            "scene.toml",
            &["no triangles"],
        );
    }
}

#[test]
fn diagonal_of_far_geometry_is_finite() {
    // One small triangle at x = 1e20 beside a unit one: |hi - lo|^2 overflows f32.
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1e20 0 0\nv 1e20 1 0\nv 1e20 0 1\nusemtl a\nf 1 2 3\nf 4 5 6\n";
    let s = load_obj("far", obj, &grey("a")).unwrap();
    let d = s.diagonal();
    assert!((d / 1e20 - 1.0).abs() < 1e-6, "diagonal {d}");
    let m = igi_core::settings::default_min_dist(&s);
    assert!((m / 5e18 - 1.0).abs() < 1e-6, "min_dist {m}");
}

#[test]
fn vectors_of_the_wrong_length_are_refused() {
    for (i, (from, to, key)) in [
        (
            "eye = [0.0, 0.0, 5.0]",
            "eye = [0.0, 1.0, 3.9, 1.0]",
            "camera.eye",
        ),
        (
            "up = [0.0, 1.0, 0.0]",
            "up = [0.0, 1.0, 0.0, \"x\"]",
            "camera.up",
        ),
        (
            "intensity = [1.0, 1.0, 1.0]",
            "intensity = [1.0, 1.0, 1.0, 9.0]",
            "point_light.intensity",
        ),
        (
            "diffuse = [0.5, 0.5, 0.5]",
            "diffuse = [0.5, 0.5, 0.5, 0.5, 0.5]",
            "materials.a.diffuse",
        ),
        ("eye = [0.0, 0.0, 5.0]", "eye = [0.0, 5.0]", "camera.eye"),
        ("eye = [0.0, 0.0, 5.0]", "eye = []", "camera.eye"),
    ]
    .into_iter()
    .enumerate()
    {
        bad_toml(
            &format!("len{i}"),
            from,
            to,
            true,
            &[key, "expected 3 numbers"],
        );
    }
}

#[test]
fn values_beyond_f32_are_reported_as_written() {
    let msg = bad_toml(
        "eye-1e300",
        "eye = [0.0, 0.0, 5.0]",
        "eye = [1e300, 1.0, 3.9]",
        true,
        &["camera.eye", "1e300", "out of range for 32-bit floats"],
    );
    assert!(!msg.contains("inf"), "{msg}");
    let msg = bad_toml(
        "fov-1e300",
        "fov_y_deg = 40.0",
        "fov_y_deg = 1e300",
        true,
        &["camera.fov_y_deg = 1e300"],
    );
    assert!(!msg.contains("inf"), "{msg}");
}

#[test]
fn trailing_comments_on_every_obj_and_mtl_line() {
    let dir = TestDir::new("comments");
    dir.write(
        "m.mtl",
        "# library\nnewmtl red # the red one\nKd 0.5 0 0 # albedo\nillum 2 # no mirror\nnewmtl Mat#2\nKd 0.1 0.2 0.3\n",
    );
    dir.write(
        "m.obj",
        "mtllib m.mtl # materials\nv 0 0 0 # a\nv 1 0 0 #b\nv 0 1 0\nvn 0 0 1 # up\nusemtl red # paint\nf 1//1 2//1 3//1 # face\nusemtl Mat#2\nf 3 2 1 #\n",
    );
    let s = dir
        .load(&scene_toml(&mesh("m.obj"), ""))
        .expect("comments are ignored");
    assert_eq!(s.triangles.len(), 2);
    let names: Vec<&str> = s.materials.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["red", "Mat#2"]);
    assert_eq!(s.materials[0].diffuse, Vec3::new(0.5, 0.0, 0.0));
    // Line numbers still count the comment lines.
    let obj = "v 0 0 0 # a\nv 1 0 0\n# c\nf 1 2 9 # bad\n";
    expect_err(
        load_obj("comment-line", obj, &grey("a")),
        "mesh.obj:4",
        &["9"],
    );
}
