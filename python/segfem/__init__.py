"""segfem from Python: finite element analysis of precast segmental concrete beams with
external prestressing (plane stress).

    import segfem
    model = segfem.load("seed-beam.toml")          # validated as `segfem check`
    result = model.run("out", progress=print)     # as `segfem run`, GIL released
    result.history                                # pandas DataFrame, units in .attrs
    result.summary["ultimate"]                    # the verdict of a run to failure
    result.fields[-1].point_data["displacement"]  # numpy arrays per output increment

Sweeps (grids, Latin hypercube, Monte Carlo; locally or on Dask): :mod:`segfem.sweep`.
docs/python.md and docs/sweeps.md describe both.
"""

from . import _segfem
from .errors import (
    AnalysisError,
    InputError,
    Interrupted,
    OutputError,
    RestartError,
    SegfemError,
)
from .model import Model, get_path, load, restart, set_path
from .result import FieldOutput, Grid, Result, read_history
from . import sweep
from .sweep import Sweep

__version__: str = _segfem.__version__

__all__ = [
    "AnalysisError",
    "FieldOutput",
    "Grid",
    "InputError",
    "Interrupted",
    "Model",
    "OutputError",
    "RestartError",
    "Result",
    "SegfemError",
    "Sweep",
    "get_path",
    "load",
    "read_history",
    "restart",
    "set_path",
    "sweep",
    "__version__",
]
