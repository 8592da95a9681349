//! Wavefront OBJ meshes: our own pass over the text (`scan_obj`, for line numbers and the
//! cases tobj gets wrong, see the loader's module documentation), then tobj, then the
//! triangles and their material slots as the loader merges them, with the texture
//! coordinates (`vt`, as v' = 1 - v: glTF's convention) of the faces whose material has
//! a texture.

use std::borrow::Cow;
use std::collections::HashMap;
use std::io::{self, Read};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3, Vec4};

use super::error::{as_lenient_text, excerpt, io_message, quote, quote_path, Location, SceneError};
use super::loader::{read_regular_file, Geometry, TriangleBudget};
use super::mtl::{read_mtl, MtlTable};
use super::{TriAttributes, Triangle};

/// The OBJ or MTL text without its comments: a `#` at the start of a line or after
/// white space begins a comment to the end of the line (`f 1 2 3 # face`). Lines keep
/// their numbers (the newlines stay). tobj skips only lines whose first word is `#`, so
/// a trailing comment failed on `f` lines ("cannot read face index '#'"), became part of
/// the name on `usemtl`/`newmtl` lines and a file name on `mtllib` lines, and passed on
/// `v` lines only by chance. A `#` inside a word (`Material#2`) is kept: names use it.
pub(super) fn strip_comments(text: &str) -> Cow<'_, str> {
    let bytes = text.as_bytes();
    let mut out = String::new();
    // text[..kept] is in `out` or was a comment.
    let mut kept = 0;
    let mut any = false;
    for (i, _) in text.match_indices('#') {
        if i < kept || (i > 0 && !bytes[i - 1].is_ascii_whitespace()) {
            continue;
        }
        out.push_str(&text[kept..i]);
        kept = text[i..].find('\n').map_or(text.len(), |n| i + n);
        any = true;
    }
    if !any {
        return Cow::Borrowed(text);
    }
    out.push_str(&text[kept..]);
    Cow::Owned(out)
}

/// The triangles of one mesh that share a `usemtl` name (or have none): their material is
/// resolved once all meshes and MTL files are read. [`Triangle::material`] holds the slot
/// index until then.
pub(super) struct Slot {
    /// The `usemtl` name; `None` for faces before any `usemtl` (default_material).
    pub(super) name: Option<String>,
    pub(super) mesh: usize,
    pub(super) file: String,
    /// First `usemtl` line of the name, or first face without `usemtl`.
    pub(super) line: usize,
    pub(super) triangles: usize,
    pub(super) has_mtllib: bool,
    /// "'path' (mtllib at file:line): error" of material libraries that do not exist.
    pub(super) missing_mtl: Vec<String>,
}

/// A triangle came from an `l` line (a polyline, not a surface): dropped.
pub(super) const TRI_POLYLINE: u8 = 1;
/// Every corner of the face the triangle came from has a `vn` index.
pub(super) const TRI_HAS_VN: u8 = 2;
/// Every corner of the face the triangle came from has a `vt` index.
pub(super) const TRI_HAS_VT: u8 = 4;

/// What [`scan_obj`] learns from an OBJ's text.
#[derive(Debug, Default)]
pub(super) struct ObjScan<'a> {
    /// `usemtl` names as tobj looks them up (the rest of the line after the first space,
    /// trimmed), distinct, in order of first use.
    pub(super) keys: Vec<&'a str>,
    /// The same names as the format reads them (the words after `usemtl`).
    pub(super) names: Vec<Cow<'a, str>>,
    pub(super) first_line: Vec<usize>,
    /// First face before any `usemtl`.
    pub(super) untagged_line: Option<usize>,
    /// (line, file) of each `mtllib` file.
    pub(super) mtllibs: Vec<(usize, &'a str)>,
    /// Per triangle of the fanned faces, in file order: `TRI_*` bits.
    pub(super) flags: Vec<u8>,
    /// Faces with one or two vertices (ignored).
    pub(super) small_faces: usize,
    /// Number of `v`, `vt`, `vn` lines.
    pub(super) counts: [usize; 3],
}

pub(super) const KIND: [&str; 3] = ["vertices", "texture coordinates", "normals"];
pub(super) const INDEX: [&str; 3] = [
    "face index",
    "face texture coordinate index",
    "face normal index",
];

