"""Parameter sweeps: one base model, parameters at dotted key paths, every case run and one
table gathered (Parquet and CSV). docs/sweeps.md describes the sweep file.

The cases are planned here, deterministically from the description (a grid, or a Latin
hypercube or Monte Carlo sample from a seeded generator), and run by an executor: the
machine's cores (processes, the default) or a Dask cluster (``client=`` a
``dask.distributed.Client``, or ``scheduler=`` its address). Both run the same function on
the same cases, so the tables are equal but for the timing columns. Each finished case is
written to ``OUT/cases/NNNNN.json`` atomically; a sweep started again over the same
``OUT`` skips the cases already there (resume).
"""

from __future__ import annotations

import argparse
import ast
import hashlib
import itertools
import json
import math
import os
import shutil
import socket
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from statistics import NormalDist
from typing import Any, Callable, Dict, Iterable, List, Mapping, Optional, Sequence, Union

import numpy as np
import pandas as pd

from . import _segfem as _native
from .errors import InputError, SegfemError
from .model import Model, get_path

PathLike = Union[str, "os.PathLike[str]"]

METHODS = ("grid", "monte_carlo", "latin_hypercube")
DISTRIBUTIONS = ("uniform", "normal", "lognormal", "triangular", "gumbel")
KEEP = ("all", "summary", "none")
REDUCTIONS = ("final", "max", "min")
#: Columns that differ between two runs of the same sweep (timing, where it ran).
TIMING_COLUMNS = ("wall_s", "elapsed_s", "worker")
#: Columns of the results table besides the parameters and monitors, and the history's own
#: columns: no parameter may take one of these names (it would be overwritten in the table).
RESERVED_COLUMNS = (
    "case", "status", "exit_code", "ultimate_mode", "ultimate_factor", "peak_factor",
    "increments", "iterations", "wall_s", "elapsed_s", "worker", "error",
    "step", "increment", "time", "time [d]",
)


class SweepError(SegfemError, ValueError):
    """A sweep description that cannot be run (names the key and what is wrong)."""

    exit_code = 2


# -- parameters --------------------------------------------------------------------------

_MATH = {k: getattr(math, k) for k in ("sqrt", "exp", "log", "log10", "sin", "cos", "tan", "pi")}
_MATH.update(abs=abs, min=min, max=max)
_ALLOWED = (
    ast.Expression, ast.BinOp, ast.UnaryOp, ast.Constant, ast.Name, ast.Load, ast.Call,
    ast.Add, ast.Sub, ast.Mult, ast.Div, ast.Pow, ast.USub, ast.UAdd, ast.Mod, ast.FloorDiv,
)


@dataclass
class Parameter:
    """One swept quantity: its column ``name``, the model key ``path`` it sets (empty: a
    column only, used by expressions), and one of
    ``values`` (a grid axis), ``value`` (a constant), ``distribution`` with its
    parameters (sampled), or ``expression`` (computed from the other parameters)."""

    name: str
    path: str
    values: Optional[List[Any]] = None
    value: Any = None
    distribution: Optional[str] = None
    params: Dict[str, float] = field(default_factory=dict)
    expression: Optional[str] = None

    @property
    def kind(self) -> str:
        if self.values is not None:
            return "grid"
        if self.distribution is not None:
            return "random"
        if self.expression is not None:
            return "expression"
        return "constant"

    def ppf(self, u: np.ndarray) -> np.ndarray:
        """The distribution's quantile function at probabilities ``u`` ∈ (0, 1)."""
        p = self.params
        d = self.distribution
        if d == "uniform":
            return p["low"] + u * (p["high"] - p["low"])
        if d == "triangular":
            a, c, b = p["low"], p["mode"], p["high"]
            fc = (c - a) / (b - a)
            return np.where(
                u < fc, a + np.sqrt(u * (b - a) * (c - a)), b - np.sqrt((1 - u) * (b - a) * (b - c))
            )
        z = np.array([NormalDist().inv_cdf(float(x)) for x in u])
        mean, std = p["mean"], p["std"]
        if d == "normal":
            return mean + std * z
        if d == "lognormal":
            # mean and std of the variable itself (not of its logarithm).
            s2 = math.log(1.0 + (std / mean) ** 2)
            return np.exp(math.log(mean) - 0.5 * s2 + math.sqrt(s2) * z)
        if d == "gumbel":
            # Largest-value Gumbel with that mean and std.
            beta = std * math.sqrt(6.0) / math.pi
            mu = mean - 0.5772156649015329 * beta
            return mu - beta * np.log(-np.log(u))
        raise AssertionError(d)


