//! Atomic file writing: write a temporary file beside the target, then rename it over.

use std::fs::{File, OpenOptions};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Distinguishes temporary files made by one process.
static COUNTER: AtomicU64 = AtomicU64::new(0);

/// Writes the file at `path` atomically: `write` fills a buffered temporary file in the same
/// directory (named `.<file name>.<pid>.<n>.tmp`), which is flushed, synced and then renamed
/// onto `path`. Readers therefore see either the old file or the complete new one, never a
/// partial write; if `write` or any step fails, the temporary file is removed, `path` is left
/// untouched and the error is returned.
///
/// Meant for every file coseg writes (meshes, outputs, caches). Errors are plain
/// [`std::io::Error`]s; callers add the file name. To report a non-I/O error from `write`, wrap
/// it with [`std::io::Error::other`].
///
/// ```
/// use std::io::Write;
/// let dir = std::env::temp_dir().join(format!("coseg-doc-atomic-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// let path = dir.join("hello.txt");
/// coseg::mesh::write_atomic(&path, |w| writeln!(w, "hello")).unwrap();
/// assert_eq!(std::fs::read_to_string(&path).unwrap(), "hello\n");
/// // A failing writer leaves the previous content in place.
/// let err = coseg::mesh::write_atomic(&path, |w| {
///     write!(w, "partial")?;
///     Err(std::io::Error::other("stop"))
/// });
/// assert!(err.is_err());
/// assert_eq!(std::fs::read_to_string(&path).unwrap(), "hello\n");
/// # std::fs::remove_dir_all(&dir).unwrap();
/// ```
pub fn write_atomic<F>(path: impl AsRef<Path>, write: F) -> std::io::Result<()>
where
    F: FnOnce(&mut BufWriter<File>) -> std::io::Result<()>,
{
    let path = path.as_ref();
    let file_name = path.file_name().ok_or_else(|| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "the path names no file (it ends in `..` or is empty)",
        )
    })?;
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let (tmp, file) = loop {
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let mut name = std::ffi::OsString::from(".");
        name.push(file_name);
        name.push(format!(".{}.{n}.tmp", std::process::id()));
        let tmp = dir.join(name);
        match OpenOptions::new().write(true).create_new(true).open(&tmp) {
            Ok(f) => break (tmp, f),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(e),
        }
    };
    let result = (|| {
        let mut w = BufWriter::new(file);
        write(&mut w)?;
        w.flush()?;
        let file = w.into_inner().map_err(|e| e.into_error())?;
        file.sync_all()?;
        drop(file);
        std::fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}