/// Positive indices beyond the count declared so far (forward references): kept when they
/// exceed every earlier one, so the first that is beyond the file's total can be found at
/// the end.
#[derive(Default)]
pub(super) struct Forward {
    pub(super) max: [usize; 3],
    pub(super) refs: [Vec<(usize, usize)>; 3],
}

/// One pass over the OBJ text: validates faces and collects what tobj does not tell us
/// (see the module documentation). No float parsing: tobj does that.
pub(super) fn scan_obj<'a>(text: &'a str, file: &str) -> Result<ObjScan<'a>, SceneError> {
    let mut s = ObjScan::default();
    let mut key_index: HashMap<&str, usize> = HashMap::new();
    let mut tagged = false;
    let mut forward = Forward::default();
    let mut first_error: Option<(usize, String)> = None;
    for (i, line) in text.lines().enumerate() {
        let ln = i + 1;
        let mut words = line.split_whitespace();
        let Some(key) = words.next() else { continue };
        match key {
            "v" => s.counts[0] += 1,
            "vt" => s.counts[1] += 1,
            "vn" => s.counts[2] += 1,
            // After an error, only count (a forward reference may be an earlier error).
            _ if first_error.is_some() => {}
            "f" | "l" => match scan_face(words, &s.counts, &mut forward, ln) {
                Err(e) => first_error = Some((ln, e)),
                Ok((corners, all_vt, all_vn)) => {
                    if corners < 3 {
                        if corners == 0 {
                            first_error = Some((ln, format!("'{key}' line without vertices")));
                        } else if key == "f" {
                            s.small_faces += 1;
                        }
                        continue;
                    }
                    let mut flag = if all_vn { TRI_HAS_VN } else { 0 };
                    if all_vt {
                        flag |= TRI_HAS_VT;
                    }
                    if key == "l" {
                        flag |= TRI_POLYLINE;
                    } else if !tagged && s.untagged_line.is_none() {
                        s.untagged_line = Some(ln);
                    }
                    s.flags.extend(std::iter::repeat_n(flag, corners - 2));
                }
            },
            "usemtl" => {
                let words: Vec<&str> = words.collect();
                let name: Cow<str> = match words.as_slice() {
                    [one] => Cow::Borrowed(one),
                    more => Cow::Owned(more.join(" ")),
                };
                let tobj_key = line.split_once(' ').map_or("", |(_, rest)| rest.trim());
                if name.is_empty() {
                    first_error = Some((ln, "usemtl without a material name".into()));
                } else if tobj_key.is_empty() {
                    first_error = Some((
                        ln,
                        "separate usemtl and the material name with a space".into(),
                    ));
                } else {
                    tagged = true;
                    key_index.entry(tobj_key).or_insert_with(|| {
                        s.keys.push(tobj_key);
                        s.names.push(name);
                        s.first_line.push(ln);
                        s.keys.len() - 1
                    });
                }
            }
            "mtllib" => {
                let before = s.mtllibs.len();
                s.mtllibs.extend(words.map(|w| (ln, w)));
                if s.mtllibs.len() == before {
                    log::warn!("{file}:{ln}: mtllib without a file name, ignored");
                }
            }
            _ => {}
        }
    }
    // The first face whose positive index is beyond the file's total.
    let mut out_of_range: Option<(usize, String)> = None;
    for k in 0..3 {
        if let Some(&(ln, idx)) = forward.refs[k].iter().find(|(_, idx)| *idx > s.counts[k]) {
            if out_of_range.as_ref().is_none_or(|(l, _)| ln < *l) {
                out_of_range = Some((
                    ln,
                    format!(
                        "{} {idx} out of range (the file has {} {})",
                        INDEX[k], s.counts[k], KIND[k]
                    ),
                ));
            }
        }
    }
    let error = match (first_error, out_of_range) {
        (Some(a), Some(b)) => Some(if b.0 < a.0 { b } else { a }),
        (a, b) => a.or(b),
    };
    match error {
        Some((ln, message)) => Err(SceneError::parse(Location::line(file, ln), message)),
        None => Ok(s),
    }
}

