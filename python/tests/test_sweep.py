"""Sweeps: planning (grid, Latin hypercube, Monte Carlo), the same table locally and on a
Dask LocalCluster, resume."""

import json
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
