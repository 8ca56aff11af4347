"""segfem from Python against the command line: the same files bit for bit, the same
messages, a clean stop on Ctrl-C."""

import json
import os
import signal
import subprocess
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import segfem


def cli_run(cli: str, model: Path, out: Path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [cli, "run", str(model), "-o", str(out), "-q"], capture_output=True, text=True
    )


def without_timings(summary: dict) -> dict:
    """summary.json less what differs between two runs of one model: wall times, the
    phase timings and peak memory (machine load), the output directory in messages."""
    s = dict(summary)
    for k in ("wall_s", "input_s", "peak_memory_bytes"):
        s.pop(k)
    t = dict(s.pop("timings"))
    s["counts"] = (t["increments"], t["iterations"], t["limit_points"], t["solver"]["factorisations"])
    return s


def test_history_equals_cli_bit_for_bit(cli, seed_beam, tmp_path):
    # The seed beam to failure (arc length, joint opening, tendon yield): the same library
    # called from Python must write the same bytes as the command line.
    assert cli_run(cli, seed_beam, tmp_path / "cli").returncode == 0
    model = segfem.load(seed_beam)
    result = model.run(tmp_path / "py")
    assert result.status == "completed"
    cli_hist = (tmp_path / "cli" / "history.csv").read_bytes()
    assert (tmp_path / "py" / "history.csv").read_bytes() == cli_hist
    cli_sum = json.loads((tmp_path / "cli" / "summary.json").read_text())
    assert without_timings(result.summary) == without_timings(cli_sum)
    # The same model given as Python data (written to TOML and read back) gives the same.
    again = segfem.Model.from_dict(model.to_dict()).run(tmp_path / "dict")
    assert (tmp_path / "dict" / "history.csv").read_bytes() == cli_hist
    assert again.ultimate == cli_sum["ultimate"]