/// Parses the corners of one `f` line exactly as tobj does (`v`, `v/vt`, `v//vn`,
/// `v/vt/vn`, negative indices relative to the count so far) and checks every index.
/// Returns the number of corners and whether all have a texture coordinate index, and a
/// normal index.
pub(super) fn scan_face<'a>(
    corners: impl Iterator<Item = &'a str>,
    counts: &[usize; 3],
    forward: &mut Forward,
    ln: usize,
) -> Result<(usize, bool, bool), String> {
    let mut n = 0;
    let mut all_vt = true;
    let mut all_vn = true;
    for corner in corners {
        n += 1;
        let mut has = [false; 3];
        for (k, part) in corner.split('/').enumerate() {
            if k >= 3 {
                return Err(format!(
                    "face corner '{}' has more than three indices (v/vt/vn)",
                    quote(corner)
                ));
            }
            if part.is_empty() {
                continue;
            }
            let Ok(x) = part.parse::<isize>() else {
                return Err(if part == corner {
                    format!("cannot read face index '{}'", quote(part))
                } else {
                    format!(
                        "cannot read face index '{}' in '{}'",
                        quote(part),
                        quote(corner)
                    )
                });
            };
            has[k] = true;
            if x == 0 {
                return Err(format!(
                    "{} 0 in '{}': OBJ indices start at 1 (negative ones count back from the last of the {})",
                    INDEX[k],
                    quote(corner),
                    KIND[k]
                ));
            }
            if x < 0 {
                if x.unsigned_abs() > counts[k] {
                    return Err(format!(
                        "{} {x} out of range (only {} {} are declared before this line)",
                        INDEX[k], counts[k], KIND[k]
                    ));
                }
            } else {
                let x = x as usize;
                if x > counts[k] && x > forward.max[k] {
                    forward.max[k] = x;
                    forward.refs[k].push((ln, x));
                }
            }
        }
        if !has[0] {
            return Err(format!(
                "face corner '{}' has no vertex index",
                quote(corner)
            ));
        }
        all_vt &= has[1];
        all_vn &= has[2];
    }
    Ok((n, all_vt, all_vn))
}

/// The path tobj is given (as its first `mtllib` line) to learn every `usemtl` name.
pub(super) const NAMES_MTLLIB: &str = "\u{1}igi-usemtl-names";

