//! Run control (docs/running.md): the report of a step that does not converge, going on
//! after a failure, checkpoints and restarts, interruption by a signal, and results that do
//! not depend on the thread count.

mod common;

use common::{code, segfem, stderr, TempDir};
use segfem::run::{run_file_opts, RunError, RunOptions, Summary};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

fn example(name: &str) -> String {
    std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("examples")
            .join(format!("{name}.toml")),
    )
    .unwrap()
}

/// Replace `from` (which must occur exactly once) by `to`.
fn edit(text: &str, from: &str, to: &str) -> String {
    assert_eq!(text.matches(from).count(), 1, "{from}");
    text.replace(from, to)
}

/// The text from the first `[[steps]]` on replaced by `steps`.
fn with_steps(text: &str, steps: &str) -> String {
    let a = text.find("[[steps]]").unwrap();
    format!("{}{steps}", &text[..a])
}

/// The seed beam (elastic concrete, dry joints that open, a held external tendon) with
/// fewer increments and a shorter ultimate step that still opens the joints.
fn seed_beam_short() -> String {
    let full = example("seed-beam-elastic");
    let to_140 = full.split("[[steps]]\nname = \"failure\"").next().unwrap();
    let t = edit(
        to_140,
        "Q = 140.0 }\nincrements = 42",
        "Q = 110.0 }\nincrements = 3",
    );
    edit(
        &t,
        "Q = 56.0 }\nincrements = 8",
        "Q = 56.0 }\nincrements = 2",
    )
}

/// The creep beam (ageing concrete, relaxation of the tendon, time steps, joints), its
/// 10 000-day step shortened to 8 substeps over 1000 days.
fn creep_beam_short() -> String {
    let t = edit(&example("creep-beam"), "to = 10000.0", "to = 1000.0");
    edit(&t, "substeps = 50", "substeps = 8")
}

/// The RC beam (cracking concrete, embedded bars, displacement control) taken to the first
/// cracks in three steps.
fn rc_beam_steps(last_value: f64, last_increments: usize, extra: &str) -> String {
    let control = "control = { point = [1.1, 0.53], component = \"y\"";
    with_steps(
        &example("rc-beam"),
        &format!(
            "[[steps]]\nname = \"s1\"\nkind = \"displacement\"\n{control}, value = -0.0001 }}\nincrements = 2\n\n\
             [[steps]]\nname = \"s2\"\nkind = \"displacement\"\n{control}, value = -0.0002 }}\nincrements = 2\n\n\
             [[steps]]\nname = \"s3\"\nkind = \"displacement\"\n{control}, value = {last_value} }}\nincrements = {last_increments}\noutput = \"increments\"\n{extra}"
        ),
    )
}

fn run(
    dir: &Path,
    model: Option<&Path>,
    out: &str,
    opts: &RunOptions,
    on_inc: &mut dyn FnMut(&segfem::analysis::steps::Snapshot),
) -> Result<Summary, RunError> {
    run_file_opts(model, &dir.join(out), on_inc, opts)
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn summary(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&read(&dir.join("summary.json"))).unwrap()
}

/// The files of `dir` except the checkpoint and summary (timings differ), sorted.
fn output_files(dir: &Path) -> Vec<PathBuf> {
    let mut names: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            let n = p.file_name().unwrap().to_string_lossy();
            !n.starts_with('.') && n != "summary.json" && n != "checkpoint.bin"
        })
        .collect();
    names.sort();
    names
}

/// `a` and `b` hold the same files except the checkpoint and summary (timings differ),
/// byte for byte: none missing, none left over.
fn same_outputs(a: &Path, b: &Path) {
    let names = output_files(a);
    let name = |p: &PathBuf| p.file_name().unwrap().to_owned();
    assert_eq!(
        names.iter().map(name).collect::<Vec<_>>(),
        output_files(b).iter().map(name).collect::<Vec<_>>(),
        "{} and {} hold other files",
        a.display(),
        b.display()
    );
    assert!(names.iter().any(|p| p.ends_with("history.csv")));
    for p in &names {
        let q = b.join(p.file_name().unwrap());
        assert!(
            std::fs::read(p).unwrap() == std::fs::read(&q).unwrap(),
            "{} and {} differ",
            p.display(),
            q.display()
        );
    }
}

