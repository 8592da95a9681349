//! `#import` lines of WGSL: a file names the modules it uses on lines `#import name`, one
//! per line, before any code (blank lines and `//` comments may come before and between
//! them). Resolving a file puts every module it needs before it, depth first, each module
//! once, a module's own imports before the module.

use std::fmt;

/// Why a shader could not be put together.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ResolveError {
    /// `importer` imports `module`, which no table entry names.
    UnknownModule { importer: String, module: String },
    /// The modules import each other in a circle: each imports the next, the last the first.
    Cycle(Vec<String>),
    /// An `#import` line of `module` (1-based `line`) after a line of code.
    ImportAfterCode { module: String, line: usize },
    /// An `#import` line of `module` with no name, or more than one word after `#import`.
    MalformedImport { module: String, line: usize },
}

impl fmt::Display for ResolveError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ResolveError::UnknownModule { importer, module } => {
                write!(f, "{importer} imports {module}, which is no known module")
            }
            ResolveError::Cycle(path) => {
                write!(f, "import cycle: {} -> {}", path.join(" -> "), path[0])
            }
            ResolveError::ImportAfterCode { module, line } => {
                write!(f, "{module}, line {line}: #import after code")
            }
            ResolveError::MalformedImport { module, line } => {
                write!(f, "{module}, line {line}: #import takes one module name")
            }
        }
    }
}

impl std::error::Error for ResolveError {}

const IMPORT: &str = "#import";

/// The modules `source` (called `name` in errors) imports, in the order written.
pub fn imports<'a>(name: &str, source: &'a str) -> Result<Vec<&'a str>, ResolveError> {
    let mut found = Vec::new();
    let mut code = false;
    for (i, line) in source.lines().enumerate() {
        let line = line.trim();
        if let Some(rest) = line.strip_prefix(IMPORT) {
            let module = name.to_string();
            if code {
                return Err(ResolveError::ImportAfterCode {
                    module,
                    line: i + 1,
                });
            }
            let mut words = rest.split_whitespace();
            match (words.next(), words.next()) {
                (Some(import), None) if rest.starts_with(char::is_whitespace) => found.push(import),
                _ => {
                    return Err(ResolveError::MalformedImport {
                        module,
                        line: i + 1,
                    })
                }
            }
        } else if !line.is_empty() && !line.starts_with("//") {
            code = true;
        }
    }
    Ok(found)
}

/// `source` without its `#import` lines.
fn body(source: &str) -> String {
    let mut out = String::with_capacity(source.len());
    for line in source.lines() {
        if !line.trim_start().starts_with(IMPORT) {
            out.push_str(line);
            out.push('\n');
        }
    }
    out
}

/// `root` (called `name`) after every module it imports, directly or not: depth first,
/// each module once, each after its own imports. `lookup` gives a module's source by name.
pub fn resolve<'a>(
    name: &str,
    root: &str,
    lookup: impl Fn(&str) -> Option<&'a str>,
) -> Result<String, ResolveError> {
    let mut done: Vec<String> = Vec::new();
    let mut visiting: Vec<String> = vec![name.to_string()];
    let mut out = String::new();
    for import in imports(name, root)? {
        visit(name, import, &lookup, &mut visiting, &mut done, &mut out)?;
    }
    out.push_str(&body(root));
    Ok(out)
}

