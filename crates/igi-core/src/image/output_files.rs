//! Output files written all or none: each output of a run gets a temporary file beside
//! its target when the run starts ([`OutputFiles::reserve`]), so that a folder that takes
//! no files, a name that cannot be made or a target that is not a regular file is an
//! error before any work is done; the images go into the temporary files, and only when
//! every one of them is complete are they renamed into place ([`OutputFiles::commit`]).
//! A run that fails or is interrupted leaves neither its outputs nor temporary files.

use super::ImageError;
use std::fs::File;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::{Mutex, MutexGuard};

/// The longest file name Linux and macOS file systems take, in bytes (NAME_MAX).
const NAME_MAX: usize = 255;

/// The file that writing `path` replaces: `path` with its symbolic links followed (the
/// link stays and its target gets the new contents, as a shell's `>` does), in a
/// directory named canonically, so that two names of one file compare equal. Errors,
/// before anything is rendered or written, where no file could be put there: a missing
/// directory, or an existing entry that is not a regular file (a FIFO, a pipe such as
/// `/dev/stdout` of a command in a pipeline, or a device must not be replaced by a rename,
/// and a directory cannot be).
pub fn output_target(path: &Path) -> Result<PathBuf, ImageError> {
    let err = |reason: String| ImageError::Write {
        path: path.to_path_buf(),
        reason,
    };
    // A trailing '/' names a directory: the OS would say "Not a directory" of a file
    // there, and without one the name would be written as a file.
    if path.as_os_str().as_encoded_bytes().ends_with(b"/") {
        return Err(err(
            "that names a directory (it ends in '/'); give a file name".into(),
        ));
    }
    // What the name leads to, links followed by the OS: /dev/stdout and /proc/self/fd/N
    // lead to a pipe or terminal although the link they name (pipe:[N]) is no path.
    if let Ok(meta) = std::fs::metadata(path) {
        if meta.is_dir() {
            return Err(err(
                "a directory, not a regular file: give a file name".into()
            ));
        }
        if !meta.is_file() {
            return Err(err(
                "not a regular file (a directory, device or pipe): igi writes image files only"
                    .into(),
            ));
        }
    }
    let mut target = path.to_path_buf();
    // Linux gives up on a chain of 40 links (ELOOP); so does this.
    for _ in 0..40 {
        match std::fs::symlink_metadata(&target) {
            Ok(meta) if meta.file_type().is_symlink() => {
                let link = std::fs::read_link(&target).map_err(|e| err(e.to_string()))?;
                target = match target.parent() {
                    Some(dir) => dir.join(link),
                    None => link,
                };
            }
            Ok(meta) if meta.is_dir() => {
                return Err(err(
                    "a directory, not a regular file: give a file name".into()
                ))
            }
            Ok(meta) if !meta.is_file() => {
                return Err(err(
                    "not a regular file (a directory, device or pipe)".into()
                ))
            }
            _ => {
                let name = target
                    .file_name()
                    .ok_or_else(|| err("not a file name".into()))?;
                if name.len() > NAME_MAX {
                    return Err(err(format!(
                        "the file name is {} bytes long; file systems take at most {NAME_MAX}",
                        name.len()
                    )));
                }
                let dir = match target.parent() {
                    Some(d) if !d.as_os_str().is_empty() => d,
                    _ => Path::new("."),
                };
                if dir.exists() && !dir.is_dir() {
                    return Err(err(format!(
                        "'{}' exists and is not a directory",
                        dir.display()
                    )));
                }
                if !dir.is_dir() {
                    return Err(err(format!("directory '{}' does not exist", dir.display())));
                }
                let dir = dir.canonicalize().map_err(|e| err(e.to_string()))?;
                return Ok(dir.join(name));
            }
        }
    }
    Err(err("too many levels of symbolic links".into()))
}