/// Stopped after each step k of `stops` in turn and restarted, a run writes exactly the files of an
/// uninterrupted run: history.csv, results.pvd and every .vtu, bit for bit. Exactness is
/// expected because the checkpoint holds every double of the state as its 8 bytes and a
/// restart repeats the same operations in the same order.
fn restart_matches(label: &str, text: &str, stops: &[usize]) {
    let tmp = TempDir::new(label);
    let model = tmp.join("m.toml");
    std::fs::write(&model, text).unwrap();
    let straight = RunOptions::default();
    run(tmp.path(), Some(&model), "straight", &straight, &mut |_| {}).unwrap();
    for &k in stops {
        let out = format!("stop{k}");
        let stop = RunOptions {
            stop_after_step: Some(k),
            ..Default::default()
        };
        let e = run(tmp.path(), Some(&model), &out, &stop, &mut |_| {}).unwrap_err();
        assert_eq!(e.exit_code(), 4, "{e}");
        let s = summary(&tmp.join(&out));
        assert_eq!(s["status"], "stopped");
        assert_eq!(s["resume_step"], k + 1);
        let h = read(&tmp.join(&out).join("history.csv"));
        assert!(
            h.lines()
                .skip(1)
                .all(|l| l.split(',').next().unwrap().parse::<usize>().unwrap() <= k),
            "history goes past step {k}"
        );
        // The restart takes the model file from the checkpoint.
        let again = RunOptions {
            restart: true,
            ..Default::default()
        };
        let s = run(tmp.path(), None, &out, &again, &mut |_| {}).unwrap();
        assert_eq!(s.status, "completed");
        assert_eq!(s.restarted_from_step, Some(k + 1));
        same_outputs(&tmp.join("straight"), &tmp.join(&out));
    }
}

/// A staged model (the viaduct: regions and falsework supports activated and removed by its
/// steps) restarts as well: the checkpoint holds the stage (active parts, the displacements
/// they were born at) and the joints' openings per row. Stopped after step 3 (span 1 creeps)
/// and after step 4 (span 2 placed: step 5 then strikes falsework, whose reactions the
/// restart computes from the restored state).
#[test]
fn restart_of_the_staged_viaduct_is_bit_identical() {
    restart_matches("restart-viaduct", &example("viaduct"), &[3, 4]);
}

/// Every file of `dir` with its bytes.
fn files_of(dir: &Path) -> std::collections::BTreeMap<String, Vec<u8>> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let p = e.unwrap().path();
            (
                p.file_name().unwrap().to_string_lossy().into_owned(),
                std::fs::read(&p).unwrap(),
            )
        })
        .collect()
}

#[test]
fn restart_of_the_seed_beam_is_bit_identical() {
    // After step 2: the tendon stressed in step 1 is rebuilt, the joints open in step 3.
    restart_matches("restart-seed", &seed_beam_short(), &[2]);
}

#[test]
fn restart_of_the_creep_beam_is_bit_identical() {
    // Before and after the 1000-day time step.
    restart_matches("restart-creep", &creep_beam_short(), &[1, 2]);
}

#[test]
fn restart_of_the_rc_beam_is_bit_identical() {
    // Step 3 cracks the concrete from the state saved after step 2.
    restart_matches("restart-rc", &rc_beam_steps(-0.0003, 2, ""), &[2]);
}

/// A signal (here: the flag the handler sets, raised from the progress callback) stops the
/// run after the increment in hand: results so far written, status "interrupted", exit
/// 128 + 2; the restart redoes the interrupted step from the checkpoint of the step before
/// and ends with the uninterrupted results.
#[test]
fn interruption_keeps_results_and_restarts() {
    let tmp = TempDir::new("interrupt");
    let model = tmp.join("m.toml");
    std::fs::write(&model, creep_beam_short()).unwrap();
    run(
        tmp.path(),
        Some(&model),
        "straight",
        &RunOptions::default(),
        &mut |_| {},
    )
    .unwrap();
    let flag = Arc::new(AtomicUsize::new(0));
    let opts = RunOptions {
        signal: Some(flag.clone()),
        ..Default::default()
    };
    let mut on_inc = |s: &segfem::analysis::steps::Snapshot| {
        if s.step == 1 && s.increment == 3 {
            flag.store(2, Ordering::SeqCst);
        }
    };
    let e = run(tmp.path(), Some(&model), "cut", &opts, &mut on_inc).unwrap_err();
    assert_eq!(e.exit_code(), 130, "{e}");
    let msg = e.to_string();
    assert!(
        msg.contains("interrupted by SIGINT at step 2 increment 3"),
        "{msg}"
    );
    assert!(msg.contains("continues with step 2"), "{msg}");
    let out = tmp.join("cut");
    let s = summary(&out);
    assert_eq!(s["status"], "interrupted");
    assert_eq!(s["resume_step"], 2);
    // Step 1 (one increment) and the first three increments of step 2 are kept.
    let rows: Vec<String> = read(&out.join("history.csv"))
        .lines()
        .skip(1)
        .map(|l| l.split(',').take(2).collect::<Vec<_>>().join(","))
        .collect();
    assert_eq!(rows, ["1,1", "2,1", "2,2", "2,3"]);
    let again = RunOptions {
        restart: true,
        ..Default::default()
    };
    // The field files of increment 3 of step 2, written when the signal came, are not those
    // of the restarted run (which writes step 2's at its end only): removed, and said.
    let s = run(tmp.path(), Some(&model), "cut", &again, &mut |_| {}).unwrap();
    assert!(
        s.warnings.iter().any(|w| w.contains("removed")
            && w.contains("field files (.vtu) of the increments the stopped run did")),
        "{:?}",
        s.warnings
    );
    same_outputs(&tmp.join("straight"), &out);
}

