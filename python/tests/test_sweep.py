"""Sweeps: planning (grid, Latin hypercube, Monte Carlo), the same table locally and on a
Dask LocalCluster, resume."""

import json
import re
import os
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import segfem
from segfem.sweep import TIMING_COLUMNS, Sweep, SweepError


def cantilever_sweep(cantilever: Path, method: str = "latin_hypercube", samples: int = 20) -> dict:
    return {
        "model": str(cantilever),
        "method": method,
        "samples": samples,
        "seed": 2026,
        "monitors": ["tip_uy", "wall_Ry"],
        "parameters": {
            "E": {"path": "materials.steel.E", "distribution": "lognormal", "mean": 200e9, "cov": 0.05},
            "t": {"path": "regions.web.thickness", "distribution": "uniform", "low": 0.08, "high": 0.12},
            "G": {"expression": "E / (2 * (1 + 0.3))"},
        },
    }


def linear_checks(table: pd.DataFrame) -> None:
    # Linear elastic, nu fixed: the tip deflection scales exactly as 1/(E t), and the wall
    # reaction is the applied shear 20 kN/m × 0.5 m whatever E and t. Tolerances: the
    # linear solve's round-off (relative 1e-9).
    k = table["tip_uy"] * table["E"] * table["t"]
    assert np.allclose(k, k.iloc[0], rtol=1e-9, atol=0)
    assert np.allclose(table["wall_Ry"], 1e4, rtol=1e-9)
    assert (table["status"] == "completed").all()


def test_latin_hypercube_strata(cantilever):
    s = Sweep.from_dict(cantilever_sweep(cantilever, samples=20))
    cases = s.cases
    assert len(cases) == 20
    # Each of the 20 equal-probability strata of t (uniform) holds exactly one sample.
    strata = np.floor((cases["t"] - 0.08) / 0.04 * 20).astype(int)
    assert sorted(strata) == list(range(20))
    # The expression column follows its inputs.
    assert np.allclose(cases["G"], cases["E"] / 2.6, rtol=1e-15)
    # Reproducible from the seed; a different seed, a different sample.
    assert Sweep.from_dict(cantilever_sweep(cantilever)).cases.equals(cases)
    other = cantilever_sweep(cantilever)
    other["seed"] = 1
    assert not Sweep.from_dict(other).cases.equals(cases)


def test_monte_carlo_moments(cantilever):
    # 4000 lognormal samples of mean 200e9, cov 0.05: the sample mean within 4 standard
    # errors (0.05 × 200e9 / sqrt(4000) ≈ 0.16e9) of the mean given.
    s = Sweep.from_dict(cantilever_sweep(cantilever, method="monte_carlo", samples=4000))
    e = s.cases["E"]
    assert abs(e.mean() - 200e9) < 4 * 0.05 * 200e9 / np.sqrt(4000)
    assert abs(e.std() / e.mean() - 0.05) < 0.005


def test_grid_is_the_product(cantilever, tmp_path):
    spec = {
        "model": str(cantilever),
        "method": "grid",
        "parameters": {
            "E": {"path": "materials.steel.E", "values": [150e9, 200e9]},
            "t": {"path": "regions.web.thickness", "values": [0.05, 0.1, 0.2]},
        },
    }
    table = Sweep.from_dict(spec).run(tmp_path / "grid", workers=1)
    assert list(zip(table["E"], table["t"])) == [(e, t) for e in (150e9, 200e9) for t in (0.05, 0.1, 0.2)]
    linear_checks(table)
    assert (tmp_path / "grid" / "results.csv").exists()
    assert pd.read_parquet(tmp_path / "grid" / "results.parquet").equals(table)


