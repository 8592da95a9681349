//! The glTF reader's messages: one line each, naming the file and the mesh, primitive,
//! accessor or buffer at fault, and the gltf crate's JSON, validation and GLB errors
//! turned into such lines.

use super::MAX_LISTED;
pub(super) use crate::scene::error::{one_line, quote, quote_message, quote_path};
use crate::scene::loader::{Location, SceneError};

pub(super) fn at(file: &str) -> Location {
    Location {
        file: one_line(file),
        line: None,
        column: None,
    }
}

/// The file is not well-formed glTF (syntax, structure, references, byte ranges).
pub(super) fn parse(file: &str, message: impl AsRef<str>) -> SceneError {
    SceneError::Parse {
        at: at(file),
        message: one_line(message.as_ref()),
    }
}

/// The file is well-formed but its values are not usable (non-finite, out of range).
pub(super) fn invalid(file: &str, message: impl AsRef<str>) -> SceneError {
    SceneError::Invalid {
        at: at(file),
        message: one_line(message.as_ref()),
    }
}

pub(super) fn fmt3(v: [f32; 3]) -> String {
    format!("[{}, {}, {}]", v[0], v[1], v[2])
}

/// "mesh 2" or "mesh 2 ('Chair')".
pub(super) fn mesh_label(mesh: &::gltf::Mesh) -> String {
    match mesh.name() {
        Some(n) => format!("mesh {} ('{}')", mesh.index(), quote(n)),
        None => format!("mesh {}", mesh.index()),
    }
}

/// A serde_json error of the glTF JSON: its message without the " at line L column C"
/// tail, and the line and column (0 when unknown).
pub(super) fn json_error(e: &::gltf::json::Error) -> (String, usize, usize) {
    let full = e.to_string();
    let tail = format!(" at line {} column {}", e.line(), e.column());
    let message = quote_message(full.strip_suffix(&tail).unwrap_or(&full));
    (message, e.line(), e.column())
}

/// The first problems of a failed validation, with their JSON paths.
pub(super) fn validation_message(
    problems: &[(::gltf::json::Path, ::gltf::json::validation::Error)],
) -> String {
    let listed: Vec<String> = problems
        .iter()
        .take(MAX_LISTED)
        .map(|(path, e)| quote_message(&format!("{path}: {}", e.to_string().to_lowercase())))
        .collect();
    let more = match problems.len().saturating_sub(MAX_LISTED) {
        0 => String::new(),
        n => format!(" (and {n} more)"),
    };
    format!("invalid glTF: {}{more}", listed.join("; "))
}

/// What is wrong with a GLB's structure (the crate's own messages omit the numbers).
pub(super) fn glb_message(e: &::gltf::binary::Error) -> String {
    use ::gltf::binary::{ChunkType, Error as E};
    let chunk = |ty: &ChunkType| match ty {
        ChunkType::Json => "JSON",
        ChunkType::Bin => "BIN",
    };
    match e {
        E::Version(v) => format!("version {v} (only version 2 is read)"),
        E::Length {
            length,
            length_read,
        } => format!(
            "the header says {} bytes but the file has {}",
            u64::from(*length) + 12,
            length_read + 12
        ),
        E::ChunkLength {
            ty,
            length,
            length_read,
        } => format!(
            "the {} chunk says {length} bytes but only {length_read} follow",
            chunk(ty)
        ),
        E::ChunkType(ty) => format!(
            "unexpected {} chunk (a JSON chunk comes first, then at most one BIN chunk)",
            chunk(ty)
        ),
        E::UnknownChunkType(t) => format!(
            "unknown chunk type '{}'",
            one_line(&String::from_utf8_lossy(t))
        ),
        E::Io(e) => format!("truncated ({e})"),
        e => e.to_string(),
    }
}

/// A gltf crate error while reading the document, as a scene error.
pub(super) fn document_error(e: ::gltf::Error, file: &str, is_glb: bool) -> SceneError {
    match e {
        ::gltf::Error::Deserialize(e) => {
            let (message, line, column) = json_error(&e);
            let what = if e.is_data() {
                "invalid glTF JSON"
            } else {
                "not a glTF file: cannot read its JSON"
            };
            if is_glb {
                parse(
                    file,
                    format!("{what} (GLB JSON chunk, line {line} column {column}): {message}"),
                )
            } else if line > 0 {
                SceneError::Parse {
                    at: Location {
                        file: one_line(file),
                        line: Some(line),
                        column: Some(column.max(1)),
                    },
                    message: one_line(&format!("{what}: {message}")),
                }
            } else {
                parse(file, format!("{what}: {message}"))
            }
        }
        ::gltf::Error::Binary(e) => parse(
            file,
            format!("not a valid GLB (binary glTF) file: {}", glb_message(&e)),
        ),
        ::gltf::Error::Validation(problems) => parse(file, validation_message(&problems)),
        e => parse(
            file,
            format!(
                "cannot read the glTF file: {}",
                quote_message(&e.to_string())
            ),
        ),
    }
}