/// Reads one OBJ: appends its triangles (material = slot index) and its slots; reads its
/// MTL files into `mtl`. Its faces must fit in `budget` (counted before tobj reads them).
/// The triangles of a material that has a texture (by the MTL files read so far; faces
/// without `usemtl` by `default_material`) get their texture coordinates.
#[allow(clippy::too_many_arguments)]
pub(super) fn load_obj(
    bytes: &[u8],
    path: &Path,
    mesh: usize,
    default_material: Option<&str>,
    budget: TriangleBudget,
    slots: &mut Vec<Slot>,
    out: &mut Geometry,
    mtl: &mut MtlTable,
    files: &mut Vec<PathBuf>,
) -> Result<(), SceneError> {
    let file = path.display().to_string();
    let text = as_lenient_text(bytes, &file)?;
    let text = strip_comments(text.as_ref());
    let text = text.as_ref();
    let scan = scan_obj(text, &file)?;
    budget.check(scan.flags.len(), &file, || {
        format!("its faces make {} triangles", scan.flags.len())
    })?;
    if scan.small_faces > 0 {
        log::warn!(
            "{file}: {} faces with fewer than 3 vertices ignored",
            scan.small_faces
        );
    }

    // Material libraries, relative to the OBJ.
    let dir = path.parent().unwrap_or(Path::new(""));
    let mut missing_mtl = Vec::new();
    for &(ln, lib) in &scan.mtllibs {
        let lib_path = dir.join(lib);
        if mtl.read.contains(&lib_path) {
            continue;
        }
        match read_regular_file(&lib_path) {
            Ok(b) => {
                read_mtl(&b, &lib_path, mtl)?;
                mtl.read.insert(lib_path.clone());
                files.push(lib_path);
            }
            Err(e) if e.kind() == io::ErrorKind::NotFound => {
                log::warn!(
                    "{file}:{ln}: material library '{}' not found",
                    quote_path(&lib_path.display().to_string())
                );
                missing_mtl.push(format!(
                    "'{}' (mtllib at {file}:{ln}): {}",
                    quote_path(&lib_path.display().to_string()),
                    io_message(&e)
                ));
            }
            Err(source) => {
                return Err(SceneError::Read {
                    what: "material library",
                    path: lib_path,
                    context: Some(format!("mtllib at {file}:{ln}")),
                    error: source,
                })
            }
        }
    }

    let slot_base = slots.len();
    let n_keys = scan.keys.len();
    for k in 0..=n_keys {
        slots.push(Slot {
            name: scan.names.get(k).map(|n| n.to_string()),
            mesh,
            file: file.clone(),
            line: scan
                .first_line
                .get(k)
                .copied()
                .or(scan.untagged_line)
                .unwrap_or(1),
            triangles: 0,
            has_mtllib: !scan.mtllibs.is_empty(),
            missing_mtl: missing_mtl.clone(),
        });
    }

    // tobj, with a first line that makes it resolve every usemtl name to our slot index
    // (its own MTL loading is bypassed: the closure returns nothing for real files).
    let names_table = || -> tobj::MTLLoadResult {
        let mut table: tobj::MTLLoadResult = Ok((Vec::new(), Default::default()));
        if let Ok((mats, map)) = &mut table {
            for (i, key) in scan.keys.iter().enumerate() {
                mats.push(tobj::Material {
                    name: key.to_string(),
                    ..Default::default()
                });
                map.insert(key.to_string(), i);
            }
        }
        table
    };
    let prefix = format!("mtllib {NAMES_MTLLIB}\n");
    let mut reader = prefix.as_bytes().chain(text.as_bytes());
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let loaded = catch_unwind(AssertUnwindSafe(|| {
        tobj::load_obj_buf(&mut reader, &options, |p| {
            if p == Path::new(NAMES_MTLLIB) {
                names_table()
            } else {
                Ok((Vec::new(), Default::default()))
            }
        })
    }));
    let models = match loaded {
        Ok(Ok((models, _))) => models,
        Ok(Err(e)) => return Err(obj_error(text, &file, e)),
        Err(_) => {
            return Err(SceneError::parse(
                Location::file(&file),
                "the OBJ reader (tobj) failed on this file",
            ))
        }
    };

    let internal = |what: &str| {
        SceneError::parse(
            Location::file(&file),
            format!("internal error reading the OBJ: {what}"),
        )
    };
    // Per slot: whether its material has a texture, so that its triangles need their `vt`.
    let textured: Vec<bool> = (0..=n_keys)
        .map(|k| {
            let name = scan.names.get(k).map(|n| n.as_ref()).or(default_material);
            name.and_then(|n| mtl.defs.get(n))
                .is_some_and(|d| d.textured())
        })
        .collect();
    let mut g = 0; // triangle number in file order, indexes scan.flags
    let mut degenerate = 0usize;
    let mut bad_normals = 0usize;
    let mut without_vt = 0usize;
    let mut bad_vt = 0usize;
    out.triangles.reserve(scan.flags.len());
    for model in &models {
        let m = &model.mesh;
        let slot = match m.material_id {
            None => n_keys,
            Some(id) if id < n_keys => id,
            Some(_) => return Err(internal("unknown material id")),
        };
        let has_normals = !m.normals.is_empty() && m.normal_indices.len() == m.indices.len();
        let pos = |i: u32| -> Option<Vec3> {
            let i = i as usize * 3;
            m.positions.get(i..i + 3).map(Vec3::from_slice)
        };
        let nrm = |i: u32| -> Option<Vec3> {
            let i = i as usize * 3;
            m.normals.get(i..i + 3).map(Vec3::from_slice)
        };
        let has_texcoords = !m.texcoords.is_empty() && m.texcoord_indices.len() == m.indices.len();
        let tex = |i: u32| -> Option<Vec2> {
            let i = i as usize * 2;
            m.texcoords.get(i..i + 2).map(Vec2::from_slice)
        };
        for (t, idx) in m.indices.chunks_exact(3).enumerate() {
            let Some(&flag) = scan.flags.get(g) else {
                return Err(internal("more triangles than faces"));
            };
            g += 1;
            if flag & TRI_POLYLINE != 0 {
                continue;
            }
            let (Some(p0), Some(p1), Some(p2)) = (pos(idx[0]), pos(idx[1]), pos(idx[2])) else {
                return Err(internal("vertex index out of range"));
            };
            let v = [p0, p1, p2];
            if !v.iter().all(|p| p.is_finite()) {
                return Err(non_finite_vertex(text, &file));
            }
            let Some(ng) = super::geometric_normal(&v) else {
                degenerate += 1;
                continue;
            };
            let mut n = [ng; 3];
            if has_normals && flag & TRI_HAS_VN != 0 {
                for (k, nk) in n.iter_mut().enumerate() {
                    let vn = m.normal_indices.get(3 * t + k).and_then(|&i| nrm(i));
                    match vn.and_then(|x| x.try_normalize()) {
                        Some(x) => *nk = x,
                        None => bad_normals += 1,
                    }
                }
            }
            let attributes = textured[slot].then(|| {
                let mut uv = [Vec2::ZERO; 3];
                if has_texcoords && flag & TRI_HAS_VT != 0 {
                    for (k, uk) in uv.iter_mut().enumerate() {
                        let vt = m.texcoord_indices.get(3 * t + k).and_then(|&i| tex(i));
                        match vt {
                            // MTL's v grows upwards, the renderer's (glTF's) downwards.
                            Some(x) if x.is_finite() => *uk = Vec2::new(x.x, 1.0 - x.y),
                            _ => bad_vt += 1,
                        }
                    }
                } else {
                    without_vt += 1;
                }
                TriAttributes {
                    uv,
                    color: [Vec4::ONE; 3],
                }
            });
            out.push(
                Triangle {
                    v,
                    n,
                    material: (slot_base + slot) as u32,
                },
                attributes,
            );
            slots[slot_base + slot].triangles += 1;
        }
    }
    if g != scan.flags.len() {
        return Err(internal("fewer triangles than faces"));
    }
    if degenerate > 0 {
        log::warn!(
            "{file}: {degenerate} degenerate triangles (zero area, or edges beyond the 32-bit float range) dropped"
        );
    }
    if bad_normals > 0 {
        log::warn!(
            "{file}: {bad_normals} vn normals of zero length or not finite replaced by the geometric normal"
        );
    }
    if without_vt > 0 {
        log::warn!(
            "{file}: {without_vt} triangles of textured materials have no texture coordinates (vt): they are drawn with the texel at (0, 0)"
        );
    }
    if bad_vt > 0 {
        log::warn!("{file}: {bad_vt} texture coordinates (vt) that are not finite made 0");
    }
    let polylines = scan
        .flags
        .iter()
        .filter(|&&f| f & TRI_POLYLINE != 0)
        .count();
    if polylines > 0 {
        log::warn!("{file}: 'l' polylines ignored");
    }
    Ok(())
}

