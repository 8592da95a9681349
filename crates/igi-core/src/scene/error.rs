//! The loader's error type, [`SceneError`], with the [`Location`] it names, and the helpers
//! that keep its messages on one line (quoting file contents and paths), plus the reading
//! of a file's bytes as text, whose failures are errors of this kind.

use std::borrow::Cow;
use std::io;
use std::path::PathBuf;

/// Where in which file an error is: `file`, `file:line` or `file:line:column` (1-based).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Location {
    pub file: String,
    pub line: Option<usize>,
    pub column: Option<usize>,
}

impl Location {
    pub(super) fn file(file: &str) -> Self {
        Location {
            file: one_line(file),
            line: None,
            column: None,
        }
    }

    pub(super) fn line(file: &str, line: usize) -> Self {
        Location {
            line: Some(line),
            ..Location::file(file)
        }
    }

    /// The line and column (in characters) of byte `offset` of `text`.
    pub(super) fn offset(file: &str, text: &str, offset: usize) -> Self {
        let mut offset = offset.min(text.len());
        while !text.is_char_boundary(offset) {
            offset -= 1;
        }
        let before = &text[..offset];
        let line = before.matches('\n').count() + 1;
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        Location {
            line: Some(line),
            column: Some(before[line_start..].chars().count() + 1),
            ..Location::file(file)
        }
    }
}

impl std::fmt::Display for Location {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.file)?;
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
            if let Some(column) = self.column {
                write!(f, ":{column}")?;
            }
        }
        Ok(())
    }
}

/// Why a scene could not be loaded. Its `Display` is one line naming the file.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// A file could not be read: missing, unreadable, a directory.
    #[error("cannot read {what} '{}'{}: {}", quote_path(&.path.display().to_string()), context_suffix(.context), io_message(.error))]
    Read {
        /// "scene file", "mesh" or "material library".
        what: &'static str,
        path: PathBuf,
        /// Who referenced the file, e.g. "referenced by scene.toml".
        context: Option<String>,
        /// The cause, whose message the error's own includes (so it is not also its
        /// `source()`, which would print it twice in a chain of causes).
        error: io::Error,
    },
    /// The file is not well-formed: TOML syntax or types, OBJ or MTL syntax, not text.
    #[error("{at}: {message}")]
    Parse { at: Location, message: String },
    /// The file is well-formed but describes no valid scene (a value out of range, a
    /// material defined nowhere, no lights, ...).
    #[error("{at}: {message}")]
    Invalid { at: Location, message: String },
}

impl SceneError {
    pub(super) fn parse(at: Location, message: impl AsRef<str>) -> Self {
        SceneError::Parse {
            at,
            message: one_line(message.as_ref()),
        }
    }

    pub(super) fn invalid(at: Location, message: impl AsRef<str>) -> Self {
        SceneError::Invalid {
            at,
            message: one_line(message.as_ref()),
        }
    }

    /// Where the error is, when it is in a file's content.
    pub fn location(&self) -> Option<&Location> {
        match self {
            SceneError::Read { .. } => None,
            SceneError::Parse { at, .. } | SceneError::Invalid { at, .. } => Some(at),
        }
    }
}

pub(super) fn context_suffix(context: &Option<String>) -> String {
    match context {
        Some(c) => format!(" ({})", one_line(c)),
        None => String::new(),
    }
}

/// The OS message without its " (os error 2)" tail: "No such file or directory".
pub(super) fn io_message(e: &io::Error) -> String {
    one_line(without_os_error_code(&e.to_string()))
}

/// `text` without the " (os error 2)" tail that Rust adds to an OS error's message (the
/// message says it in words); the `igi` command drops it from every error it prints.
pub fn without_os_error_code(text: &str) -> &str {
    match text.rfind(" (os error ") {
        Some(i) if text.ends_with(')') => &text[..i],
        _ => text,
    }
}

/// Messages quote file contents and paths: keep them on one line.
pub(super) fn one_line(s: &str) -> String {
    s.chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect()
}

/// The most characters of a name, word or value from a file that a message quotes whole.
pub const QUOTED_CHARS: usize = 80;

