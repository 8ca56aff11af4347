//! Whole-or-nothing file output: write to a temporary file beside the target, then rename.

use std::io::Write;
use std::path::Path;

/// Write `bytes` to `path` atomically (a reader sees the old file or the new one, never a part).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    write_atomic_with_tail(path, bytes, || Ok(Vec::new()), || Ok(()))
}

/// As [`write_atomic`], with `tail()` appended after `bytes` (it may be computed while they
/// are written, e.g. a checksum on another thread), and the file put in place only once
/// `ready` has returned (e.g. other files it refers to are written); an error of `tail` or
/// `ready` leaves the old file.
pub fn write_atomic_with_tail(
    path: &Path,
    bytes: &[u8],
    tail: impl FnOnce() -> std::io::Result<Vec<u8>>,
    ready: impl FnOnce() -> std::io::Result<()>,
) -> std::io::Result<()> {
    let dir = path.parent().unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_else(|| "out".into());
    let tmp = dir.join(format!(".{name}.tmp{}", std::process::id()));
    // No fsync: the rename alone gives readers the whole-or-nothing view (on this kind of
    // VM an fsync costs ~10 ms a file, a third of a small run's time); durability across
    // a power cut is left to the file system, as for any other program output.
    let written = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.write_all(&tail()?)
    })();
    written
        .and_then(|()| ready())
        .and_then(|()| std::fs::rename(&tmp, path))
        .inspect_err(|_| {
            let _ = std::fs::remove_file(&tmp);
        })
}