def test_history_frame_is_the_file(cli, seed_beam, tmp_path):
    result = segfem.load(seed_beam).run(tmp_path / "py")
    df = result.history
    lines = (tmp_path / "py" / "history.csv").read_text().splitlines()
    header = lines[0].split(",")
    # Units come from the header's brackets: "tendon_stress [Pa]" → tendon_stress: Pa.
    assert df.attrs["units"]["tendon_stress"] == "Pa"
    assert df.attrs["units"]["midspan_uy"] == "m"
    assert [c.split(" [")[0] for c in header] == list(df.columns)
    assert len(df) == len(lines) - 1
    # Every number reads back exactly (round trip of the shortest representation).
    for i in (0, len(df) // 2, len(df) - 1):
        cells = lines[i + 1].split(",")
        for j, c in enumerate(df.columns):
            v = float(cells[j])
            assert (np.isnan(v) and np.isnan(df[c].iloc[i])) or df[c].iloc[i] == v
    assert result.final["Q"] == df["Q"].iloc[-1]


def test_fields_hold_the_monitored_displacement(seed_beam, tmp_path):
    # The midspan monitor (a node at x = 3.6 m, y = 0) and the .vtu displacement there are
    # the same committed state: equal exactly at each output increment.
    result = segfem.load(seed_beam).run(tmp_path / "py")
    hist = result.history
    assert len(result.fields) == len(segfem.load(seed_beam).steps)
    for f in result.fields:
        g = f.continuum
        i = np.flatnonzero((np.abs(g.points[:, 0] - 3.6) < 1e-9) & (g.points[:, 1] == 0.0))
        assert len(i) == 1
        row = hist[(hist["step"] == f.step) & (hist["increment"] == f.increment)]
        assert f.point_data["displacement"][i[0], 1] == row["midspan_uy"].iloc[0]
    assert result.fields[-1].lines is not None


@pytest.mark.parametrize("change", [("thickness = 0.1", "thickness = -0.1"), ("nu = 0.3", "nu = 0.3\nfoo = 1")])
def test_bad_model_raises_the_cli_message(cli, cantilever, tmp_path, change):
    p = tmp_path / "bad.toml"
    p.write_text(cantilever.read_text().replace(*change))
    proc = cli_run(cli, p, tmp_path / "out")
    assert proc.returncode == 2
    with pytest.raises(segfem.InputError) as e:
        segfem.load(p)
    assert proc.stderr.splitlines()[0] == f"error: {e.value}"
    assert e.value.exit_code == 2 and e.value.file == str(p)
    # The same model as data names the label given, with the same problem.
    data = segfem.load(cantilever).to_dict()
    if change[0].startswith("thickness"):
        data["regions"][0]["thickness"] = -0.1
    else:
        data["materials"][0]["foo"] = 1
    with pytest.raises(segfem.InputError) as d:
        segfem.Model.from_dict(data, name="bad.toml")
    assert d.value.problem == e.value.problem
    assert d.value.key == e.value.key


def test_ctrl_c_stops_cleanly_and_restart_completes(seed_beam, tmp_path):
    full = segfem.load(seed_beam).run(tmp_path / "full")
    seen = []

    def progress(p):
        seen.append((p["step"], p["increment"]))
        if p["step"] == 3 and p["increment"] == 5:
            # A real SIGINT, as Ctrl-C sends: Python raises KeyboardInterrupt here, and
            # the run stops after this increment.
            os.kill(os.getpid(), signal.SIGINT)

    with pytest.raises(segfem.Interrupted) as e:
        segfem.load(seed_beam).run(tmp_path / "cut", progress=progress)
    assert isinstance(e.value, KeyboardInterrupt)
    r = e.value.result
    assert r.status == "interrupted" and r.exit_code == 130
    assert "interrupted by SIGINT at step 3 increment 5" in str(e.value)
    # Results so far are written: the history up to the increment it stopped at.
    assert len(r.history) == len(seen)
    full_lines = (tmp_path / "full" / "history.csv").read_text().splitlines()
    cut_lines = (tmp_path / "cut" / "history.csv").read_text().splitlines()
    assert cut_lines == full_lines[: len(cut_lines)]
    # The restart goes on from the last step end and ends as the uninterrupted run.
    done = segfem.restart(tmp_path / "cut")
    assert done.status == "completed"
    assert (tmp_path / "cut" / "history.csv").read_text().splitlines() == full_lines
    assert done.ultimate == full.ultimate


def test_progress_exception_stops_the_run(cantilever, seed_beam, tmp_path):
    class Stop(Exception):
        pass

    def progress(p):
        raise Stop(p["increment"])

    with pytest.raises(Stop) as e:
        segfem.load(seed_beam).run(tmp_path / "o", progress=progress)
    # Recorded as the exception it was, not as a Ctrl-C.
    r = e.value.result
    assert r.status == "stopped" and r.exit_code == 4
    assert "the progress callback raised Stop: 1" in r.summary["error"]
    assert "SIGINT" not in r.summary["error"] and "SIGINT" not in (r.error or "")
    assert len(r.history) == 1


def test_open_of_a_directory_without_results_raises(tmp_path):
    with pytest.raises(FileNotFoundError, match="no summary.json"):
        segfem.Result.open("/nonexistent")
    with pytest.raises(FileNotFoundError):
        segfem.Result.open(tmp_path)


def test_a_truncated_vtu_is_refused(seed_beam, tmp_path):
    r = segfem.load(seed_beam).run(tmp_path / "o")
    f = r.fields[-1].file
    text = f.read_bytes()
    cut = tmp_path / "cut.vtu"
    # Cut after the cells: points and cells complete, every data array lost.
    cut.write_bytes(text[: text.index(b"</Cells>") + len(b"</Cells>")])
    with pytest.raises(OSError, match="truncated"):
        segfem.Grid.read(cut)
    assert len(segfem.Grid.read(f).point_data) > 0


def test_run_releases_the_gil(seed_beam, tmp_path):
    # A Python thread keeps counting while the run is in progress (no progress callback:
    # the run itself never takes the GIL but to check for signals).
    count = [0]
    stop = threading.Event()

    def spin():
        while not stop.is_set():
            count[0] += 1
            time.sleep(0.001)

    t = threading.Thread(target=spin)
    t.start()
    t0 = time.perf_counter()
    segfem.load(seed_beam).run(tmp_path / "o")
    elapsed = time.perf_counter() - t0
    stop.set()
    t.join()
    # At 1 ms per tick, a thread starved of the GIL would tick a few times at most; allow
    # for a loaded machine (a tenth of the possible ticks).
    assert count[0] > 0.1 * elapsed / 0.001


def test_temporary_output_and_check(cantilever):
    r = segfem.load(cantilever).run()
    assert r.out_dir.exists() and r.check() is r
    # Closed form: the tip deflection of the 4 m cantilever (Timoshenko, E = 200 GPa,
    # nu = 0.3, 0.1 × 0.5 m, P = 10 kN): PL³/3EI + PL/(κGA), κ = 5/6; the Q8 mesh is
    # within 1 % (shear-strain distribution of plane stress versus κ).
    E, nu, b, h, L, P = 200e9, 0.3, 0.1, 0.5, 4.0, 10e3
    I, A, G = b * h**3 / 12, b * h, E / (2 * (1 + nu))
    exact = P * L**3 / (3 * E * I) + P * L / (5 / 6 * G * A)
    assert abs(-r.final["tip_uy"] - exact) < 0.01 * exact
    d = r.out_dir
    del r
    import gc

    gc.collect()
    assert not d.exists()


def test_sigint_from_outside_during_the_solve(seed_beam, tmp_path):
    # Ctrl-C while the solver runs (no Python code running): another thread sends SIGINT
    # once step 3 has begun; the run stops at a later increment of step 3 or 4.
    started = threading.Event()

    def progress(p):
        if p["step"] == 3:
            started.set()

    def interrupt():
        started.wait(30)
        os.kill(os.getpid(), signal.SIGINT)

    t = threading.Thread(target=interrupt)
    t.start()
    with pytest.raises(segfem.Interrupted) as e:
        segfem.load(seed_beam).run(tmp_path / "o", progress=progress)
    t.join()
    r = e.value.result
    assert r.status == "interrupted"
    assert r.history["step"].iloc[-1] >= 3
    assert r.summary["resume_step"] in (3, 4)


def test_run_without_fields_gives_the_same_history(cli, seed_beam, tmp_path):
    # fields=False (segfem run --no-fields): no .vtu or results.pvd, and the history and the
    # summary's answers bit for bit those of the run that writes its fields.
    assert cli_run(cli, seed_beam, tmp_path / "cli").returncode == 0
    result = segfem.load(seed_beam).run(tmp_path / "py", fields=False)
    assert result.status == "completed"
    out = tmp_path / "py"
    assert (out / "history.csv").read_bytes() == (tmp_path / "cli" / "history.csv").read_bytes()
    assert not list(out.glob("*.vtu")) and not (out / "results.pvd").exists()
    cli_sum = json.loads((tmp_path / "cli" / "summary.json").read_text())
    assert without_timings(result.summary) == without_timings(cli_sum)