/// Interrupted in its first step, a run leaves the checkpoint written before that step,
/// which holds no analysis state (the model's initial one, checkpoint format 7): the restart
/// runs the model from its start and ends with the uninterrupted results, bit for bit.
#[test]
fn restart_from_the_initial_checkpoint_reruns_from_the_start() {
    let tmp = TempDir::new("restart-initial");
    let model = tmp.join("m.toml");
    std::fs::write(&model, rc_beam_steps(-0.0003, 2, "")).unwrap();
    run(
        tmp.path(),
        Some(&model),
        "straight",
        &RunOptions::default(),
        &mut |_| {},
    )
    .unwrap();
    // Raised before the run: it stops after the first increment of step 1 (of 2).
    let opts = RunOptions {
        signal: Some(Arc::new(AtomicUsize::new(2))),
        ..Default::default()
    };
    let e = run(tmp.path(), Some(&model), "cut", &opts, &mut |_| {}).unwrap_err();
    assert_eq!(e.exit_code(), 130, "{e}");
    let out = tmp.join("cut");
    assert_eq!(summary(&out)["resume_step"], 1);
    let (_, cp) = segfem::results::checkpoint::read(&out).unwrap();
    assert_eq!(cp.driver.next_step, 0);
    assert!(cp.system.is_none(), "the initial checkpoint holds no state");
    let again = RunOptions {
        restart: true,
        ..Default::default()
    };
    let s = run(tmp.path(), Some(&model), "cut", &again, &mut |_| {}).unwrap();
    assert_eq!(s.status, "completed");
    assert_eq!(s.restarted_from_step, Some(1));
    same_outputs(&tmp.join("straight"), &out);
}

/// The real thing: SIGINT sent to the `segfem` binary, at a deterministic point. The model
/// file is a named pipe: the binary installs its signal handlers before it reads the
/// model, so once its read end is open (our write end's open returns) the signal is
/// caught, and it is pending before the model text arrives. The run must then do the first
/// increment in hand, write its results and exit 130 with a summary saying where to
/// restart: exactly one history row (step 1 is one increment), status "interrupted",
/// resume at step 2.
#[test]
fn sigint_stops_the_binary_cleanly() {
    use std::io::Write;
    let tmp = TempDir::new("sigint");
    let text = example("creep-beam");
    let fifo = tmp.join("m.toml");
    let mk = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap();
    assert!(mk.success());
    let child = std::process::Command::new(env!("CARGO_BIN_EXE_segfem"))
        .current_dir(tmp.path())
        .args(["run", "m.toml", "-o", "out", "-q", "--threads", "2"])
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // Blocks until the binary opens the pipe to read the model (handlers in place).
    let mut w = std::fs::OpenOptions::new().write(true).open(&fifo).unwrap();
    let k = std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(k.success());
    w.write_all(text.as_bytes()).unwrap();
    // The binary opens the file a second time for the checkpoint's digest: by then the
    // path must be a plain file with the same text (the rename does not touch the pipe
    // it is reading).
    std::fs::write(tmp.join("plain.toml"), &text).unwrap();
    std::fs::rename(tmp.join("plain.toml"), &fifo).unwrap();
    drop(w);
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(130), "{err}");
    assert!(err.contains("interrupted by SIGINT"), "{err}");
    assert!(err.contains("segfem run --restart out"), "{err}");
    let s = summary(&tmp.join("out"));
    assert_eq!(s["status"], "interrupted", "{s}");
    // Step 1 (prestress) is one increment: the run stops after it, with its checkpoint.
    assert_eq!(s["resume_step"], 2, "{s}");
    assert_eq!(
        s["error"],
        "interrupted by SIGINT after step 1; a restart continues with step 2"
    );
    let rows = read(&tmp.join("out/history.csv")).lines().count() - 1;
    assert_eq!(rows, 1, "the increment in hand only");
    assert!(tmp.join("out/checkpoint.bin").is_file());
}