fn visit<'a>(
    importer: &str,
    module: &str,
    lookup: &impl Fn(&str) -> Option<&'a str>,
    visiting: &mut Vec<String>,
    done: &mut Vec<String>,
    out: &mut String,
) -> Result<(), ResolveError> {
    if done.iter().any(|d| d == module) {
        return Ok(());
    }
    if let Some(start) = visiting.iter().position(|v| v == module) {
        return Err(ResolveError::Cycle(visiting[start..].to_vec()));
    }
    let source = lookup(module).ok_or_else(|| ResolveError::UnknownModule {
        importer: importer.to_string(),
        module: module.to_string(),
    })?;
    visiting.push(module.to_string());
    for import in imports(module, source)? {
        visit(module, import, lookup, visiting, done, out)?;
    }
    visiting.pop();
    out.push_str(&body(source));
    out.push('\n');
    done.push(module.to_string());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table<'a>(modules: &'a [(&'a str, &'a str)]) -> impl Fn(&str) -> Option<&'a str> {
        move |name| modules.iter().find(|(n, _)| *n == name).map(|(_, s)| *s)
    }

    #[test]
    fn dependencies_come_first_each_once() {
        let modules = [
            ("a", "// a\nconst A = 1;"),
            ("b", "#import a\nconst B = A;"),
            ("c", "#import a\n#import b\nconst C = B;"),
        ];
        let out = resolve(
            "root",
            "#import c\n#import b\nconst R = C;",
            table(&modules),
        )
        .unwrap();
        assert_eq!(
            out,
            "// a\nconst A = 1;\n\nconst B = A;\n\nconst C = B;\n\nconst R = C;\n"
        );
    }

    #[test]
    fn comments_and_blank_lines_may_come_before_imports() {
        let modules = [("a", "const A = 1;")];
        let root = "// root: what it does\n\n  #import a\n// more\nconst R = A;";
        let out = resolve("root", root, table(&modules)).unwrap();
        assert_eq!(
            out,
            "const A = 1;\n\n// root: what it does\n\n// more\nconst R = A;\n"
        );
    }

    #[test]
    fn no_imports_is_the_file_itself() {
        let out = resolve("root", "const R = 1;\n", table(&[])).unwrap();
        assert_eq!(out, "const R = 1;\n");
    }

    #[test]
    fn an_unknown_module_is_an_error() {
        let modules = [("a", "#import nowhere\nconst A = 1;")];
        assert_eq!(
            resolve("root", "#import a", table(&modules)),
            Err(ResolveError::UnknownModule {
                importer: "a".into(),
                module: "nowhere".into()
            })
        );
    }

    #[test]
    fn a_cycle_is_an_error() {
        let modules = [
            ("a", "#import b\nconst A = 1;"),
            ("b", "#import c\nconst B = 1;"),
            ("c", "#import a\nconst C = 1;"),
        ];
        let err = resolve("root", "#import a", table(&modules)).unwrap_err();
        assert_eq!(
            err,
            ResolveError::Cycle(vec!["a".into(), "b".into(), "c".into()])
        );
        assert_eq!(err.to_string(), "import cycle: a -> b -> c -> a");
        // A module importing itself, and the root imported back.
        let modules = [("s", "#import s")];
        assert_eq!(
            resolve("root", "#import s", table(&modules)),
            Err(ResolveError::Cycle(vec!["s".into()]))
        );
        let modules = [("s", "#import root")];
        assert_eq!(
            resolve("root", "#import s", table(&modules)),
            Err(ResolveError::Cycle(vec!["root".into(), "s".into()]))
        );
    }

    #[test]
    fn an_import_after_code_is_an_error() {
        let modules = [("a", "const A = 1;"), ("b", "const B = 1;\n#import a")];
        assert_eq!(
            resolve(
                "root",
                "#import a\nconst R = 1;\n\n#import b",
                table(&modules)
            ),
            Err(ResolveError::ImportAfterCode {
                module: "root".into(),
                line: 4
            })
        );
        assert_eq!(
            resolve("root", "#import b", table(&modules)),
            Err(ResolveError::ImportAfterCode {
                module: "b".into(),
                line: 2
            })
        );
    }

    #[test]
    fn an_import_names_one_module() {
        for bad in ["#import", "#import a b", "#importa"] {
            assert_eq!(
                imports("root", bad),
                Err(ResolveError::MalformedImport {
                    module: "root".into(),
                    line: 1
                }),
                "{bad}"
            );
        }
        assert_eq!(
            imports("root", "#import a // why"),
            Err(ResolveError::MalformedImport {
                module: "root".into(),
                line: 1
            })
        );
    }
}