/// Turns a tobj error into one with a line: tobj's remaining failures (after
/// [`scan_obj`]) are numbers it cannot read in `v`, `vt`, `vn` lines.
pub(super) fn obj_error(text: &str, file: &str, e: tobj::LoadError) -> SceneError {
    use tobj::LoadError as E;
    match e {
        E::PositionParseError
        | E::ScalingByZeroError
        | E::ColorParseError
        | E::NormalParseError
        | E::TexcoordParseError => {
            if let Some((ln, message)) = find_bad_vertex_line(text) {
                return SceneError::parse(Location::line(file, ln), message);
            }
        }
        E::FaceVertexOutOfBounds | E::FaceNormalOutOfBounds | E::FaceTexCoordOutOfBounds => {
            // Indices are in range of the whole file (checked), so this is a forward
            // reference past the end of the face's object or group, which tobj cannot do.
            return SceneError::parse(
                Location::file(file),
                "a face refers to a vertex declared later in the file, after the face's object or group ends (move the vertices before the faces)",
            );
        }
        _ => {}
    }
    SceneError::parse(Location::file(file), format!("cannot read the OBJ: {e}"))
}

/// The first `v`, `vt` or `vn` line that tobj rejects, with tobj's rules.
pub(super) fn find_bad_vertex_line(text: &str) -> Option<(usize, String)> {
    let num = |w: Option<&str>| w.and_then(|w| w.parse::<f32>().ok());
    for (i, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let (need, what) = match words.next() {
            Some("v") => (3, "vertex position (v x y z [w] or v x y z r g b)"),
            Some("vt") => (2, "texture coordinate (vt u v)"),
            Some("vn") => (3, "normal (vn x y z)"),
            _ => continue,
        };
        let bad = || Some((i + 1, format!("cannot read {what}: '{}'", excerpt(line))));
        if !(0..need).all(|_| num(words.next()).is_some()) {
            return bad();
        }
        if need == 3 && line.split_whitespace().next() == Some("v") {
            let rest: Vec<&str> = words.collect();
            match rest.len() {
                0 | 3 => {}
                1 => match num(rest.first().copied()) {
                    Some(w) if w != 0.0 => {}
                    _ => return bad(),
                },
                _ => return bad(),
            }
        }
    }
    None
}