/// A step that fails after all cuts: exit 3, results so far kept (history, fields of the
/// converged increments, the checkpoint of the last finished step), and a report that
/// names the step, increment and level, gives the residual history of the last attempt and
/// the largest out-of-balance forces at real nodes with the elements around them.
#[test]
fn hard_convergence_failure_is_reported_and_results_kept() {
    let tmp = TempDir::new("hardfail");
    std::fs::write(tmp.join("m.toml"), failing_rc_beam()).unwrap();
    let o = segfem(tmp.path(), &["run", "m.toml", "-o", "out", "-q"]);
    assert_eq!(code(&o), 3, "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains("error: m.toml: step 's3' did not converge"),
        "{err}"
    );
    assert!(
        err.contains("largest out-of-balance forces: node "),
        "{err}"
    );
    assert!(
        err.contains("results up to the last converged increment are in out"),
        "{err}"
    );
    let s = summary(&tmp.join("out"));
    assert_eq!(s["status"], "failed");
    let f = &s["failures"][0];
    assert_eq!(f["step"], "s3");
    assert_eq!(f["step_number"], 3);
    assert_eq!(f["cause"], "diverged");
    let inc = f["increment"].as_u64().unwrap() as usize;
    let level = f["level"].as_f64().unwrap();
    assert!(level > 0.0 && level <= 1.0, "{level}");
    // One residual per iteration of the last attempt: max_iterations + 1.
    let hist = f["residual_history"].as_array().unwrap();
    assert_eq!(hist.len(), 3);
    assert_eq!(f["cuts"], 1);
    // Converged increments before the failure are in the history: 2 + 2 + (inc - 1), and
    // nothing of the step after the failed one.
    let h = read(&tmp.join("out/history.csv"));
    assert_eq!(h.lines().count() - 1, 4 + inc - 1);
    assert!(h.lines().skip(1).all(|l| !l.starts_with("4,")));
    // Fields of every converged increment of s3 (output = "increments").
    for i in 1..inc {
        assert!(tmp.join(&format!("out/step003_inc{i:04}.vtu")).is_file());
    }
    // The worst dofs are real nodes, largest first, each inside a reported element.
    let model = segfem::input::load(&tmp.join("m.toml")).unwrap().model;
    let worst = f["worst_dofs"].as_array().unwrap();
    assert!(!worst.is_empty());
    let elements: Vec<usize> = f["elements"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e.as_u64().unwrap() as usize)
        .collect();
    let mut last = f64::INFINITY;
    for w in worst {
        let node = w["node"].as_u64().unwrap() as usize;
        let [x, y] = model.nodes[node - 1];
        // Coordinates as printed (shortest round-trip of a rounded value): 1e-9 m.
        assert!((w["x"].as_f64().unwrap() - x).abs() < 1e-9);
        assert!((w["y"].as_f64().unwrap() - y).abs() < 1e-9);
        let r = w["residual"].as_f64().unwrap().abs();
        assert!(r <= last && r > 0.0);
        last = r;
        assert!(elements
            .iter()
            .any(|&e| model.elements[e - 1].nodes.contains(&(node - 1))));
    }
    assert!(f["negative_pivots"].is_u64());
    // The checkpoint is that of the end of step 2: a restart redoes step 3 (and fails the
    // same way, with the same report).
    let o = segfem(tmp.path(), &["run", "--restart", "out", "-q"]);
    assert_eq!(code(&o), 3, "{}", stderr(&o));
    let s2 = summary(&tmp.join("out"));
    assert_eq!(s2["restarted_from_step"], 3);
    assert_eq!(s2["failures"][0], *f);
    assert_eq!(read(&tmp.join("out/history.csv")), h);
}

/// A fourth step of the RC beam: back to 0.2 mm.
const UNLOAD: &str = "\n[[steps]]\nname = \"unload\"\nkind = \"displacement\"\ncontrol = { point = [1.1, 0.53], component = \"y\", value = -0.0002 }\nincrements = 8\n";