/// The most characters of a path from a file (a mesh, a material library, a buffer) that a
/// message quotes whole: more than a real path needs, so that only hostile text is cut.
pub const QUOTED_PATH_CHARS: usize = 300;

/// How many characters of a line of a file [`excerpt`] keeps.
const EXCERPT_CHARS: usize = 60;

/// Text from a file as a message quotes it: on one line, and past `max` characters cut
/// to its first `max`, an ellipsis and, when `note_length`, its full length, so that a
/// 150 KB material name makes a readable message (`nnnn... (150000 characters)`), not a
/// 300,000-character line. Every loader message that quotes a file goes through here.
fn shorten(text: &str, max: usize, note_length: bool) -> String {
    match text.char_indices().nth(max) {
        Some((i, _)) if note_length => format!(
            "{}... ({} characters)",
            one_line(&text[..i]),
            text.chars().count()
        ),
        Some((i, _)) => format!("{}...", one_line(&text[..i])),
        None => one_line(text),
    }
}

/// A name, word or value from a file (a material name, a face index, a URI), for a
/// message: at most [`QUOTED_CHARS`] characters, with the full length when cut.
pub(super) fn quote(text: &str) -> String {
    shorten(text, QUOTED_CHARS, true)
}

/// A path from a file, for a message: at most [`QUOTED_PATH_CHARS`] characters, with the
/// full length when cut.
pub(super) fn quote_path(path: &str) -> String {
    shorten(path, QUOTED_PATH_CHARS, true)
}

/// Another crate's message about the file (the toml, JSON and glTF crates quote the
/// file's keys and values between backticks or double quotes): each part between those
/// quotes shortened as [`quote`] does.
pub(super) fn quote_message(message: &str) -> String {
    let mut out = String::new();
    let mut rest = message;
    while let Some(i) = rest.find(['`', '"']) {
        out.push_str(&quote(&rest[..i]));
        out.push_str(&rest[i..=i]);
        rest = &rest[i + 1..];
    }
    out.push_str(&quote(rest));
    out
}

/// A line of a file, trimmed and shortened for a message (the line is what is wrong, its
/// length is not).
pub(super) fn excerpt(line: &str) -> String {
    shorten(line.trim(), EXCERPT_CHARS, false)
}

pub(super) fn fmt3(v: [f32; 3]) -> String {
    format!("[{}, {}, {}]", v[0], v[1], v[2])
}

pub(super) const CHANNELS: [&str; 3] = ["red", "green", "blue"];

/// The line (1-based) of byte `offset`.
pub(super) fn line_at(bytes: &[u8], offset: usize) -> usize {
    bytes[..offset.min(bytes.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// The TOML file as text (TOML must be UTF-8), or an error naming the line of the first
/// byte that is not UTF-8.
pub(super) fn as_text<'a>(bytes: &'a [u8], file: &str) -> Result<&'a str, SceneError> {
    match std::str::from_utf8(bytes) {
        Ok(text) => Ok(text.strip_prefix('\u{feff}').unwrap_or(text)),
        Err(e) => {
            let at = e.valid_up_to();
            Err(SceneError::parse(
                Location::line(file, line_at(bytes, at)),
                format!(
                    "not a text file: byte 0x{:02x} at offset {at} is not UTF-8",
                    bytes.get(at).copied().unwrap_or(0)
                ),
            ))
        }
    }
}

/// An OBJ or MTL file as text. A NUL byte means binary data: an error. Other bytes that
/// are not UTF-8 (a Latin-1 comment or material name, say) are replaced by U+FFFD with a
/// warning, as the reference converter reads these files (`errors="replace"`). Lines may
/// end in LF, CRLF or a lone CR (classic Mac OS files): a lone CR becomes an LF, because
/// tobj and our own passes split lines at LF only, and such a file was one long line
/// without a face.
pub(super) fn as_lenient_text<'a>(bytes: &'a [u8], file: &str) -> Result<Cow<'a, str>, SceneError> {
    match lone_cr_as_lf(bytes) {
        None => lenient_text(bytes, file),
        Some(fixed) => lenient_text(&fixed, file).map(|t| Cow::Owned(t.into_owned())),
    }
}