def test_dask_equals_local_and_resume(cantilever, tmp_path):
    from dask.distributed import Client, LocalCluster

    spec = cantilever_sweep(cantilever)
    local = Sweep.from_dict(spec).run(tmp_path / "local", workers=2)
    assert len(local) == 20
    linear_checks(local)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        with Client(cluster) as client:
            dask = Sweep.from_dict(spec).run(tmp_path / "dask", client=client)
    same = [c for c in local.columns if c not in TIMING_COLUMNS]
    pd.testing.assert_frame_equal(local[same], dask[same])
    # The tables on disk hold the same.
    csv = pd.read_csv(tmp_path / "dask" / "results.csv")
    assert np.array_equal(csv["tip_uy"].to_numpy(), local["tip_uy"].to_numpy())

    # Resume: remove three finished cases; a second run redoes those three only, and
    # leaves the other records untouched.
    cases = tmp_path / "local" / "cases"
    for c in (3, 11, 17):
        (cases / f"{c:05d}.json").unlink()
    before = {p.name: p.stat().st_mtime_ns for p in cases.glob("*.json")}
    ran = []
    again = Sweep.from_dict(spec).run(tmp_path / "local", workers=2, progress=lambda d, n, rec: ran.append(rec["case"]))
    assert sorted(ran) == [3, 11, 17]
    assert {p.name: p.stat().st_mtime_ns for p in cases.glob("*.json") if p.name in before} == before
    pd.testing.assert_frame_equal(again[same], local[same])
    # A changed sweep (another seed: other parameter values) reruns every case.
    spec["seed"] = 7
    ran.clear()
    Sweep.from_dict(spec).run(tmp_path / "local", workers=2, progress=lambda d, n, rec: ran.append(rec["case"]))
    assert sorted(ran) == list(range(20))


def test_case_directories_keep_summary(cantilever, tmp_path):
    table = Sweep.from_dict(cantilever_sweep(cantilever, samples=2)).run(tmp_path / "s", workers=1)
    d = tmp_path / "s" / "cases" / "00000"
    assert sorted(p.name for p in d.iterdir()) == ["cantilever.toml", "history.csv", "summary.json"]
    r = segfem.Result.open(d)
    assert r.final["tip_uy"] == table["tip_uy"][0]


def test_bad_sweeps_name_the_key(cantilever, tmp_path):
    spec = cantilever_sweep(cantilever)
    spec["parameters"]["E"]["distribution"] = "weibul"
    with pytest.raises(SweepError, match=r"parameters.E.distribution: 'weibul' is not one of"):
        Sweep.from_dict(spec)
    spec = cantilever_sweep(cantilever)
    spec["parameters"]["E"]["path"] = "materials.concrete.E"
    with pytest.raises(SweepError, match=r"parameters.E.path: materials.concrete.E: 'materials.concrete': no item named 'concrete'"):
        Sweep.from_dict(spec)
    spec = cantilever_sweep(cantilever)
    spec["monitors"] = ["nope"]
    with pytest.raises(SweepError, match="the model has no monitor 'nope'"):
        Sweep.from_dict(spec)
    # A key the model refuses fails once, with the model's message, before any case runs.
    spec = cantilever_sweep(cantilever)
    spec["parameters"]["E"]["path"] = "materials.steel.EE"
    with pytest.raises(SweepError, match="unknown field `EE`"):
        Sweep.from_dict(spec).run(tmp_path / "bad", workers=1)
    assert not list((tmp_path / "bad" / "cases").glob("*.json"))


def test_sweep_file_and_command(cantilever, tmp_path):
    f = tmp_path / "grid.toml"
    f.write_text(
        f'model = "{cantilever.name}"\nmethod = "grid"\nmonitors = ["tip_uy"]\n'
        "[parameters.t]\npath = \"regions.web.thickness\"\nvalues = [0.1, 0.2]\n"
    )
    from segfem.sweep import main

    assert main([str(f), "-q", "--workers", "1"]) == 0
    table = pd.read_csv(tmp_path / "grid" / "results.csv")
    assert list(table["t"]) == [0.1, 0.2]
    # Half the thickness, twice the deflection (linear); round-off tolerance.
    assert np.isclose(table["tip_uy"][0], 2 * table["tip_uy"][1], rtol=1e-9)