/// The RC beam pushed from 0.2 to 3 mm in three increments in step 3 with two iterations
/// and one cut: the second increment, in which the cracks formed in the first (explicitly,
/// IMPL-EX) open and the bars yield, cannot converge; then the unloading step.
fn failing_rc_beam() -> String {
    rc_beam_steps(-0.003, 3, UNLOAD)
        + "\n[solver]\nforce_tolerance = 1e-4\nmax_iterations = 2\nmax_cuts = 1\n"
}

/// --continue-on-failure: the failed step is reported, the next step runs from the last
/// converged state (here unloading the plate back to 0.2 mm), the run exits 3.
#[test]
fn continue_on_failure_runs_the_next_step() {
    let tmp = TempDir::new("continue");
    std::fs::write(tmp.join("m.toml"), failing_rc_beam()).unwrap();
    let o = segfem(
        tmp.path(),
        &["run", "m.toml", "-o", "out", "-q", "--continue-on-failure"],
    );
    assert_eq!(code(&o), 3, "{}", stderr(&o));
    let err = stderr(&o);
    // The unloading step passes through crack closure under the same tight iteration limit
    // and may fail as well; either way the run must have gone on to it.
    assert!(
        err.contains("did not converge (the run went on): 's3'"),
        "{err}"
    );
    let s = summary(&tmp.join("out"));
    assert_eq!(s["status"], "failed");
    let failures = s["failures"].as_array().unwrap();
    assert_eq!(failures[0]["step"], "s3");
    assert!(failures.len() == 1 || failures[1]["step"] == "unload");
    let h = read(&tmp.join("out/history.csv"));
    let header: Vec<&str> = h.lines().next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|c| c.starts_with(name)).unwrap();
    let (c_step, c_r) = (col("step"), col("R_support"));
    let rows: Vec<Vec<f64>> = h
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    let last_s3 = rows.iter().rev().find(|r| r[c_step] == 3.0).unwrap();
    let unl: Vec<&Vec<f64>> = rows.iter().filter(|r| r[c_step] == 4.0).collect();
    // At least two converged unloading increments (the first ones, far from closure).
    assert!(unl.len() >= 2, "{} unloading rows", unl.len());
    let unl = [unl[0], unl[unl.len() - 1]];
    // Unloading: the support reaction falls, and at 0.2 mm lies below its value at 0.2 mm
    // on the way up (end of s2) now that cracks have opened.
    let end_s2 = rows.iter().rev().find(|r| r[c_step] == 2.0).unwrap();
    assert!(unl[0][c_r] < last_s3[c_r] && unl[1][c_r] < unl[0][c_r]);
    // Compared at 0.2 mm only if the unloading step got there.
    assert!(
        failures.len() == 2 || unl[1][c_r] < end_s2[c_r],
        "{} vs {}",
        unl[1][c_r],
        end_s2[c_r]
    );
    // The time column stays that of the displacement steps.
    assert_eq!(unl[1][col("time")], rows[0][col("time")]);
}

/// history.csv is bit-identical with 1, 2 and 4 worker threads, for a model with joints and
/// a tendon (seed beam) and one with cracking concrete and bars (RC beam): the element
/// loops run in parallel but forces and tangents are summed in element order.
#[test]
fn results_do_not_depend_on_the_thread_count() {
    for (label, text) in [
        ("seed", seed_beam_short()),
        ("rc", rc_beam_steps(-0.0003, 2, "")),
    ] {
        let tmp = TempDir::new(&format!("threads-{label}"));
        let model = tmp.join("m.toml");
        std::fs::write(&model, text).unwrap();
        for n in [1, 2, 4] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .unwrap();
            pool.install(|| {
                run(
                    tmp.path(),
                    Some(&model),
                    &format!("t{n}"),
                    &RunOptions::default(),
                    &mut |_| {},
                )
                .unwrap()
            });
        }
        let h1 = read(&tmp.join("t1/history.csv"));
        assert!(h1.lines().count() > 5);
        for n in [2, 4] {
            assert!(
                read(&tmp.join(&format!("t{n}/history.csv"))) == h1,
                "{label}: {n} threads differ from 1"
            );
        }
    }
}

