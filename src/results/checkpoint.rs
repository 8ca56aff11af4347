//! The checkpoint file of a run (`checkpoint.bin` in the output directory): the analysis
//! state after the last finished step, rewritten atomically at every step end, from which
//! `segfem run --restart DIR` continues.
//!
//! Encoding: postcard (serde, compact binary). Floats are stored as their 8 bytes, so a
//! restored state is bit-identical to the saved one, NaN and infinities included (JSON
//! would turn NaN into null and needs care to round-trip every double). A small header
//! (magic text, format version, model file and its digest) is read first, so that an
//! older or foreign file gives a clear message rather than a decoding error. The file ends
//! with the 8-byte FNV-1a digest of everything before it: a damaged file (a flipped bit, a
//! truncated copy) is refused instead of restarting from a silently different state.

use super::atomic::write_atomic_with_tail;
use super::recorder::{FieldWrite, RecorderState};
use crate::analysis::failure::FailureReport;
use crate::analysis::state::{DriverState, SystemState, SystemStateRef};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// File name of the checkpoint in the output directory.
pub const FILE: &str = "checkpoint.bin";
const MAGIC: &str = "segfem checkpoint";
/// Format version; bumped whenever a saved structure changes (the test `layout_has_a_version`
/// fails until it is). 2: trailing checksum; 3: state saved by element family; 4: creep state
/// of creeping concrete points; 5: tendon spans keep the shared steel state `SteelState`; 6: concrete points without the
/// IMPL-EX kink side; 7: the system state is optional (absent in the checkpoint written
/// before the first step, which is the model's initial state); 8: no Gauss outputs of linear
/// elastic points (a restart recomputes them from the displacements), and concrete points
/// keep the softening cut-off's history (`cutoff_max`, `cutoff_max_old`); 9: the
/// construction stage reached (staged models restart) and the recorder's joint openings; 10:
/// the one-way supports' contact points and statuses, and the recorder's lifted points per
/// row; 11: the concrete points' plastic strain before the committed one (IMPL-EX in
/// compression); 12: the crack-axis directions' compressive plastic strains before the
/// committed ones (IMPL-EX compression of cracked points).
const VERSION: u32 = 12;
/// Bytes of the trailing checksum.
const CHECKSUM_BYTES: usize = 8;

/// Every format version with the digest of its encoding of the layout sample
/// (`analysis::state::layout::sample`), oldest first. A change of the saved state types
/// changes the digest: append a line with the next version and the new digest, and set
/// [`VERSION`] to it.
#[cfg(test)]
const LAYOUTS: &[(u32, u64)] = &[
    (3, 16_113_229_074_358_229_730),
    (4, 14_334_971_633_857_522_506),
    (5, 10_812_821_786_394_591_690),
    (6, 17_771_896_231_766_552_362),
    (7, 2_879_888_328_409_885_521),
    (8, 13_423_329_791_089_162_975),
    (9, 7_976_921_271_131_270_574),
    (10, 5_454_227_443_183_593_876),
    (11, 3_136_055_901_800_596_340),
    (12, 4_395_502_844_849_288_628),
];

#[derive(Serialize, Deserialize)]
struct Header {
    magic: String,
    version: u32,
    /// Model file the run read (absolute where it could be resolved).
    model_file: String,
    /// FNV-1a digest of the model file's bytes.
    model_digest: u64,
}

#[derive(Serialize)]
struct BodyRef<'a> {
    driver: &'a DriverState,
    failures: &'a [FailureReport],
    recorder: &'a RecorderState,
    system: Option<SystemStateRef<'a>>,
}

/// A checkpoint read back.
#[derive(Deserialize)]
pub struct Checkpoint {
    /// The driver's state (next step, load factors, clock, counters).
    pub driver: DriverState,
    /// Steps that failed so far (continue on failure).
    pub failures: Vec<FailureReport>,
    /// History rows and field-file list so far.
    pub recorder: RecorderState,
    /// The committed analysis state; `None` in the checkpoint written before the first
    /// step, whose state is the one the model starts from (at 5e5 dofs it spares the 9 MB
    /// of displacements and material points that a restart rebuilds from the model).
    pub system: Option<SystemState>,
}

/// What a checkpoint says about the model it belongs to.
pub struct Origin {
    /// Model file.
    pub model_file: String,
    /// Digest of its bytes when the run started.
    pub model_digest: u64,
}