/// `bytes` with every CR that is not followed by an LF turned into an LF, or `None` when
/// there is none. One byte for one, so offsets (and line numbers) stay those of the file.
fn lone_cr_as_lf(bytes: &[u8]) -> Option<Vec<u8>> {
    let lone = |i: usize| bytes[i] == b'\r' && bytes.get(i + 1) != Some(&b'\n');
    // `contains` is a fast byte search; most files have no CR or only CRLFs.
    if !bytes.contains(&b'\r') || !(0..bytes.len()).any(lone) {
        return None;
    }
    Some(
        (0..bytes.len())
            .map(|i| if lone(i) { b'\n' } else { bytes[i] })
            .collect(),
    )
}

fn lenient_text<'a>(bytes: &'a [u8], file: &str) -> Result<Cow<'a, str>, SceneError> {
    // `contains` searches bytes with memchr, many at a time, several times faster than a
    // byte loop over a large mesh; the offset is only wanted for the error.
    if bytes.contains(&0) {
        let at = bytes.iter().position(|&b| b == 0).unwrap_or(0);
        return Err(SceneError::parse(
            Location::line(file, line_at(bytes, at)),
            format!("not a text file: a NUL byte at offset {at} (binary data?)"),
        ));
    }
    let text = match std::str::from_utf8(bytes) {
        Ok(text) => Cow::Borrowed(text),
        Err(e) => {
            log::warn!(
                "{file}:{}: bytes that are not UTF-8 replaced by U+FFFD",
                line_at(bytes, e.valid_up_to())
            );
            String::from_utf8_lossy(bytes)
        }
    };
    Ok(match text {
        Cow::Borrowed(t) => Cow::Borrowed(t.strip_prefix('\u{feff}').unwrap_or(t)),
        Cow::Owned(t) => match t.strip_prefix('\u{feff}') {
            Some(rest) => Cow::Owned(rest.to_string()),
            None => Cow::Owned(t),
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn location_of_an_offset_counts_lines_and_characters() {
        let text = "a = 1\nbé = [1, 2]\n";
        let at = Location::offset("s.toml", text, text.find('[').unwrap());
        assert_eq!(at.to_string(), "s.toml:2:6");
        assert_eq!(
            Location::offset("s.toml", text, 0).to_string(),
            "s.toml:1:1"
        );
        // Past the end and inside a character: clamped, no panic.
        assert_eq!(Location::offset("s.toml", text, 999).line, Some(3));
        assert_eq!(
            Location::offset("s.toml", text, 8).to_string(),
            "s.toml:2:2"
        );
        assert_eq!(Location::file("x.obj").to_string(), "x.obj");
        assert_eq!(Location::line("x.obj", 7).to_string(), "x.obj:7");
    }

    #[test]
    fn messages_are_one_line() {
        assert_eq!(one_line("a\nb\r\tc"), "a b  c");
        let e = io::Error::from_raw_os_error(2);
        assert_eq!(io_message(&e), "No such file or directory");
        assert_eq!(excerpt(&"x".repeat(100)).len(), 63);
        let e = SceneError::invalid(Location::file("f\ng"), "two\nlines");
        assert_eq!(e.to_string(), "f g: two lines");
    }

    #[test]
    fn long_quoted_text_is_cut_with_its_length() {
        assert_eq!(quote("short\nname"), "short name");
        let long = "é".repeat(QUOTED_CHARS + 1);
        let q = quote(&long);
        assert!(q.starts_with(&"é".repeat(QUOTED_CHARS)), "{q}");
        assert!(
            q.ends_with(&format!("... ({} characters)", QUOTED_CHARS + 1)),
            "{q}"
        );
        assert_eq!(quote(&"x".repeat(QUOTED_CHARS)), "x".repeat(QUOTED_CHARS));
        // Each part of another crate's message between quotes is cut on its own.
        let key = "k".repeat(1000);
        let m = quote_message(&format!("unknown field `{key}`, expected `eye` or \"up\""));
        assert_eq!(
            m,
            format!(
                "unknown field `{}... (1000 characters)`, expected `eye` or \"up\"",
                "k".repeat(QUOTED_CHARS)
            )
        );
        assert!(quote_path(&"p".repeat(5000)).chars().count() < QUOTED_PATH_CHARS + 30);
    }
}