/// Thread independence where the split solver runs (issue 42): the segmental-decompression
/// example (three Q8 segments, dry joints that open under the bending step) refined to
/// 23,900 equations, above `SPLIT_MIN_EQUATIONS` = 20,000 where the LLᵀ is factorised by
/// halves on two threads. The `segfem` binary with `--threads 1` and `--threads 2`:
/// history.csv and every .vtu bit-identical (docs/running.md: the same bits with any thread
/// count). A reduction whose order followed the threads, or halves joined in the order they
/// finish, would show in the last digits of the history or of the fields.
#[test]
fn results_above_the_split_threshold_do_not_depend_on_the_thread_count() {
    let text = edit(
        &example("segmental-decompression"),
        "nx_per_segment = 8",
        "nx_per_segment = 40",
    );
    let text = edit(&text, "depth = 0.5, rows = 8 }", "depth = 0.5, rows = 32 }");
    let text = edit(&text, "increments = 30", "increments = 10");
    // The system really is factorised by halves (ordered by dissection, with a top-level
    // split), not the whole-matrix way.
    {
        use segfem::linalg::solver::SparseCholesky;
        let model = segfem::input::parse(&text, "m.toml").unwrap().model;
        let sys = segfem::analysis::system::System::new(&model);
        let chol = SparseCholesky::with_ordering(&sys.asm.pattern, sys.ordering.as_deref());
        assert!(chol.unwrap().is_split(), "the split solver is not used");
    }
    let tmp = TempDir::new("threads-split");
    std::fs::write(tmp.join("m.toml"), &text).unwrap();
    for n in ["1", "2"] {
        let o = segfem(
            tmp.path(),
            &[
                "run",
                "m.toml",
                "-o",
                &format!("t{n}"),
                "-q",
                "--threads",
                n,
            ],
        );
        assert_eq!(code(&o), 0, "{n} threads: {}", stderr(&o));
    }
    let eq = summary(&tmp.join("t1"))["size"]["equations"]
        .as_u64()
        .unwrap();
    assert!(
        eq >= 20_000,
        "{eq} equations: below the split solver's threshold"
    );
    let h1 = read(&tmp.join("t1/history.csv"));
    assert!(h1.lines().count() > 10, "{h1}");
    assert!(
        read(&tmp.join("t2/history.csv")) == h1,
        "history.csv differs"
    );
    let mut vtus: Vec<String> = std::fs::read_dir(tmp.join("t1"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|f| f.ends_with(".vtu"))
        .collect();
    vtus.sort();
    assert!(vtus.len() >= 10, "{vtus:?}");
    for f in &vtus {
        let a = std::fs::read(tmp.join("t1").join(f)).unwrap();
        let b = std::fs::read(tmp.join("t2").join(f)).unwrap();
        assert!(a == b, "{f} differs between 1 and 2 threads");
    }
}

/// `--restart` errors: a directory without a checkpoint, and a model whose mesh changed.
#[test]
fn restart_refuses_what_it_cannot_continue() {
    let tmp = TempDir::new("restart-bad");
    std::fs::create_dir_all(tmp.join("empty")).unwrap();
    let o = segfem(tmp.path(), &["run", "--restart", "empty"]);
    assert_eq!(code(&o), 2, "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.starts_with("error: cannot restart: empty/checkpoint.bin: cannot read the checkpoint"),
        "{err}"
    );
    // A run stopped after step 1, then the mesh refined: the saved state no longer fits.
    let text = seed_beam_short();
    std::fs::write(tmp.join("m.toml"), &text).unwrap();
    let o = segfem(
        tmp.path(),
        &["run", "m.toml", "-o", "out", "-q", "--stop-after-step", "1"],
    );
    assert_eq!(code(&o), 4, "{}", stderr(&o));
    assert!(stderr(&o).contains("`segfem run --restart out` continues with step 2"));
    std::fs::write(
        tmp.join("m.toml"),
        edit(&text, "nx_per_segment = 6", "nx_per_segment = 12"),
    )
    .unwrap();
    let before = files_of(&tmp.join("out"));
    let o = segfem(tmp.path(), &["run", "--restart", "out", "-q"]);
    assert_eq!(code(&o), 2, "{}", stderr(&o));
    let err = stderr(&o);
    assert!(err.contains("cannot restart"), "{err}");
    assert!(
        err.contains("the model changed since the checkpoint was written"),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
    // Refused, the restart changed nothing: the directory still continues as it did.
    assert!(
        files_of(&tmp.join("out")) == before,
        "a refused restart rewrote the output directory"
    );
    // A damaged checkpoint.
    std::fs::write(tmp.join("out/checkpoint.bin"), b"segfem?").unwrap();
    let o = segfem(tmp.path(), &["run", "--restart", "out", "-q"]);
    assert_eq!(code(&o), 2, "{}", stderr(&o));
    assert!(
        stderr(&o).contains("not a segfem checkpoint"),
        "{}",
        stderr(&o)
    );
}

/// Runs `text` (written as `name`.toml in `tmp`) and returns its summary and history (the
/// `iterations` column left out).
fn run_history(tmp: &TempDir, name: &str, text: &str) -> (serde_json::Value, Vec<Vec<f64>>) {
    std::fs::write(tmp.join(&format!("{name}.toml")), text).unwrap();
    let o = segfem(tmp.path(), &["run", "-q", &format!("{name}.toml")]);
    assert_eq!(code(&o), 0, "{name}: {}", stderr(&o));
    let h = read(&tmp.join(name).join("history.csv"));
    // Every column but the iteration counts.
    let keep: Vec<bool> = h
        .lines()
        .next()
        .unwrap()
        .split(',')
        .map(|c| c != "iterations")
        .collect();
    let rows = h
        .lines()
        .skip(1)
        .map(|l| {
            l.split(',')
                .zip(&keep)
                .filter(|(_, &k)| k)
                .map(|(v, _)| v.parse().unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    (summary(&tmp.join(name)), rows)
}

/// Largest difference between the histories `a` and `b` (same shape), per column relative to
/// the column's largest value.
fn history_difference(a: &[Vec<f64>], b: &[Vec<f64>]) -> f64 {
    assert_eq!(a.len(), b.len(), "same increments");
    let mut worst = 0.0_f64;
    for j in 0..a[0].len() {
        let scale = a.iter().map(|r| r[j].abs()).fold(0.0, f64::max);
        if scale.is_nan() || scale == 0.0 {
            continue;
        }
        for (x, y) in a.iter().zip(b) {
            worst = worst.max((x[j] - y[j]).abs() / scale);
        }
    }
    worst
}

/// `[solver] predictor = "extrapolated"` starts each increment of a load or displacement
/// step from the linear extrapolation of the path (docs/theory.md, "Newton predictor").
#[test]
fn extrapolated_predictor_converges_to_the_same_path_in_fewer_iterations() {
    let tmp = TempDir::new("predictor");
    let iterations = |s: &serde_json::Value| s["timings"]["iterations"].as_u64().unwrap();
    // Segmental beam: joints that open and close, load steps. Both predictors converge to
    // the force tolerance (1e-6); the states agree to 1e-5 of each column's largest value
    // (the tolerance × 10 for the conditioning of the joint stiffness).
    let seg = example("segmental-decompression");
    let ext = format!("{seg}\n[solver]\npredictor = \"extrapolated\"\n");
    let (s_last, h_last) = run_history(&tmp, "seg_last", &seg);
    let (s_ext, h_ext) = run_history(&tmp, "seg_ext", &ext);
    let d = history_difference(&h_last, &h_ext);
    assert!(d < 1e-5, "segmental histories differ by {d:e}");
    assert!(
        iterations(&s_ext) < iterations(&s_last),
        "segmental: {} iterations extrapolated, {} from the last state",
        iterations(&s_ext),
        iterations(&s_last)
    );
    // RC beam to failure under displacement control (cracking, yielding): the converged path
    // is one of those within the 1e-4 force tolerance; the peak control force agrees within
    // 0.5 % (the spread of force-tolerance paths on a cracking model).
    let rc = example("rc-beam");
    let rc_ext = edit(
        &rc,
        "max_cuts = 8",
        "max_cuts = 8\npredictor = \"extrapolated\"",
    );
    let (s_last, h_last) = run_history(&tmp, "rc_last", &rc);
    let (s_ext, h_ext) = run_history(&tmp, "rc_ext", &rc_ext);
    let peak = |h: &[Vec<f64>]| {
        h.iter()
            .map(|r| r.last().unwrap().abs())
            .fold(0.0, f64::max)
    };
    let (pe, pl) = (peak(&h_ext), peak(&h_last));
    assert!(
        ((pe - pl) / pl).abs() < 5e-3,
        "RC peak control force {pe} extrapolated, {pl} from the last state"
    );
    assert!(
        iterations(&s_ext) < iterations(&s_last),
        "RC beam: {} iterations extrapolated, {} from the last state",
        iterations(&s_ext),
        iterations(&s_last)
    );
}

/// One run per output directory: while a run writes into `out` (held stopped by SIGSTOP once
/// its lock is in place), a second run into `out` is refused (status 2) with a message
/// naming the directory and the first run's process, and touches none of its files; the
/// first then completes. A lock left by a process that no longer runs (killed) is stale and
/// taken over.
#[test]
fn a_second_run_into_a_busy_directory_is_refused() {
    let tmp = TempDir::new("busy");
    std::fs::write(tmp.join("v.toml"), example("viaduct")).unwrap();
    let mut first = std::process::Command::new(env!("CARGO_BIN_EXE_segfem"))
        .args(["run", "v.toml", "-o", "out", "-q"])
        .current_dir(tmp.path())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let lock = tmp.join("out/.segfem-lock");
    // Wait for the lock (its content written), then hold the first run where it is.
    let mut held = String::new();
    for _ in 0..200_000 {
        held = std::fs::read_to_string(&lock).unwrap_or_default();
        if held.contains("model=") || first.try_wait().unwrap().is_some() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_micros(100));
    }
    let pid = first.id().to_string();
    let kill = |sig: &str| {
        std::process::Command::new("kill")
            .args([sig, &pid])
            .status()
            .unwrap()
    };
    assert!(kill("-STOP").success());
    assert!(
        held.contains(&format!("pid={pid}")),
        "the first run's lock: {held:?}"
    );
    let o = segfem(tmp.path(), &["run", "v.toml", "-o", "out", "-q"]);
    let err = stderr(&o);
    assert!(kill("-CONT").success());
    assert_eq!(code(&o), 2, "{err}");
    assert!(
        err.starts_with(&format!(
            "error: out: another segfem run (process {pid}, model "
        )),
        "{err}"
    );
    assert!(err.contains("is writing into this directory"), "{err}");
    let status = first.wait().unwrap();
    assert!(status.success(), "the first run failed");
    assert!(!lock.exists(), "the lock outlived its run");
    let s = summary(&tmp.join("out"));
    assert_eq!(s["status"], "completed");
    // The first run's files only: every .vtu results.pvd lists is there, and no other.
    let pvd = read(&tmp.join("out/results.pvd"));
    let listed: std::collections::BTreeSet<String> = pvd
        .split("file=\"")
        .skip(1)
        .map(|r| r.split('"').next().unwrap().to_string())
        .collect();
    let on_disk: std::collections::BTreeSet<String> = std::fs::read_dir(tmp.join("out"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".vtu"))
        .collect();
    assert_eq!(listed, on_disk);

    // A stale lock: the process that wrote it has ended (a finished child's id).
    let mut dead = std::process::Command::new("true").spawn().unwrap();
    dead.wait().unwrap();
    std::fs::write(
        &lock,
        format!("pid={}\nstart=1\nmodel=gone.toml\n", dead.id()),
    )
    .unwrap();
    let o = segfem(tmp.path(), &["run", "v.toml", "-o", "out", "-q"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    assert!(!lock.exists());
}

/// A load step of ten increments to Q = 100 ends at Q = 100 exactly: 10 × 0.1 sums to
/// 0.9999999999999999, and the last increment used to end there (Q = 99.999999999999986
/// in history.csv and in a sweep's table). The same for a time step's clock.
#[test]
fn the_last_increment_lands_on_the_step_factors_exactly() {
    let tmp = TempDir::new("exact-end");
    let text = with_steps(
        &example("cantilever"),
        "[[monitors]]\nname = \"Q\"\nkind = \"load_factor\"\ncase = \"tip\"\n\n\
         [[steps]]\nname = \"a\"\nkind = \"load\"\nloads = { tip = 0.3 }\nincrements = 10\n\n\
         [[steps]]\nname = \"b\"\nkind = \"load\"\nloads = { tip = 100.0 }\nincrements = 10\n",
    );
    std::fs::write(tmp.join("m.toml"), text).unwrap();
    let s = run(
        tmp.path(),
        Some(&tmp.join("m.toml")),
        "out",
        &RunOptions::default(),
        &mut |_| {},
    )
    .unwrap();
    let h = read(&tmp.join("out/history.csv"));
    let head: Vec<&str> = h.lines().next().unwrap().split(',').collect();
    let col = |name: &str| head.iter().position(|c| c.starts_with(name)).unwrap();
    let (f, q) = (col("factor:tip"), col("Q ["));
    // The rows that end steps a (10) and b (20).
    for (row, want) in [(10, 0.3), (20, 100.0)] {
        let cells: Vec<&str> = h.lines().nth(row).unwrap().split(',').collect();
        assert_eq!(
            cells[f].parse::<f64>().unwrap(),
            want,
            "row {row}: {}",
            cells[f]
        );
        assert_eq!(
            cells[q].parse::<f64>().unwrap(),
            want,
            "row {row}: {}",
            cells[q]
        );
    }
    assert_eq!(
        s.final_monitors.iter().find(|(n, _)| n == "Q").unwrap().1,
        100.0
    );
}