/// The error for a face that uses a vertex with a non-finite coordinate, located by
/// reading the text again (a cold path).
pub(super) fn non_finite_vertex(text: &str, file: &str) -> SceneError {
    let mut bad: HashMap<usize, usize> = HashMap::new(); // vertex index -> its line
    let mut nv = 0usize;
    let lines: Vec<&str> = text.lines().collect();
    for (i, line) in lines.iter().enumerate() {
        let mut words = line.split_whitespace();
        if words.next() != Some("v") {
            continue;
        }
        let vals: Vec<f32> = words.filter_map(|w| w.parse::<f32>().ok()).collect();
        let w = if vals.len() == 4 { vals[3] } else { 1.0 };
        if vals.iter().take(3).any(|x| !(x / w).is_finite()) {
            bad.insert(nv, i + 1);
        }
        nv += 1;
    }
    let mut seen = 0usize;
    for (i, line) in lines.iter().enumerate() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => seen += 1,
            Some("f") => {
                for corner in words {
                    let idx = corner
                        .split('/')
                        .next()
                        .and_then(|p| p.parse::<isize>().ok());
                    let v = match idx {
                        Some(x) if x < 0 => seen.checked_sub(x.unsigned_abs()),
                        Some(x) if x > 0 => Some(x as usize - 1),
                        _ => None,
                    };
                    if let Some(vl) = v.and_then(|v| bad.get(&v).map(|l| (v, *l))) {
                        return SceneError::invalid(
                            Location::line(file, i + 1),
                            format!(
                                "face uses vertex {} whose coordinates are not finite (line {}: '{}')",
                                vl.0 + 1,
                                vl.1,
                                excerpt(lines[vl.1 - 1])
                            ),
                        );
                    }
                }
            }
            _ => {}
        }
    }
    SceneError::invalid(
        Location::file(file),
        "a face uses a vertex whose coordinates are not finite",
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scan_counts_fanned_triangles_and_flags() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvn 0 0 1\nf 1 2 3 4\nusemtl m\nf 1//1 2//1 3//1\nl 1 2 3\nf 1 2\n";
        let s = scan_obj(text, "t.obj").unwrap();
        assert_eq!(s.flags, [0, 0, TRI_HAS_VN, TRI_POLYLINE]);
        assert_eq!(s.untagged_line, Some(6));
        assert_eq!(s.keys, ["m"]);
        assert_eq!(s.small_faces, 1);
        assert_eq!(s.counts, [4, 0, 1]);
        let s = scan_obj("v 0 0 0\nvt 0 0\nf 1/1 1/1 1/1\nf 1/1 1 1\n", "t.obj").unwrap();
        assert_eq!(s.flags, [TRI_HAS_VT, 0]);
    }

    #[test]
    fn scan_reports_the_first_bad_line() {
        // A forward reference beyond the file (line 1) comes before the zero (line 2).
        let e = scan_obj("f 1 2 9\nf 0 1 2\nv 0 0 0\n", "t.obj").unwrap_err();
        let e = e.to_string();
        assert!(e.starts_with("t.obj:1: face index "), "{e}");
        assert!(
            e.ends_with(" out of range (the file has 1 vertices)"),
            "{e}"
        );
        let e = scan_obj("v 0 0 0\nf 1 1 1\nf 1 1 0\nf 1 1 5\n", "t.obj").unwrap_err();
        assert!(e.to_string().starts_with("t.obj:3: face index 0"));
    }
}