/// Temporary files being written now, so that a signal handler can remove them
/// ([`remove_partial_files`]) before the process exits.
static PARTIAL_FILES: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn partial_files() -> MutexGuard<'static, Vec<PathBuf>> {
    // The list stays valid whatever a panicking holder did: each change is one push or
    // one retain.
    PARTIAL_FILES
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Remove every temporary file of the [`OutputFiles`] in flight, and keep any other from
/// being created or renamed into place: for a handler of SIGINT or SIGTERM, which exits
/// right after. Writers that get here later wait until the process is gone.
pub fn remove_partial_files() {
    let partial = partial_files();
    for p in partial.iter() {
        let _ = std::fs::remove_file(p);
    }
    // Held until the process exits: a writer neither creates a temporary file after the
    // removal nor renames one that the removal missed.
    std::mem::forget(partial);
}

/// The temporary name of an output called `name`: `.NAME.PID-N.partial`, with NAME cut
/// (at a character boundary) where the whole would pass [`NAME_MAX`], so that any name
/// that may be written may also be written through its temporary file. N counts the
/// outputs of the process, so that two long names cut alike stay apart.
fn temporary_name(name: &str) -> String {
    static OUTPUTS: AtomicU32 = AtomicU32::new(0);
    let tail = format!(
        ".{}-{}.partial",
        std::process::id(),
        OUTPUTS.fetch_add(1, Ordering::Relaxed)
    );
    let room = NAME_MAX - 1 - tail.len();
    let mut end = name.len().min(room);
    while !name.is_char_boundary(end) {
        end -= 1;
    }
    format!(".{}{tail}", &name[..end])
}

/// One reserved output: its name as given, the file it replaces and its temporary file.
struct Reserved {
    path: PathBuf,
    target: PathBuf,
    tmp: PathBuf,
    /// Open from the reservation until the output is written.
    file: Option<File>,
    written: bool,
}

/// The outputs of one run, written all or none (see the module's documentation).
pub struct OutputFiles {
    files: Vec<Reserved>,
}

impl OutputFiles {
    /// Checks each output's target ([`output_target`]) and creates its temporary file
    /// now: a folder where nothing can be created fails here, before any work.
    pub fn reserve<'a>(
        paths: impl IntoIterator<Item = &'a Path>,
    ) -> Result<OutputFiles, ImageError> {
        let mut outputs = OutputFiles { files: vec![] };
        for path in paths {
            let err = |reason: String| ImageError::Write {
                path: path.to_path_buf(),
                reason,
            };
            let target = output_target(path)?;
            let (dir, name) = match (target.parent(), target.file_name()) {
                (Some(dir), Some(name)) => (dir, name.to_string_lossy()),
                _ => return Err(err("not a file name".into())),
            };
            let tmp = dir.join(temporary_name(&name));
            let mut partial = partial_files();
            // Anything under this name was left by a dead process that had this id.
            let _ = std::fs::remove_file(&tmp);
            let file = File::options()
                .write(true)
                .create_new(true)
                .open(&tmp)
                .map_err(|e| {
                    // The directory exists (output_target checked), so "not found" means
                    // it takes no new files (/proc, /sys): the OS's words alone would say
                    // that the output itself is missing.
                    err(match e.kind() {
                        std::io::ErrorKind::NotFound => {
                            format!("directory '{}' takes no new files", dir.display())
                        }
                        _ => format!("cannot create a file in '{}': {e}", dir.display()),
                    })
                })?;
            partial.push(tmp.clone());
            drop(partial);
            outputs.files.push(Reserved {
                path: path.to_path_buf(),
                target,
                tmp,
                file: Some(file),
                written: false,
            });
        }
        Ok(outputs)
    }

    /// Writes the output reserved as `path` through `write`, into its temporary file.
    pub fn write(
        &mut self,
        path: &Path,
        write: impl FnOnce(&mut File) -> Result<(), String>,
    ) -> Result<(), ImageError> {
        let err = |reason: String| ImageError::Write {
            path: path.to_path_buf(),
            reason,
        };
        let reserved = self
            .files
            .iter_mut()
            .find(|r| r.path == path)
            .ok_or_else(|| err("internal error: the output was not reserved".into()))?;
        let mut file = reserved
            .file
            .take()
            .ok_or_else(|| err("internal error: the output was written twice".into()))?;
        write(&mut file).map_err(err)?;
        reserved.written = true;
        Ok(())
    }

    /// Renames every written output into place, once each one is written and its
    /// temporary file is still there (its folder may have gone meanwhile): then none is
    /// renamed.
    pub fn commit(mut self) -> Result<(), ImageError> {
        for r in &self.files {
            let err = |reason: String| ImageError::Write {
                path: r.path.clone(),
                reason,
            };
            if !r.written {
                return Err(err("internal error: the output was not written".into()));
            }
            if std::fs::symlink_metadata(&r.tmp).is_err() {
                return Err(err(format!(
                    "its temporary file '{}' has gone (was its folder removed?)",
                    r.tmp.display()
                )));
            }
        }
        let mut partial = partial_files();
        // Each output leaves the list once renamed: what is left when a rename fails is
        // what Drop removes.
        while !self.files.is_empty() {
            let r = &self.files[0];
            std::fs::rename(&r.tmp, &r.target).map_err(|e| ImageError::Write {
                path: r.path.clone(),
                reason: e.to_string(),
            })?;
            partial.retain(|p| p != &r.tmp);
            self.files.remove(0);
        }
        Ok(())
    }
}

