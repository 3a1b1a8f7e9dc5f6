//! Output files written atomically, the one writer every output of raypack goes
//! through (images, sidecars, generated scenes, hit tables): the bytes go to a
//! temporary file in the target's directory, flushed to disk and renamed over
//! the target only once complete, so a failed or interrupted run never leaves a
//! half-written file.
//!
//! `tempfile` does the temporary file: a unique name, created exclusively, and
//! removed when dropped uncommitted, on every exit path. It is created with
//! mode `0o666` less the umask, like any file a program writes (tempfile's
//! default, `0o600`, would make the image private after the rename).
//!
//! A run stopped by a signal (SIGINT, SIGTERM, SIGHUP: Ctrl-C, `timeout`, a
//! closed terminal) runs no destructors, so every temporary in flight is also
//! listed in `IN_FLIGHT`, and [`remove_temporaries_on_signals`] starts a
//! thread that removes them when such a signal arrives and then exits with
//! `128 + signal`, as the shell reports a process killed by it. (SIGKILL
//! cannot be caught; nothing can clean up after it.)

use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use tempfile::NamedTempFile;

/// The temporary files being written, for the signal thread to remove.
static IN_FLIGHT: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// The list of temporaries, even if a thread panicked while holding it.
fn in_flight() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    IN_FLIGHT.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// Remove every temporary in flight when SIGINT, SIGTERM or SIGHUP arrives,
/// then exit with `128 + signal`. Call once, early in `main`.
pub fn remove_temporaries_on_signals() -> io::Result<()> {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    let mut signals = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP])?;
    std::thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            if let Some(signal) = signals.forever().next() {
                for temp in in_flight().drain(..) {
                    let _ = std::fs::remove_file(temp);
                }
                std::process::exit(128 + signal);
            }
        })?;
    Ok(())
}

/// An output file that cannot be written, naming the path and the reason.
/// 48 bytes plus the strings.
#[derive(Debug, thiserror::Error)]
#[error("cannot write {}: {reason}", path.display())]
pub struct OutputError {
    /// The target path.
    pub path: PathBuf,
    /// What went wrong.
    pub reason: String,
}

impl OutputError {
    /// The error of writing `path`, for `reason`.
    pub fn new(path: &Path, reason: impl ToString) -> Self {
        Self {
            path: path.to_path_buf(),
            reason: reason.to_string(),
        }
    }
}

/// A file being written: create it before the work (so an unwritable path fails
/// at once), [`commit`](AtomicFile::commit) the bytes after. Dropped
/// uncommitted, it leaves nothing behind. 80 bytes plus the paths.
#[derive(Debug)]
pub struct AtomicFile {
    path: PathBuf,
    /// The temporary until it is committed.
    temp: Option<NamedTempFile>,
    /// Its path, as listed in [`IN_FLIGHT`].
    temp_path: PathBuf,
}

impl AtomicFile {
    /// Reserve `path`: its directory must exist and be writable, and `path`
    /// itself must not be a directory.
    pub fn create(path: &Path) -> Result<Self, OutputError> {
        if path.is_dir() {
            return Err(OutputError::new(path, "it is a directory"));
        }
        let name = path
            .file_name()
            .ok_or_else(|| OutputError::new(path, "the path has no file name"))?;
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        if !dir.is_dir() {
            return Err(OutputError::new(
                path,
                format!("directory {} does not exist", dir.display()),
            ));
        }
        let mut builder = tempfile::Builder::new();
        #[cfg(unix)]
        builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
        let temp = builder
            .prefix(&format!(".{}.", name.to_string_lossy()))
            .suffix(".tmp")
            .tempfile_in(dir)
            .map_err(|e| OutputError::new(path, e))?;
        let temp_path = temp.path().to_path_buf();
        in_flight().push(temp_path.clone());
        Ok(Self {
            path: path.to_path_buf(),
            temp: Some(temp),
            temp_path,
        })
    }

    /// Write `bytes`, flush them to disk and rename the file onto the target.
    pub fn commit(self, bytes: &[u8]) -> Result<(), OutputError> {
        self.commit_with(|out| out.write_all(bytes))
    }

    /// Stream the contents through `write` (buffered), flush them to disk and
    /// rename the file onto the target; on any error the temporary is removed.
    pub fn commit_with(
        mut self,
        write: impl FnOnce(&mut dyn Write) -> io::Result<()>,
    ) -> Result<(), OutputError> {
        let path = self.path.clone();
        let mut temp = self.temp.take().expect("an AtomicFile is committed once");
        let mut out = BufWriter::new(temp.as_file_mut());
        write(&mut out)
            .and_then(|()| out.flush())
            .map_err(|e| OutputError::new(&path, e))?;
        drop(out);
        temp.as_file()
            .sync_all()
            .map_err(|e| OutputError::new(&path, e))?;
        temp.persist(&path)
            .map_err(|e| OutputError::new(&path, e.error))?;
        Ok(())
    }
}

impl Drop for AtomicFile {
    /// Off the in-flight list: committed (renamed) or removed by `tempfile`.
    fn drop(&mut self) {
        in_flight().retain(|p| *p != self.temp_path);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("raypack-atomic-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn committed_file_appears_whole_and_uncommitted_leaves_nothing() {
        let dir = scratch("commit");
        let target = dir.join("a.png");
        let f = AtomicFile::create(&target).unwrap();
        // Until commit the target does not exist.
        assert!(!target.exists());
        f.commit(b"hello").unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"hello");
        // A second file replaces the first whole; a streamed one too.
        AtomicFile::create(&target).unwrap().commit(b"again").unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"again");
        AtomicFile::create(&target)
            .unwrap()
            .commit_with(|out| out.write_all(b"streamed"))
            .unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"streamed");
        // The same mode as any file the program writes, not private like a temporary one.
        let plain = dir.join("plain");
        std::fs::write(&plain, b"x").unwrap();
        let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions();
        assert_eq!(mode(&target), mode(&plain));
        std::fs::remove_file(&plain).unwrap();

        let g = AtomicFile::create(&dir.join("b.png")).unwrap();
        drop(g);
        let names: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, vec![std::ffi::OsString::from("a.png")]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn unwritable_paths_are_clear_errors_naming_the_path() {
        let dir = scratch("errors");
        let missing = dir.join("no/such/dir/out.png");
        let e = AtomicFile::create(&missing).unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.contains(&missing.display().to_string()) && msg.contains("does not exist"),
            "{msg}"
        );
        let e = AtomicFile::create(&dir).unwrap_err();
        assert!(e.to_string().contains("is a directory"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