def _parameter(name: str, spec: Mapping[str, Any]) -> Parameter:
    where = f"parameters.{name}"
    if not isinstance(spec, Mapping):
        raise SweepError(f"{where}: expected a table with path and values, value, distribution or expression")
    known = {"path", "values", "value", "distribution", "expression",
             "low", "high", "mode", "mean", "std", "cov"}
    extra = sorted(set(spec) - known)
    if extra:
        raise SweepError(f"{where}: unknown key(s) {extra} (known: {sorted(known)})")
    path = spec.get("path", "")
    if not isinstance(path, str):
        raise SweepError(f"{where}.path: expected the dotted model key the parameter sets, e.g. \"materials.concrete.E\" (no path: a column only, for expressions)")
    given = [k for k in ("values", "value", "distribution", "expression") if k in spec]
    if len(given) != 1:
        raise SweepError(f"{where}: give exactly one of values, value, distribution, expression (given: {given})")
    p = Parameter(name=name, path=path)
    if "values" in spec:
        v = spec["values"]
        if not isinstance(v, list) or not v:
            raise SweepError(f"{where}.values: expected a non-empty list")
        p.values = list(v)
    elif "value" in spec:
        p.value = spec["value"]
    elif "expression" in spec:
        p.expression = str(spec["expression"])
        try:
            tree = ast.parse(p.expression, mode="eval")
        except SyntaxError as e:
            raise SweepError(f"{where}.expression: {e.msg}") from None
        for node in ast.walk(tree):
            if not isinstance(node, _ALLOWED):
                raise SweepError(
                    f"{where}.expression: only arithmetic, parameter names and {sorted(_MATH)} are allowed"
                )
    else:
        d = spec["distribution"]
        if d not in DISTRIBUTIONS:
            raise SweepError(f"{where}.distribution: '{d}' is not one of {list(DISTRIBUTIONS)}")
        p.distribution = d
        num = {k: float(spec[k]) for k in ("low", "high", "mode", "mean", "std", "cov") if k in spec}
        if d in ("uniform", "triangular"):
            need = ["low", "high"] + (["mode"] if d == "triangular" else [])
            for k in need:
                if k not in num:
                    raise SweepError(f"{where}.{k}: required for a {d} distribution")
            if not num["low"] < num["high"]:
                raise SweepError(f"{where}: low must be below high")
            if d == "triangular" and not num["low"] <= num["mode"] <= num["high"]:
                raise SweepError(f"{where}.mode: must lie between low and high")
        else:
            if "mean" not in num:
                raise SweepError(f"{where}.mean: required for a {d} distribution")
            if ("std" in num) == ("cov" in num):
                raise SweepError(f"{where}: give one of std or cov (coefficient of variation)")
            if "cov" in num:
                num["std"] = abs(num["mean"]) * num.pop("cov")
            if not num["std"] > 0:
                raise SweepError(f"{where}: the standard deviation must be > 0")
            if d == "lognormal" and not num["mean"] > 0:
                raise SweepError(f"{where}.mean: must be > 0 for a lognormal distribution")
        p.params = num
    return p


def _evaluate(p: Parameter, row: Dict[str, Any]) -> float:
    try:
        return float(eval(compile(p.expression or "", p.name, "eval"), {"__builtins__": {}}, {**_MATH, **row}))
    except Exception as e:  # noqa: BLE001 - any failure of the user's expression
        raise SweepError(f"parameters.{p.name}.expression: {e}") from None


# -- the sweep ---------------------------------------------------------------------------