def test_an_int_parameter_stays_an_int_beside_a_float(cantilever, tmp_path):
    # mesh.nx takes a whole number; beside a float parameter it used to reach the model as
    # 16.0 (a table row has one dtype) and every case failed. Exact values: the tip
    # deflection of the linear cantilever changes with the mesh but scales as 1/E exactly
    # within one mesh (round-off 1e-9).
    spec = {
        "model": str(cantilever),
        "method": "grid",
        "monitors": ["tip_uy"],
        "parameters": {
            "nx": {"path": "mesh.nx", "values": [8, 16]},
            "E": {"path": "materials.steel.E", "values": [100e9, 200e9]},
        },
    }
    table = Sweep.from_dict(spec).run(tmp_path / "ints", workers=1)
    assert (table["status"] == "completed").all(), table["error"].tolist()
    assert table["nx"].tolist() == [8, 8, 16, 16]
    assert all(type(v) is int for v in Sweep.from_dict(spec).tasks(tmp_path)[0]["values"].values() if v == 8)
    assert pd.api.types.is_integer_dtype(table["nx"])
    for nx in (8, 16):
        t = table[table["nx"] == nx]
        assert np.isclose(t["tip_uy"].iloc[0], 2 * t["tip_uy"].iloc[1], rtol=1e-9)


@pytest.mark.parametrize("name", ["tip_uy", "status", "step", "time [d]", "iterations"])
def test_parameter_names_that_collide_are_refused(cantilever, name):
    spec = cantilever_sweep(cantilever)
    spec["parameters"][name] = {"path": "regions.web.thickness", "value": 0.1}
    with pytest.raises(SweepError, match=re.escape(f"parameters.{name}: the name of a")):
        Sweep.from_dict(spec)


def test_a_monitor_named_like_a_history_column_is_refused(cantilever):
    data = segfem.load(cantilever).to_dict()
    data["monitors"][0]["name"] = "step"
    with pytest.raises(segfem.InputError, match="'step' is a column history.csv already has"):
        segfem.Model.from_dict(data, name="m.toml")


def test_killed_driver_leaves_no_worker_running(tmp_path):
    # A sweep of slow cases (the viaduct, about a second each) in two worker processes; the
    # driver is killed with SIGKILL once the workers run, and the workers must end on their
    # own (they watch their parent). Waits are bounded generously; no timing is asserted.
    import signal
    import subprocess
    import sys
    import time

    from conftest import EXAMPLES

    model = tmp_path / "viaduct.toml"
    model.write_text((EXAMPLES / "viaduct.toml").read_text())
    sweep = tmp_path / "s.toml"
    sweep.write_text(
        'model = "viaduct.toml"\nmethod = "grid"\nkeep = "none"\n'
        "[parameters.rho]\npath = \"materials.concrete.density\"\nvalues = " + str([2500.0 + i for i in range(40)]) + "\n"
    )
    driver = subprocess.Popen(
        [sys.executable, "-m", "segfem.sweep", str(sweep), "-q", "--workers", "2"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )

    def children(pid: int) -> list:
        out = []
        for d in Path("/proc").iterdir():
            if d.name.isdigit():
                try:
                    stat = (d / "stat").read_text()
                except OSError:
                    continue
                if int(stat[stat.rfind(")") + 2 :].split()[1]) == pid:
                    out.append(int(d.name))
        return out

    workers = []
    deadline = time.monotonic() + 120
    # The workers have started once a case record is written (each ran a case).
    while time.monotonic() < deadline and not list((tmp_path / "s" / "cases").glob("*.json")):
        time.sleep(0.05)
    workers = children(driver.pid)
    assert workers, "no worker processes seen"
    os.kill(driver.pid, signal.SIGKILL)
    driver.wait()
    deadline = time.monotonic() + 60
    alive = workers
    while alive and time.monotonic() < deadline:
        time.sleep(0.1)
        alive = [w for w in workers if Path(f"/proc/{w}").exists() and "Z" not in (Path(f"/proc/{w}/stat").read_text().split(")")[1][:3])]
    for w in alive:
        os.kill(w, signal.SIGKILL)
    assert not alive, f"workers {alive} still run after the driver was killed"
