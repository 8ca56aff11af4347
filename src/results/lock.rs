//! One run per output directory: a run holds `.segfem-lock` in its output directory while it
//! writes there, so that a second run into the same directory is refused instead of mixing
//! its files with the first one's (a results.pvd listing the other run's files, orphans).
//!
//! The file is created with `create_new` (atomic: of two runs starting at once, one gets
//! it) and holds the process id, the process's start time (clock ticks since boot, Linux
//! `/proc/PID/stat` field 22) and the model file. A lock left by a process that died
//! without removing it (SIGKILL, power loss) is stale: no process with that id, or one that
//! started at another time (the id reused). A stale lock is taken over; the lock of a live
//! run is refused with a message naming the directory and that run.

use std::io::Write;
use std::path::{Path, PathBuf};

/// Name of the lock file in the output directory.
pub const FILE: &str = ".segfem-lock";

/// The lock of an output directory, removed when dropped.
#[derive(Debug)]
pub struct DirLock {
    path: PathBuf,
}

impl Drop for DirLock {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
    }
}

/// Start time of process `pid` [clock ticks since boot] (Linux), if it runs.
fn start_time(pid: u32) -> Option<u64> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    // The command name (field 2) is in parentheses and may hold spaces: count from the
    // last ')'. Field 22 is then the 20th after it.
    let rest = &stat[stat.rfind(')')? + 1..];
    rest.split_whitespace().nth(19)?.parse().ok()
}

/// What a lock file says: process id, start time, model file.
struct Holder {
    pid: u32,
    start: Option<u64>,
    model: String,
}

impl Holder {
    fn parse(text: &str) -> Option<Holder> {
        let field = |key: &str| {
            text.lines()
                .find_map(|l| l.strip_prefix(key).map(|v| v.trim().to_string()))
        };
        Some(Holder {
            pid: field("pid=")?.parse().ok()?,
            start: field("start=").and_then(|s| s.parse().ok()),
            model: field("model=").unwrap_or_default(),
        })
    }

    /// Whether the process that wrote the lock still runs. Without `/proc` (not Linux) a
    /// lock is taken as live: refusing is safe, the message says how to clear it.
    fn alive(&self) -> bool {
        if !Path::new("/proc/self/stat").exists() {
            return true;
        }
        match (start_time(self.pid), self.start) {
            (None, _) => false,
            (Some(now), Some(then)) => now == then,
            (Some(_), None) => true,
        }
    }
}

/// Take the lock of output directory `dir` (which must exist) for a run of `model`. Errors
/// are complete sentences naming the directory (and the other run when one holds it).
pub fn acquire(dir: &Path, model: &Path) -> Result<DirLock, String> {
    let path = dir.join(FILE);
    let pid = std::process::id();
    let text = format!(
        "pid={pid}\nstart={}\nmodel={}\n",
        start_time(pid).map_or(String::new(), |s| s.to_string()),
        model.display()
    );
    // Two attempts: the second after a stale lock was removed.
    for _ in 0..2 {
        match std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&path)
        {
            Ok(mut f) => {
                f.write_all(text.as_bytes())
                    .map_err(|e| format!("{}: cannot write the lock file: {e}", path.display()))?;
                return Ok(DirLock { path });
            }
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                // A lock being written has no content yet: read as held by an unknown run.
                let held = std::fs::read_to_string(&path).unwrap_or_default();
                match Holder::parse(&held) {
                    Some(h) if !h.alive() => {
                        let _ = std::fs::remove_file(&path);
                    }
                    Some(h) => {
                        return Err(format!(
                            "{}: another segfem run (process {}, model {}) is writing into this directory; wait for it to end or give another output directory (if no such run is in progress, remove {})",
                            dir.display(),
                            h.pid,
                            if h.model.is_empty() { "?" } else { &h.model },
                            path.display()
                        ))
                    }
                    None => {
                        return Err(format!(
                            "{}: another segfem run is starting in this directory ({} exists); wait for it or give another output directory (if no run is in progress, remove the file)",
                            dir.display(),
                            path.display()
                        ))
                    }
                }
            }
            Err(e) => {
                return Err(format!(
                    "{}: cannot create the lock file: {e}",
                    path.display()
                ))
            }
        }
    }
    Err(format!(
        "{}: another segfem run took this directory at the same moment; give another output directory",
        dir.display()
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn this_process_is_alive_and_a_wrong_start_time_is_not() {
        let pid = std::process::id();
        let start = start_time(pid);
        assert!(start.is_some(), "Linux /proc expected");
        let me = Holder {
            pid,
            start,
            model: String::new(),
        };
        assert!(me.alive());
        let reused = Holder {
            pid,
            start: start.map(|s| s + 1),
            model: String::new(),
        };
        assert!(!reused.alive());
    }
}