class Sweep:
    """A sweep: base model, parameters, method, monitors to collect.

    Make one with :meth:`load` (a sweep file, TOML) or :meth:`from_dict`; the keys are
    those of docs/sweeps.md: ``model`` (a model file name relative to the sweep file, model
    data, or a :class:`~segfem.Model`), ``method`` (grid, monte_carlo, latin_hypercube),
    ``samples`` and ``seed`` (sampling), ``parameters`` (name → spec), ``monitors``
    (default: all), ``reductions`` (final, max, min; default final), ``keep`` (all,
    summary, none: what stays of each case's run directory).
    """

    def __init__(self, spec: Mapping[str, Any], base_dir: Optional[PathLike] = None, label: str = "sweep") -> None:
        self.label = label
        self.base_dir = Path(base_dir) if base_dir is not None else Path.cwd()
        known = {"model", "method", "samples", "seed", "parameters", "monitors", "reductions", "keep", "name"}
        extra = sorted(set(spec) - known)
        if extra:
            raise SweepError(f"{label}: unknown key(s) {extra} (known: {sorted(known)})")
        self.name: str = str(spec.get("name", Path(label).stem))
        self.model = self._model(spec.get("model"))
        self.method: str = spec.get("method", "grid")
        if self.method not in METHODS:
            raise SweepError(f"{label}: method: '{self.method}' is not one of {list(METHODS)}")
        params = spec.get("parameters")
        if not isinstance(params, Mapping) or not params:
            raise SweepError(f"{label}: parameters: at least one parameter (a table name → spec)")
        self.parameters = [_parameter(n, s) for n, s in params.items()]
        kinds = {p.kind for p in self.parameters}
        if self.method == "grid" and "random" in kinds:
            raise SweepError(f"{label}: method grid: a parameter has a distribution (use values, or method monte_carlo / latin_hypercube)")
        if self.method != "grid" and "grid" in kinds:
            raise SweepError(f"{label}: method {self.method}: a parameter has values (a grid); give it a distribution or a value")
        if self.method != "grid":
            if "samples" not in spec or int(spec["samples"]) < 1:
                raise SweepError(f"{label}: samples: required for method {self.method} (number of cases ≥ 1)")
            if "seed" not in spec:
                raise SweepError(f"{label}: seed: required for method {self.method} (the sample is reproducible from it)")
        self.samples = int(spec.get("samples", 0))
        self.seed = int(spec.get("seed", 0))
        names = [m["name"] for m in self.model.monitors]
        self.monitors: List[str] = list(spec.get("monitors", names))
        for m in self.monitors:
            if m not in names:
                raise SweepError(f"{label}: monitors: the model has no monitor '{m}' (monitors: {names})")
        self.reductions: List[str] = list(spec.get("reductions", ["final"]))
        for r in self.reductions:
            if r not in REDUCTIONS:
                raise SweepError(f"{label}: reductions: '{r}' is not one of {list(REDUCTIONS)}")
        # A parameter column must not share its name with another column of the table: a
        # result column would overwrite it.
        monitor_columns = {m if r == "final" else f"{m}_{r}" for m in names for r in self.reductions}
        for p in self.parameters:
            if p.name in RESERVED_COLUMNS or p.name.startswith("factor:"):
                raise SweepError(
                    f"{label}: parameters.{p.name}: the name of a column the results table or the history already has "
                    f"({', '.join(RESERVED_COLUMNS)}); choose another name"
                )
            if p.name in monitor_columns:
                raise SweepError(
                    f"{label}: parameters.{p.name}: the name of a monitor column of the model's results; choose another name"
                )
        self.keep: str = spec.get("keep", "summary")
        if self.keep not in KEEP:
            raise SweepError(f"{label}: keep: '{self.keep}' is not one of {list(KEEP)}")
        self._text = self.model.toml()
        self._data = self.model.to_dict()
        for p in self.parameters:
            if not p.path:
                continue
            # The path must name a table in the model (the last key may be new).
            parent = p.path.rsplit(".", 1)[0] if "." in p.path else None
            try:
                if parent is not None:
                    get_path(self._data, parent)
            except KeyError as e:
                why = str(e.args[0]).removeprefix(f"{parent}: ")
                raise SweepError(f"{label}: parameters.{p.name}.path: {p.path}: {why}") from None
        self._cases: Optional[pd.DataFrame] = None
        self._rows: Optional[List[Dict[str, Any]]] = None

    def _model(self, m: Any) -> Model:
        if isinstance(m, Model):
            return m
        if isinstance(m, (str, os.PathLike)):
            p = Path(m)
            return Model.from_file(p if p.is_absolute() else self.base_dir / p)
        if isinstance(m, Mapping):
            return Model.from_dict(m, base_dir=self.base_dir)
        raise SweepError(f"{self.label}: model: required: a model file name, model data or a segfem.Model")

    @classmethod
    def load(cls, path: PathLike) -> "Sweep":
        """Read a sweep file (TOML, docs/sweeps.md); ``model`` is relative to it."""
        p = Path(path)
        try:
            text = p.read_text(encoding="utf-8")
        except OSError as e:
            raise SweepError(f"{p}: cannot read the file: {e.strerror}") from None
        try:
            # tomllib keeps the order of the parameters (the table's columns).
            import tomllib

            try:
                spec = tomllib.loads(text)
            except tomllib.TOMLDecodeError as e:
                raise SweepError(f"{p}: {e}") from None
        except ImportError:  # Python < 3.11
            try:
                spec = json.loads(_native.toml_to_json(text, str(p)))
            except ValueError as e:
                raise SweepError(str(e)) from None
        return cls(spec, base_dir=p.parent, label=str(p))

    @classmethod
    def from_dict(cls, spec: Mapping[str, Any], base_dir: Optional[PathLike] = None) -> "Sweep":
        """A sweep from Python data with the sweep file's keys."""
        return cls(spec, base_dir=base_dir)

    # -- planning ---------------------------------------------------------------------

    @property
    def cases(self) -> pd.DataFrame:
        """The planned cases: one row per case (index ``case``), one column per parameter."""
        if self._cases is None:
            rows = self._case_rows()
            self._cases = pd.DataFrame(rows, columns=[p.name for p in self.parameters])
            self._cases.index.name = "case"
        return self._cases.copy()

    def _case_rows(self) -> List[Dict[str, Any]]:
        """The planned cases as the values given (an int stays an int: a table row would
        turn it into the float of a column beside a float)."""
        if self._rows is None:
            self._rows = self._plan()
        return self._rows

    def _plan(self) -> List[Dict[str, Any]]:
        grid = [p for p in self.parameters if p.kind == "grid"]
        random = [p for p in self.parameters if p.kind == "random"]
        if self.method == "grid":
            rows = [dict(zip([p.name for p in grid], combo)) for combo in itertools.product(*[p.values for p in grid])]
            if not grid:
                rows = [{}]
        else:
            n, k = self.samples, len(random)
            rng = np.random.default_rng(self.seed)
            if self.method == "monte_carlo":
                u = rng.random((n, k))
            else:
                # Latin hypercube: one point in each of n equal-probability strata per axis,
                # strata paired at random across axes.
                u = np.empty((n, k))
                for j in range(k):
                    u[:, j] = (rng.permutation(n) + rng.random(n)) / n
            # Probabilities of exactly 0 would map to an infinite quantile.
            u = np.clip(u, 1e-12, 1.0 - 1e-12)
            cols = {p.name: p.ppf(u[:, j]) for j, p in enumerate(random)}
            rows = [{name: float(v[i]) for name, v in cols.items()} for i in range(n)]
        for row in rows:
            for p in self.parameters:
                if p.kind == "constant":
                    row[p.name] = p.value
            for p in self.parameters:
                if p.kind == "expression":
                    row[p.name] = _evaluate(p, row)
        return [{p.name: row[p.name] for p in self.parameters} for row in rows]

    def tasks(self, out_dir: Path, threads: int = 1) -> List[Dict[str, Any]]:
        """The work of each case as plain data (sent to a worker process or a Dask worker)."""
        digest = hashlib.sha256(self._text.encode()).hexdigest()
        name = self.model.path.name if self.model.path is not None else "model.toml"
        out = []
        for case, row in enumerate(self._case_rows()):
            params = {k: _plain(v) for k, v in row.items()}
            out.append(
                {
                    "case": int(case),
                    "params": params,
                    "values": {p.path: params[p.name] for p in self.parameters if p.path},
                    "model": self._data,
                    "model_name": name,
                    "model_digest": digest,
                    "base_dir": str(self.model.base_dir.resolve()),
                    "case_dir": None if self.keep == "none" else str((out_dir / "cases" / f"{int(case):05d}").resolve()),
                    "keep": self.keep,
                    "monitors": self.monitors,
                    "reductions": self.reductions,
                    "threads": threads,
                }
            )
        return out

    # -- running ----------------------------------------------------------------------

    def run(
        self,
        out_dir: Optional[PathLike] = None,
        *,
        workers: Optional[int] = None,
        client: Any = None,
        scheduler: Optional[str] = None,
        progress: Optional[Callable[[int, int, Dict[str, Any]], Any]] = None,
        threads_per_case: int = 1,
    ) -> pd.DataFrame:
        """Run every case not yet finished in ``out_dir`` (default: the sweep's name) and
        return the table of all cases, also written as ``results.parquet`` (with pyarrow)
        and ``results.csv``.

        Locally the cases run in ``workers`` processes (default: the machine's cores);
        with ``client`` (a ``dask.distributed.Client``) or ``scheduler`` (its address)
        they run on that Dask cluster. ``progress(done, total, record)`` is called as
        cases finish. Ctrl-C stops the sweep; the finished cases are kept.
        """
        out = Path(out_dir) if out_dir is not None else self.base_dir / self.name
        (out / "cases").mkdir(parents=True, exist_ok=True)
        tasks = self.tasks(out, threads_per_case)
        _write_atomic(out / "sweep.json", json.dumps(self._description(), indent=1, allow_nan=True))
        todo = [t for t in tasks if not _finished(out, t)]
        if todo:
            self._validate(todo[0])
        total, done = len(tasks), len(tasks) - len(todo)

        def finish(rec: Dict[str, Any]) -> None:
            nonlocal done
            _write_atomic(_record_path(out, rec["case"]), json.dumps(rec, allow_nan=True))
            done += 1
            if progress is not None:
                progress(done, total, rec)

        if todo:
            if client is None and scheduler is not None:
                from dask.distributed import Client

                with Client(scheduler) as c:
                    _run_dask(c, todo, finish)
            elif client is not None:
                _run_dask(client, todo, finish)
            else:
                _run_local(todo, finish, workers)
        table = self.gather(out)
        return table

    def _validate(self, task: Dict[str, Any]) -> None:
        """Validate one case's model before sending all: a wrong key path fails here once,
        with the model's message, instead of in every case."""
        data = json.loads(json.dumps(task["model"]))
        from .model import set_path

        for path, value in task["values"].items():
            set_path(data, path, value)
        try:
            Model.from_dict(data, name=task["model_name"], base_dir=task["base_dir"])
        except InputError as e:
            raise SweepError(f"{self.label}: case {task['case']}: {e}") from None

    def gather(self, out_dir: PathLike) -> pd.DataFrame:
        """The table of the finished cases in ``out_dir`` (written as results.parquet and
        results.csv)."""
        out = Path(out_dir)
        recs = []
        for t in self.tasks(out):
            p = _record_path(out, t["case"])
            if p.exists():
                recs.append(json.loads(p.read_text(encoding="utf-8")))
        table = self._table(recs)
        _write_table(table, out)
        return table

    def _table(self, recs: List[Dict[str, Any]]) -> pd.DataFrame:
        cols = ["case"] + [p.name for p in self.parameters]
        cols += ["status", "exit_code", "ultimate_mode", "ultimate_factor", "peak_factor"]
        for m in self.monitors:
            cols += [m if r == "final" else f"{m}_{r}" for r in self.reductions]
        cols += ["increments", "iterations", "wall_s", "elapsed_s", "worker", "error"]
        rows = []
        for rec in sorted(recs, key=lambda r: r["case"]):
            row = {"case": rec["case"], **rec["params"], **rec["result"]}
            rows.append({c: row.get(c) for c in cols})
        df = pd.DataFrame(rows, columns=cols)
        for c in cols:
            if c in ("status", "ultimate_mode", "worker", "error"):
                df[c] = df[c].astype("string")
        units = {m["name"]: m["unit"] for m in self.model.monitors}
        df.attrs["units"] = {
            **{(m if r == "final" else f"{m}_{r}"): units[m] for m in self.monitors for r in self.reductions},
            "wall_s": "s",
            "elapsed_s": "s",
        }
        return df

    def _description(self) -> Dict[str, Any]:
        return {
            "name": self.name,
            "model": str(self.model.path) if self.model.path is not None else None,
            "method": self.method,
            "samples": self.samples,
            "seed": self.seed,
            "parameters": [p.__dict__ for p in self.parameters],
            "monitors": self.monitors,
            "reductions": self.reductions,
            "keep": self.keep,
        }


