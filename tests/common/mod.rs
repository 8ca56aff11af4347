//! Helpers shared by the end-to-end tests: a self-cleaning temporary directory and a runner
//! for the built `segfem` binary.

#![allow(dead_code)]

pub mod mc90;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::atomic::{AtomicUsize, Ordering};

/// A fresh directory under the system temp dir, removed (with its contents) on drop.
pub struct TempDir {
    path: PathBuf,
}

impl TempDir {
    /// A new empty directory whose name contains `label`, the process id and a counter, so
    /// that tests running in parallel (threads or processes) never share one.
    pub fn new(label: &str) -> Self {
        static COUNTER: AtomicUsize = AtomicUsize::new(0);
        let n = COUNTER.fetch_add(1, Ordering::SeqCst);
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.subsec_nanos())
            .unwrap_or(0);
        let path = std::env::temp_dir().join(format!(
            "segfem-test-{label}-{}-{n}-{nanos}",
            std::process::id()
        ));
        std::fs::create_dir_all(&path).expect("create temp dir");
        Self { path }
    }

    /// The directory.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// A path inside the directory.
    pub fn join(&self, name: &str) -> PathBuf {
        self.path.join(name)
    }

    /// Names of the entries of the directory, sorted.
    pub fn entries(&self) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(&self.path)
            .expect("read temp dir")
            .map(|e| {
                e.expect("dir entry")
                    .file_name()
                    .to_string_lossy()
                    .into_owned()
            })
            .collect();
        v.sort();
        v
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.path);
    }
}

/// Run the built binary with `args` in the working directory `cwd`.
pub fn segfem(cwd: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_segfem"))
        .args(args)
        .current_dir(cwd)
        .output()
        .expect("spawn segfem")
}

/// Stdout as text.
pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Stderr as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Exit status code (panics if killed by a signal, which is itself a failure).
pub fn code(o: &Output) -> i32 {
    o.status.code().unwrap_or_else(|| {
        panic!(
            "segfem was killed by a signal; stderr:\n{}",
            String::from_utf8_lossy(&o.stderr)
        )
    })
}

/// One 0.1 m Q4 (thickness 0.1 m) of C30 concrete, held at x = 0 (and at the origin in y),
/// its right edge driven in x to each `value` in turn in `n` increments.
pub fn block(stages: &[(f64, usize)], extra: &str) -> String {
    let mut steps = String::new();
    for (i, (value, n)) in stages.iter().enumerate() {
        steps.push_str(&format!(
            r#"
[[steps]]
name = "s{i}"
kind = "displacement"
control = {{ line = [[0.1, 0.0], [0.1, 0.1]], component = "x", value = {value} }}
increments = {n}
"#
        ));
    }
    format!(
        r#"
[[materials]]
name = "c30"
kind = "concrete"
fcm = 38e6
nu = 0.2
{extra}

[[regions]]
name = "r"
material = "c30"
thickness = 0.1

[mesh]
type = "explicit"
nodes = [[0.0, 0.0], [0.1, 0.0], [0.1, 0.1], [0.0, 0.1]]
blocks = [{{ region = "r", element = "Q4", elements = [[1, 2, 3, 4]] }}]

[[supports]]
name = "left"
line = [[0.0, 0.0], [0.0, 0.1]]
ux = 0.0

[[supports]]
name = "pin"
node = 1
uy = 0.0
{steps}"#
    )
}
