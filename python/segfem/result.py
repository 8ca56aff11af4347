"""Results of a run: :class:`Result` (history, summary, fields) read from the output directory.

The files are those of ``segfem run`` (docs/running.md, "Output files"); nothing is
recomputed: the history is history.csv read back exactly (every number round-trips), the
summary is summary.json, the fields are the .vtu files listed in results.pvd.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Dict, List, Optional

import numpy as np
import pandas as pd

from . import _segfem as _native
from .errors import AnalysisError

_HEADER = re.compile(r"^(?P<name>.*?)(?: \[(?P<unit>[^\]]*)\])?$")
_FILE = re.compile(r"step(?P<step>\d+)_inc(?P<inc>\d+)\.vtu$")


def read_history(path: "str | Path") -> pd.DataFrame:
    """history.csv as a DataFrame: columns named without their unit (``Q``,
    ``midspan_uy``, ``factor:Q``, ``time``), the units in ``df.attrs["units"]``
    (column → SI unit, as in the header). Every number equals the file's exactly."""
    # pandas 3 parses floats exactly by default (and deprecates the option).
    exact = {} if int(pd.__version__.split(".")[0]) >= 3 else {"float_precision": "round_trip"}
    df = pd.read_csv(path, **exact)
    names, units = [], {}
    for h in df.columns:
        m = _HEADER.match(h)
        assert m is not None
        name = m.group("name")
        names.append(name)
        if m.group("unit") is not None:
            units[name] = m.group("unit")
    df.columns = names
    df.attrs["units"] = units
    return df


@dataclass
class Grid:
    """One .vtu piece read back: ``points`` (n × 2) [m], cells as ``connectivity`` and
    ``offsets`` (VTK layout: cell i is ``connectivity[offsets[i-1]:offsets[i]]``), VTK cell
    ``types``, and the point and cell arrays by name (n × components, or n for one
    component; SI units: m, Pa, …)."""

    path: Path
    points: np.ndarray = field(repr=False)
    connectivity: np.ndarray = field(repr=False)
    offsets: np.ndarray = field(repr=False)
    types: np.ndarray = field(repr=False)
    point_data: Dict[str, np.ndarray] = field(default_factory=dict, repr=False)
    cell_data: Dict[str, np.ndarray] = field(default_factory=dict, repr=False)

    @classmethod
    def read(cls, path: "str | Path") -> "Grid":
        """Read a .vtu file written by segfem."""
        d = _native.read_vtu(str(path))

        def f64(b: bytes) -> np.ndarray:
            return np.frombuffer(b, dtype="<f8")

        def arrays(items: List[Any]) -> Dict[str, np.ndarray]:
            out = {}
            for name, comps, b in items:
                a = f64(b)
                out[name] = a if comps == 1 else a.reshape(-1, comps)
            return out

        return cls(
            path=Path(path),
            points=f64(d["points"]).reshape(-1, 2),
            connectivity=f64(d["connectivity"]).astype(np.int64),
            offsets=f64(d["offsets"]).astype(np.int64),
            types=np.frombuffer(d["types"], dtype=np.uint8),
            point_data=arrays(d["point_data"]),
            cell_data=arrays(d["cell_data"]),
        )

    def cells(self) -> List[np.ndarray]:
        """Connectivity of each cell (0-based point indices, VTK node order)."""
        starts = np.concatenate([[0], self.offsets[:-1]])
        return [self.connectivity[a:b] for a, b in zip(starts, self.offsets)]


class FieldOutput:
    """One output increment of the fields (one entry of results.pvd): ``time`` [d],
    ``step`` (1-based) and ``increment``; the grids are read when first asked for:
    ``continuum`` (nodal displacements, stresses, …), ``lines`` (tendons and joints, or
    None) and ``joint_points`` (joint integration points, or None)."""

    def __init__(
        self, time: float, file: Path, lines: Optional[Path], joint_points: Optional[Path]
    ) -> None:
        self.time = time
        self.file = Path(file)
        self._lines = Path(lines) if lines else None
        self._joint_points = Path(joint_points) if joint_points else None
        m = _FILE.search(self.file.name)
        self.step = int(m.group("step")) if m else 0
        self.increment = int(m.group("inc")) if m else 0
        self._cache: Dict[str, Optional[Grid]] = {}

    def _grid(self, key: str, path: Optional[Path]) -> Optional[Grid]:
        if key not in self._cache:
            self._cache[key] = Grid.read(path) if path is not None else None
        return self._cache[key]

    @property
    def continuum(self) -> Grid:
        """The continuum mesh with its point and cell arrays."""
        g = self._grid("continuum", self.file)
        assert g is not None
        return g

    @property
    def lines(self) -> Optional[Grid]:
        """Tendons and joints as line cells, or None."""
        return self._grid("lines", self._lines)

    @property
    def joint_points(self) -> Optional[Grid]:
        """The joints' integration points, or None."""
        return self._grid("joint_points", self._joint_points)

    @property
    def point_data(self) -> Dict[str, np.ndarray]:
        """The continuum's point arrays (``displacement`` n × 2 [m], ``stress`` [Pa], …)."""
        return self.continuum.point_data

    @property
    def cell_data(self) -> Dict[str, np.ndarray]:
        """The continuum's cell arrays."""
        return self.continuum.cell_data

    def __repr__(self) -> str:
        return f"FieldOutput(step={self.step}, increment={self.increment}, time={self.time})"