def _plain(v: Any) -> Any:
    if isinstance(v, np.generic):
        return v.item()
    return v


def _record_path(out: Path, case: int) -> Path:
    return out / "cases" / f"{case:05d}.json"


def _finished(out: Path, task: Dict[str, Any]) -> bool:
    """Whether the case's record is there for the same parameters and base model."""
    p = _record_path(out, task["case"])
    if not p.exists():
        return False
    try:
        rec = json.loads(p.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return False
    return rec.get("params") == task["params"] and rec.get("model_digest") == task["model_digest"]


def _write_atomic(path: Path, text: str) -> None:
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(text)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


def _write_table(table: pd.DataFrame, out: Path) -> None:
    tmp = out / ".results.csv.tmp"
    table.to_csv(tmp, index=False, float_format="%.17g")
    os.replace(tmp, out / "results.csv")
    try:
        import pyarrow  # noqa: F401
    except ImportError:
        return
    tmp = out / ".results.parquet.tmp"
    table.to_parquet(tmp, index=False)
    os.replace(tmp, out / "results.parquet")


# -- one case (runs in a worker) ---------------------------------------------------------


def run_case(task: Dict[str, Any]) -> Dict[str, Any]:
    """Run one case of a sweep (in a worker process, local or Dask) and return its record:
    the parameters, the status, the ultimate verdict, the monitors' reductions, timings.
    Bad input for a case (a sampled value the model refuses) is a finished case with
    status ``input`` and the message; Ctrl-C propagates (the case is not finished)."""
    os.environ.setdefault("RAYON_NUM_THREADS", str(task.get("threads", 1)))
    t0 = time.perf_counter()
    res: Dict[str, Any] = {"worker": f"{socket.gethostname()}:{os.getpid()}"}
    tmp = None
    try:
        data = json.loads(json.dumps(task["model"]))
        from .model import set_path

        for path, value in task["values"].items():
            set_path(data, path, value)
        model = Model.from_dict(data, name=task["model_name"], base_dir=task["base_dir"])
        if task["case_dir"] is None:
            tmp = tempfile.TemporaryDirectory(prefix="segfem-case-")
            case_dir = Path(tmp.name)
        else:
            case_dir = Path(task["case_dir"])
        # Cases that keep only their summaries write no field files at all.
        r = model.run(case_dir, fields=task["keep"] == "all")
        u = r.ultimate or {}
        s = r.summary
        res.update(
            status=r.status,
            exit_code=r.exit_code,
            ultimate_mode=u.get("mode"),
            ultimate_factor=u.get("at_factor"),
            peak_factor=u.get("peak_factor"),
            increments=s.get("timings", {}).get("increments"),
            iterations=s.get("timings", {}).get("iterations"),
            wall_s=s.get("wall_s"),
            error=r.error,
        )
        final = r.final
        hist = r.history if any(x != "final" for x in task["reductions"]) else None
        for m in task["monitors"]:
            for red in task["reductions"]:
                col = m if red == "final" else f"{m}_{red}"
                if red == "final":
                    res[col] = final.get(m)
                elif hist is not None and len(hist):
                    res[col] = float(hist[m].max() if red == "max" else hist[m].min())
        if task["keep"] == "summary":
            for f in case_dir.iterdir():
                if f.name not in ("history.csv", "summary.json", task["model_name"]):
                    f.unlink() if f.is_file() else shutil.rmtree(f)
    except InputError as e:
        res.update(status="input", exit_code=e.exit_code, error=str(e))
    except SegfemError as e:
        res.update(status="error", exit_code=e.exit_code, error=str(e))
    finally:
        if tmp is not None:
            tmp.cleanup()
    res["elapsed_s"] = time.perf_counter() - t0
    return {
        "case": task["case"],
        "params": task["params"],
        "model_digest": task["model_digest"],
        "result": res,
    }


# -- executors ---------------------------------------------------------------------------


def _init_worker(threads: int, parent: int) -> None:
    os.environ["RAYON_NUM_THREADS"] = str(threads)
    # A worker outlives a driver killed with SIGKILL (no chance to shut the pool down) and
    # would run its case to the end: it watches its parent and ends itself once the parent
    # is gone (it is then re-parented). The case it ran is not finished (no record) and is
    # run again when the sweep is resumed. A polling thread rather than Linux's
    # PR_SET_PDEATHSIG, which fires when the parent's *thread* that started the worker ends.
    import threading

    def watch() -> None:
        while True:
            if os.getppid() != parent:
                os._exit(137)
            time.sleep(0.2)

    threading.Thread(target=watch, name="segfem-parent-watch", daemon=True).start()


def _run_local(todo: List[Dict[str, Any]], finish: Callable[[Dict[str, Any]], None], workers: Optional[int]) -> None:
    import concurrent.futures as cf
    import multiprocessing as mp

    n = max(1, min(workers or os.cpu_count() or 1, len(todo)))
    # Fresh interpreters (spawn): a forked child would inherit a copy of a thread pool
    # the parent may have started and hang on it.
    ctx = mp.get_context("spawn")
    ex = cf.ProcessPoolExecutor(max_workers=n, mp_context=ctx, initializer=_init_worker, initargs=(todo[0]["threads"], os.getpid()))
    try:
        futures = [ex.submit(run_case, t) for t in todo]
        for f in cf.as_completed(futures):
            finish(f.result())
    except BaseException:
        ex.shutdown(wait=True, cancel_futures=True)
        raise
    ex.shutdown(wait=True)


def _run_dask(client: Any, todo: List[Dict[str, Any]], finish: Callable[[Dict[str, Any]], None]) -> None:
    from dask.distributed import as_completed

    futures = client.map(run_case, todo, pure=False)
    try:
        for f in as_completed(futures):
            finish(f.result())
    except BaseException:
        client.cancel(futures)
        raise


def run(sweep: Union[PathLike, Mapping[str, Any], Sweep], out_dir: Optional[PathLike] = None, **kwargs: Any) -> pd.DataFrame:
    """Run a sweep (a sweep file, sweep data or a :class:`Sweep`); keywords as
    :meth:`Sweep.run`. Returns the table."""
    if isinstance(sweep, Sweep):
        s = sweep
    elif isinstance(sweep, Mapping):
        s = Sweep.from_dict(sweep)
    else:
        s = Sweep.load(sweep)
    return s.run(out_dir, **kwargs)


def main(argv: Optional[Sequence[str]] = None) -> int:
    """``segfem-sweep SWEEP.toml [-o OUT] [--workers N | --dask ADDRESS]``."""
    ap = argparse.ArgumentParser(prog="segfem-sweep", description="Run a segfem parameter sweep (docs/sweeps.md).")
    ap.add_argument("sweep", help="sweep file (TOML)")
    ap.add_argument("-o", "--output", help="output directory (default: the sweep's name beside the file)")
    ap.add_argument("--workers", type=int, help="local worker processes (default: the machine's cores)")
    ap.add_argument("--dask", metavar="ADDRESS", help="run on the Dask scheduler at ADDRESS instead")
    ap.add_argument("--plan", action="store_true", help="print the planned cases and stop")
    ap.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors")
    a = ap.parse_args(argv)
    try:
        s = Sweep.load(a.sweep)
        if a.plan:
            print(s.cases.to_string())
            return 0

        def show(done: int, total: int, rec: Dict[str, Any]) -> None:
            if not a.quiet:
                r = rec["result"]
                print(f"[{done}/{total}] case {rec['case']}: {r.get('status')} {r.get('ultimate_mode') or ''} {r.get('elapsed_s', 0):.2f} s", file=sys.stderr)

        out = Path(a.output) if a.output else None
        table = s.run(out, workers=a.workers, scheduler=a.dask, progress=show)
    except SegfemError as e:
        print(f"error: {e}", file=sys.stderr)
        return e.exit_code
    except KeyboardInterrupt:
        print("interrupted: finished cases are kept; run the same command again to go on", file=sys.stderr)
        return 130
    if not a.quiet:
        where = out or s.base_dir / s.name
        print(f"{len(table)} cases; table in {where}/results.csv (and results.parquet)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
