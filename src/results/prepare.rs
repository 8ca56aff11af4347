//! The memory of the next large .vtu prepared on an idle core: its document buffer and the
//! page cache of the temporary file it will be written to, faulted in while the numeric
//! factorisation runs (sequential: the other core is idle then; see
//! [`crate::analysis::steps::Observer::idle_work`]).
//!
//! Why: on a virtual machine whose balloon reports free memory to its host (the project's
//! 2-vCPU machine, docs/performance.md) every page the kernel hands out for the first time
//! in a while costs a host fault at its first touch. Writing the 70 MB .vtu of a 5e5-dof
//! run into fresh page cache took 0.2–0.35 s there, against 0.02–0.05 s into pages already
//! allocated; the document buffer's faults another 0.05 s. Both now happen beside the
//! factorisation: the file is filled with zeros of about the document's length, and the
//! document then overwrites them from its start (the file is cut or extended to the exact
//! length) before it is renamed into place, as every field file is
//! ([`super::atomic::write_atomic`]).

use crate::analysis::steps::IdleWork;
use std::fs::File;
use std::io::{Seek, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

/// Documents from this length on are prepared [bytes] (a plane model of ≈ 1e5 dofs):
/// below, the faults cost a few milliseconds.
pub const PREPARE_MIN_BYTES: usize = 16 << 20;

/// Bytes faulted in between two looks at the stop flag.
const CHUNK: usize = 1 << 20;

/// A temporary file in the output directory, already holding `len` bytes (zeros); removed
/// when dropped unless it was renamed into place.
pub struct TempFile {
    /// Its path (a hidden name of this process).
    pub path: PathBuf,
    file: Option<File>,
}

impl TempFile {
    /// Write `bytes` over the file from its start, cut it to their length, and rename it to
    /// `path`; on an error the temporary file is removed and `path` left as it was.
    pub fn write_as(mut self, path: &Path, bytes: &[u8]) -> std::io::Result<()> {
        let mut file = self.file.take().expect("the file is open until written");
        file.rewind()?;
        file.write_all(bytes)?;
        file.set_len(bytes.len() as u64)?;
        drop(file);
        std::fs::rename(&self.path, path)?;
        self.path = PathBuf::new();
        Ok(())
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        if !self.path.as_os_str().is_empty() {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

/// What the work leaves: the buffer (empty, its capacity faulted in) and the file, if it
/// could be made.
pub struct Ready {
    /// Document buffer.
    pub buffer: Vec<u8>,
    /// Temporary file with the document's length of zeros.
    pub file: Option<TempFile>,
}

/// Preparation under way, shared by the work and the recorder.
pub struct Prepared {
    stop: AtomicBool,
    ready: Mutex<Option<Ready>>,
}

impl Prepared {
    /// The work for a document of about `len` bytes to be written into `dir`, and the
    /// handle to take its result with.
    pub fn start(dir: &Path, len: usize) -> (Arc<Prepared>, IdleWork) {
        let p = Arc::new(Prepared {
            stop: AtomicBool::new(false),
            ready: Mutex::new(None),
        });
        let shared = p.clone();
        let path = dir.join(format!(".fields.tmp{}", std::process::id()));
        let work = Box::new(move || {
            // Held for the whole work: [`Prepared::take`] waits for at most one chunk.
            let mut ready = shared.ready.lock().unwrap_or_else(|e| e.into_inner());
            let stopped = || shared.stop.load(Ordering::Relaxed);
            if stopped() {
                return;
            }
            let mut buffer = Vec::with_capacity(len);
            while buffer.len() < len && !stopped() {
                let k = CHUNK.min(len - buffer.len());
                buffer.resize(buffer.len() + k, 0);
            }
            buffer.clear();
            let file = (|| {
                let mut file = File::create(&path)?;
                let zeros = vec![0u8; CHUNK];
                let mut n = 0;
                while n < len && !stopped() {
                    let k = CHUNK.min(len - n);
                    file.write_all(&zeros[..k])?;
                    n += k;
                }
                Ok::<_, std::io::Error>(file)
            })();
            let file = match file {
                Ok(file) => Some(TempFile {
                    path: path.clone(),
                    file: Some(file),
                }),
                Err(_) => {
                    // Only a preparation: the document is written the ordinary way.
                    let _ = std::fs::remove_file(&path);
                    None
                }
            };
            *ready = Some(Ready { buffer, file });
        });
        (p, work)
    }

    /// Stop the work (if it runs: after its current chunk; if it has not started: for good)
    /// and take what it prepared, if anything.
    pub fn take(&self) -> Option<Ready> {
        self.stop.store(true, Ordering::Relaxed);
        self.ready.lock().unwrap_or_else(|e| e.into_inner()).take()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Prepared work, run, leaves a file of the length asked and a buffer of that
    /// capacity; writing a document through it gives exactly the document, under the
    /// final name, and no temporary file.
    #[test]
    fn prepared_file_becomes_the_document() {
        let dir = std::env::temp_dir().join(format!("segfem-prepare-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for (len, doc_len) in [(3 * CHUNK + 5, 1000), (10, 3 * CHUNK + 7)] {
            let (p, work) = Prepared::start(&dir, len);
            work();
            let ready = p.take().expect("the work ran");
            assert!(ready.buffer.is_empty() && ready.buffer.capacity() >= len);
            let file = ready.file.expect("a file");
            assert_eq!(std::fs::metadata(&file.path).unwrap().len(), len as u64);
            let doc: Vec<u8> = (0..doc_len).map(|i| (i % 251) as u8 + 1).collect();
            let target = dir.join("a.vtu");
            file.write_as(&target, &doc).unwrap();
            assert_eq!(std::fs::read(&target).unwrap(), doc);
            let names: Vec<_> = std::fs::read_dir(&dir).unwrap().flatten().collect();
            assert_eq!(names.len(), 1, "only the document is left");
            std::fs::remove_file(&target).unwrap();
        }
        std::fs::remove_dir(&dir).unwrap();
    }

    /// Work taken before it starts never runs: nothing prepared, no file made.
    #[test]
    fn work_called_off_before_it_starts_does_nothing() {
        let dir = std::env::temp_dir().join(format!("segfem-prepare0-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let (p, work) = Prepared::start(&dir, 5 * CHUNK);
        assert!(p.take().is_none());
        work();
        assert!(p.take().is_none());
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0);
        std::fs::remove_dir(&dir).unwrap();
    }
}