class Result:
    """The results of one run, read from its output directory ``out_dir``.

    ``status`` (``completed``, ``failed``, ``implausible``, ``interrupted``, ``stopped``),
    ``exit_code`` (the command line's), ``error`` (its message, or None), ``summary``
    (summary.json as a dict), ``ultimate`` (the verdict of a run to failure, or None),
    ``final`` (monitor → final value), ``history`` (DataFrame, units in
    ``history.attrs["units"]``), ``fields`` (list of :class:`FieldOutput`).
    """

    def __init__(
        self,
        out_dir: Path,
        *,
        exit_code: int = 0,
        error: Optional[str] = None,
        summary: Optional[Dict[str, Any]] = None,
        tmp: Any = None,
    ) -> None:
        self.out_dir = Path(out_dir)
        self.exit_code = exit_code
        self.error = error
        self._tmp = tmp  # a TemporaryDirectory kept alive with the result
        if summary is None:
            p = self.out_dir / "summary.json"
            summary = json.loads(p.read_text(encoding="utf-8")) if p.exists() else {}
        self.summary: Dict[str, Any] = summary
        self._history: Optional[pd.DataFrame] = None
        self._fields: Optional[List[FieldOutput]] = None

    @classmethod
    def open(cls, out_dir: "str | Path") -> "Result":
        """The results of an earlier run (its output directory). Raises FileNotFoundError
        when the directory holds no summary.json (not the output of a run, or a run still
        going)."""
        d = Path(out_dir)
        if not (d / "summary.json").is_file():
            raise FileNotFoundError(
                f"{d}: no summary.json: not the output directory of a segfem run"
                " (or its run has not ended yet)"
            )
        return cls(d)

    @property
    def status(self) -> str:
        """The summary's status."""
        return str(self.summary.get("status", "failed"))

    @property
    def ultimate(self) -> Optional[Dict[str, Any]]:
        """The ultimate verdict (mode, detail, load case, factor at failure, peak), or None."""
        return self.summary.get("ultimate")

    @property
    def final(self) -> Dict[str, float]:
        """Final monitor values, name → value (SI units: ``units``)."""
        return {k: v for k, v in self.summary.get("final_monitors", [])}

    @property
    def units(self) -> Dict[str, str]:
        """Monitor name → unit."""
        return {m["name"]: m["unit"] for m in self.summary.get("monitors", [])}

    @property
    def warnings(self) -> List[str]:
        """Warnings of the input and the results."""
        return list(self.summary.get("warnings", []))

    @property
    def history(self) -> pd.DataFrame:
        """history.csv: one row per converged increment (:func:`read_history`)."""
        if self._history is None:
            self._history = read_history(self.out_dir / "history.csv")
        return self._history

    @property
    def fields(self) -> List[FieldOutput]:
        """The output increments of the fields, in order (results.pvd)."""
        if self._fields is None:
            if not (self.out_dir / "results.pvd").exists():
                self._fields = []
            else:
                self._fields = [
                    FieldOutput(t, f, lines, jp)
                    for t, f, lines, jp in _native.field_outputs(str(self.out_dir))
                ]
        return self._fields

    def check(self) -> "Result":
        """Return self if the run completed, else raise :class:`~segfem.AnalysisError`."""
        if self.status != "completed" or self.exit_code != 0:
            raise AnalysisError(
                self.error or f"run ended with status {self.status}",
                self.exit_code,
                self.status,
                self,
            )
        return self

    def __repr__(self) -> str:
        u = self.ultimate
        verdict = f", ultimate {u.get('mode')!r} at {u.get('at_factor')}" if u else ""
        return f"Result({self.status!r}, {str(self.out_dir)!r}{verdict})"