/// 64-bit FNV-1a digest of `bytes` (a change detector, not a cryptographic hash).
pub fn digest(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// Write the checkpoint into `dir` atomically (`system`: `None` for the initial state of the
/// model, see [`Checkpoint::system`]).
pub fn write(
    dir: &Path,
    origin: &Origin,
    driver: &DriverState,
    failures: &[FailureReport],
    recorder: &RecorderState,
    system: Option<SystemStateRef>,
) -> std::io::Result<()> {
    start(dir, origin, driver, failures, recorder, system, None)?.wait()
}

/// A checkpoint encoded and being digested and written on a thread of its own.
pub struct Pending(std::thread::JoinHandle<std::io::Result<()>>);

impl Pending {
    /// Wait until the file is in place; the write's error, if any.
    pub fn wait(self) -> std::io::Result<()> {
        self.0
            .join()
            .unwrap_or_else(|_| Err(std::io::Error::other("the checkpoint writer panicked")))
    }
}

/// Size of the last checkpoint [bytes], to encode the next one into a buffer of that size.
static LAST_LEN: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

/// Encode the checkpoint now (the state may change once this returns) and digest and write
/// it into `dir` atomically on another thread: at 5e5 dofs the digest and the write of the
/// 57 MB of format 7 took 0.2 s (9 MB since format 8), which then overlap the analysis. [`Pending::wait`] before the next
/// checkpoint and before the run ends. `after`: field files being written that the
/// recorder's state lists; the checkpoint is put in place only once they are (their write
/// error is then the checkpoint's).
pub fn start(
    dir: &Path,
    origin: &Origin,
    driver: &DriverState,
    failures: &[FailureReport],
    recorder: &RecorderState,
    system: Option<SystemStateRef>,
    after: Option<FieldWrite>,
) -> std::io::Result<Pending> {
    use std::sync::atomic::Ordering;
    let header = Header {
        magic: MAGIC.into(),
        version: VERSION,
        model_file: origin.model_file.clone(),
        model_digest: origin.model_digest,
    };
    // Header and body into one buffer (encoding them apart and joining them copied the
    // whole state twice more).
    let buffer = Vec::with_capacity(LAST_LEN.load(Ordering::Relaxed));
    let bytes = postcard::to_extend(&header, buffer).map_err(std::io::Error::other)?;
    let body = BodyRef {
        driver,
        failures,
        recorder,
        system,
    };
    let bytes = postcard::to_extend(&body, bytes).map_err(std::io::Error::other)?;
    LAST_LEN.store(bytes.len() + CHECKSUM_BYTES, Ordering::Relaxed);
    let path = dir.join(FILE);
    Ok(Pending(std::thread::spawn(move || {
        std::thread::scope(|s| {
            // The checksum (byte-serial, ~80 ms at 57 MB) on a thread of its own while the
            // bytes are written, appended after them.
            let sum = s.spawn(|| digest(&bytes));
            let tail = || {
                sum.join()
                    .map(|d| d.to_le_bytes().to_vec())
                    .map_err(|_| std::io::Error::other("the checkpoint digest panicked"))
            };
            // Written beside the field files, renamed into place after them.
            write_atomic_with_tail(&path, &bytes, tail, || after.map_or(Ok(()), |w| w.wait()))
        })
    })))
}

/// Read the checkpoint of `dir`. Errors are complete sentences naming the file.
pub fn read(dir: &Path) -> Result<(Origin, Checkpoint), String> {
    let path = dir.join(FILE);
    let bytes = std::fs::read(&path).map_err(|e| {
        format!(
            "{}: cannot read the checkpoint ({e}); --restart needs the output directory of a run started by this version of segfem",
            path.display()
        )
    })?;
    let bad = |what: &str| format!("{}: not a segfem checkpoint ({what})", path.display());
    let (header, _) =
        postcard::take_from_bytes::<Header>(&bytes).map_err(|_| bad("unreadable header"))?;
    if header.magic != MAGIC {
        return Err(bad("wrong magic text"));
    }
    // The checksum before the version: a flipped bit may sit in the version field itself.
    let intact = bytes.len() >= CHECKSUM_BYTES && {
        let (data, sum) = bytes.split_at(bytes.len() - CHECKSUM_BYTES);
        digest(data).to_le_bytes() == sum
    };
    if !intact && header.version == VERSION {
        return Err(format!(
            "{}: the checkpoint is damaged (its checksum does not match its contents: the file was altered or truncated after it was written); rerun from the start",
            path.display()
        ));
    }
    if header.version != VERSION {
        return Err(format!(
            "{}: checkpoint format {} but this segfem reads format {VERSION}; rerun from the start",
            path.display(),
            header.version
        ));
    }
    let body = &bytes[..bytes.len() - CHECKSUM_BYTES];
    let (_, rest) =
        postcard::take_from_bytes::<Header>(body).map_err(|_| bad("unreadable header"))?;
    let cp: Checkpoint = postcard::from_bytes(rest).map_err(|e| {
        format!(
            "{}: the checkpoint is damaged ({e}); rerun from the start",
            path.display()
        )
    })?;
    Ok((
        Origin {
            model_file: header.model_file,
            model_digest: header.model_digest,
        },
        cp,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::state::layout;

    /// The saved state's layout is the one recorded for the current format version: a change
    /// of a saved type without a new version (and a new line in `LAYOUTS`) fails here.
    #[test]
    fn layout_has_a_version() {
        // As the body holds it (an optional state).
        let bytes = postcard::to_stdvec(&Some(layout::as_ref(&layout::sample()))).unwrap();
        let now = digest(&bytes);
        let &(last, recorded) = LAYOUTS.last().unwrap();
        assert!(
            LAYOUTS
                .windows(2)
                .all(|w| w[0].0 < w[1].0 && w[0].1 != w[1].1),
            "LAYOUTS: versions must increase and each must have its own layout"
        );
        assert_eq!(last, VERSION, "the last line of LAYOUTS must be VERSION");
        assert_eq!(
            now, recorded,
            "the checkpoint layout changed (digest {now}): bump VERSION and append ({}, {now}) to LAYOUTS",
            VERSION + 1
        );
    }
}