impl Drop for OutputFiles {
    /// Removes the temporary files of outputs that were not renamed into place.
    fn drop(&mut self) {
        let mut partial = partial_files();
        for r in &self.files {
            let _ = std::fs::remove_file(&r.tmp);
            partial.retain(|p| p != &r.tmp);
        }
    }
}

/// Write through `write` to a temporary file beside the target of `path` (see
/// [`output_target`], checked first), then rename it into place: an [`OutputFiles`] of
/// one output.
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut File) -> Result<(), String>,
) -> Result<(), ImageError> {
    let mut outputs = OutputFiles::reserve([path])?;
    outputs.write(path, write)?;
    outputs.commit()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fresh_dir(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("igi-outputs-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn write_bytes(bytes: &'static [u8]) -> impl FnOnce(&mut File) -> Result<(), String> {
        move |f| std::io::Write::write_all(f, bytes).map_err(|e| e.to_string())
    }

    #[test]
    fn outputs_are_renamed_together_or_not_at_all() {
        let dir = fresh_dir("together");
        let (a, b) = (dir.join("a.png"), dir.join("sub/b.exr"));
        std::fs::create_dir(dir.join("sub")).unwrap();
        let mut outputs = OutputFiles::reserve([a.as_path(), b.as_path()]).unwrap();
        outputs.write(&a, write_bytes(b"a")).unwrap();
        // The second output's folder goes while the run works.
        std::fs::remove_dir_all(dir.join("sub")).unwrap();
        outputs.write(&b, write_bytes(b"b")).unwrap();
        let e = outputs.commit().unwrap_err().to_string();
        assert!(e.contains("b.exr") && e.contains("has gone"), "{e}");
        // Neither output, and no temporary file.
        let left: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert!(left.is_empty(), "{left:?}");
        // A failed write leaves nothing either.
        let mut outputs = OutputFiles::reserve([a.as_path()]).unwrap();
        let e = outputs.write(&a, |_| Err("disk full".into())).unwrap_err();
        assert!(e.to_string().contains("disk full"));
        drop(outputs);
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0);
        // Both written: both there.
        std::fs::create_dir(dir.join("sub")).unwrap();
        let mut outputs = OutputFiles::reserve([a.as_path(), b.as_path()]).unwrap();
        outputs.write(&a, write_bytes(b"a")).unwrap();
        outputs.write(&b, write_bytes(b"b")).unwrap();
        outputs.commit().unwrap();
        assert_eq!(std::fs::read(&a).unwrap(), b"a");
        assert_eq!(std::fs::read(&b).unwrap(), b"b");
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 2);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn temporary_names_of_long_names_fit_a_file_system() {
        for name in ["a.png".to_string(), "x".repeat(255), "é".repeat(127)] {
            let t = temporary_name(&name);
            assert!(t.len() <= NAME_MAX, "{} bytes", t.len());
            assert!(t.starts_with('.') && t.ends_with(".partial"), "{t}");
        }
        // Two long names cut alike stay apart.
        let long = "y".repeat(255);
        assert_ne!(temporary_name(&long), temporary_name(&long));
    }
}
