"""Models and runs: :func:`load`, :meth:`Model.from_dict`, :meth:`Model.run`, :func:`restart`.

A :class:`Model` is a model file (or the same content as Python data) that has been read and
validated by the segfem library exactly as ``segfem check`` does. :meth:`Model.run` runs it
as ``segfem run`` does, writing the same files (history.csv, summary.json, .vtu fields, the
checkpoint) into an output directory, and returns a :class:`~segfem.Result`.
"""

from __future__ import annotations

import copy
import json
import os
import tempfile
from pathlib import Path
from typing import Any, Callable, Dict, List, Mapping, Optional, Union

from . import _segfem as _native
from .errors import InputError, Interrupted, OutputError, RestartError
from .result import Result

PathLike = Union[str, "os.PathLike[str]"]
#: A progress callback: called with one dict per converged increment (docs/python.md).
Progress = Callable[[Dict[str, Any]], Any]


def _input_error(e: ValueError) -> InputError:
    """The native ValueError(message, file, line, key, problem) as an InputError."""
    args = e.args
    if len(args) == 5:
        return InputError(args[0], file=args[1], line=args[2], key=args[3], problem=args[4])
    return InputError(str(args[0]) if args else str(e))


class Model:
    """A validated segfem model.

    Make one with :func:`segfem.load` (a model file), :meth:`Model.from_dict` (Python
    data with the model file's keys, docs/input.md) or :meth:`Model.from_toml` (text).
    Invalid input raises :class:`~segfem.InputError` with the command line's message.

    Attributes: ``title``, ``load_cases`` and ``steps`` (names, in order), ``monitors``
    (list of dicts: name, kind, component, unit), ``size`` (dict: nodes, elements, dofs),
    ``warnings`` (input warnings), ``path`` (the model file, or None for data).
    """

    def __init__(
        self,
        *,
        path: Optional[Path],
        text: Optional[str],
        label: str,
        base_dir: Path,
        facts: Dict[str, Any],
        warnings: List[str],
    ) -> None:
        self.path = path
        self._text = text
        self._label = label
        self.base_dir = base_dir
        self.title: str = facts["title"]
        self.load_cases: List[str] = list(facts["load_cases"])
        self.steps: List[str] = list(facts["steps"])
        self.monitors: List[Dict[str, Any]] = list(facts["monitors"])
        self.size: Dict[str, int] = {k: facts[k] for k in ("nodes", "elements", "dofs")}
        self.warnings: List[str] = list(warnings)
        self._data: Optional[Dict[str, Any]] = None

    # -- construction ---------------------------------------------------------------

    @classmethod
    def from_file(cls, path: PathLike) -> "Model":
        """Read and validate a model file (TOML, docs/input.md); same as :func:`segfem.load`."""
        p = Path(path)
        try:
            facts, warnings = _native.check(str(p))
        except ValueError as e:
            raise _input_error(e) from None
        return cls(
            path=p,
            text=None,
            label=str(p),
            base_dir=p.parent,
            facts=json.loads(facts),
            warnings=warnings,
        )

    @classmethod
    def from_toml(
        cls, text: str, *, name: str = "model.toml", base_dir: Optional[PathLike] = None
    ) -> "Model":
        """Validate model-file text. ``name`` names the model in messages and is the file
        name written into the output directory at a run; relative file names in the model
        (a Gmsh mesh) are found in ``base_dir`` (default: the current directory)."""
        base = Path(base_dir) if base_dir is not None else Path.cwd()
        label = str(base / name) if base_dir is not None else name
        try:
            facts, warnings = _native.check_text(text, label)
        except ValueError as e:
            raise _input_error(e) from None
        return cls(
            path=None,
            text=text,
            label=label,
            base_dir=base,
            facts=json.loads(facts),
            warnings=warnings,
        )

    @classmethod
    def from_dict(
        cls,
        data: Mapping[str, Any],
        *,
        name: str = "model.toml",
        base_dir: Optional[PathLike] = None,
    ) -> "Model":
        """Validate a model given as Python data: the keys of a model file (docs/input.md),
        arrays of tables as lists of dicts. ``name`` and ``base_dir`` as in
        :meth:`from_toml`. Numbers must be finite (TOML has no NaN in a model)."""
        try:
            text = _native.json_to_toml(json.dumps(data, allow_nan=False))
        except ValueError as e:
            raise InputError(f"{name}: {e}", file=name, problem=str(e)) from None
        m = cls.from_toml(text, name=name, base_dir=base_dir)
        m._data = copy.deepcopy(dict(data))
        return m

    # -- data -----------------------------------------------------------------------

    def to_dict(self) -> Dict[str, Any]:
        """The model as Python data (a fresh copy): the model file's keys and values."""
        if self._data is None:
            text = self.toml()
            self._data = json.loads(_native.toml_to_json(text, self._label))
        return copy.deepcopy(self._data)

    def toml(self) -> str:
        """The model-file text (the file itself for a model read from a file)."""
        if self._text is not None:
            return self._text
        assert self.path is not None
        return self.path.read_text(encoding="utf-8")

    def with_values(self, values: Mapping[str, Any]) -> "Model":
        """A copy with the values at dotted key paths replaced, then validated; e.g.
        ``{"materials.concrete.E": 30e9, "tendons.T1.initial_stress": 9e8}``. A path
        segment picks a list item by position (``steps.2``) or by its ``name``."""
        data = self.to_dict()
        for key, value in values.items():
            set_path(data, key, value)
        name = self.path.name if self.path is not None else Path(self._label).name
        return Model.from_dict(data, name=name, base_dir=self.base_dir)

    # -- running --------------------------------------------------------------------

    def run(
        self,
        out_dir: Optional[PathLike] = None,
        progress: Optional[Progress] = None,
        *,
        verbose: bool = False,
        continue_on_failure: bool = False,
        stop_after_step: Optional[int] = None,
        fields: bool = True,
    ) -> Result:
        """Run the model as ``segfem run`` does and return its :class:`~segfem.Result`.

        ``out_dir``: where history.csv, summary.json, the .vtu fields and the checkpoint
        go (files of an earlier run there are replaced); None: a temporary directory that
        lives as long as the Result. A model given as data is written there first as
        ``name`` (default model.toml), the file the run reads and the checkpoint names.
        ``fields=False`` writes no field files (.vtu, results.pvd) whatever the steps'
        ``output``, as ``segfem run --no-fields``: the history, summary and checkpoint
        only, with the same numbers.

        ``progress(p)`` is called after every converged increment with a dict: ``step``
        (1-based), ``step_name``, ``steps``, ``increment``, ``end_of_step``,
        ``iterations``, ``factors`` (load case → factor), ``arc_length_factor``,
        ``negative_pivots``. An exception it raises stops the run after that increment
        and is raised again from here.

        The analysis runs without the GIL. Ctrl-C stops it after the current increment:
        :class:`~segfem.Interrupted` (a KeyboardInterrupt) is raised with the results so
        far in its ``result``. A run that ends otherwise than ``completed`` (an increment
        that does not converge at failure, a mechanism, implausible results, a stop after
        a step) returns its Result with that ``status``: call ``result.check()`` to raise
        instead. Bad input raises :class:`~segfem.InputError`.
        """
        if stop_after_step is not None and stop_after_step < 1:
            raise ValueError("stop_after_step: steps are numbered from 1")
        tmp = None
        if out_dir is None:
            tmp = tempfile.TemporaryDirectory(prefix="segfem-")
            out = Path(tmp.name)
        else:
            out = Path(out_dir)
        if self.path is not None:
            model_path = self.path
        else:
            out.mkdir(parents=True, exist_ok=True)
            model_path = out / Path(self._label).name
            _write_atomic(model_path, self._text_for(out))
        return _run(
            str(model_path),
            out,
            progress,
            verbose=verbose,
            continue_on_failure=continue_on_failure,
            stop_after_step=stop_after_step,
            restart=False,
            tmp=tmp,
            no_fields=not fields,
        )

    def _text_for(self, out: Path) -> str:
        """The text to write into ``out``: relative mesh file names made absolute
        against ``base_dir``, so that the copy reads the same mesh."""
        assert self._text is not None
        if _relative_mesh_file(self) is None:
            return self._text
        data = self.to_dict()
        data["mesh"]["file"] = str((self.base_dir / data["mesh"]["file"]).resolve())
        return _native.json_to_toml(json.dumps(data, allow_nan=False))

    def __repr__(self) -> str:
        src = str(self.path) if self.path is not None else f"<data {self._label}>"
        return (
            f"Model({self.title!r}, {src}, {self.size['nodes']} nodes, "
            f"{len(self.steps)} steps, monitors {[m['name'] for m in self.monitors]})"
        )


def _relative_mesh_file(m: Model) -> Optional[str]:
    mesh = m.to_dict().get("mesh")
    f = mesh.get("file") if isinstance(mesh, dict) else None
    if isinstance(f, str) and not os.path.isabs(f):
        return f
    return None


def _write_atomic(path: Path, text: str) -> None:
    tmp = path.with_name(f".{path.name}.tmp{os.getpid()}")
    tmp.write_text(text, encoding="utf-8")
    os.replace(tmp, path)


def load(path: PathLike) -> Model:
    """Read and validate a model file (TOML, docs/input.md), as ``segfem check``.

    Raises :class:`~segfem.InputError` with the command line's message on bad input.
    """
    return Model.from_file(path)


def restart(out_dir: PathLike, progress: Optional[Progress] = None, *, model: Optional[PathLike] = None) -> Result:
    """Continue the stopped run in ``out_dir`` from its last checkpoint, as
    ``segfem run --restart DIR`` (``model``: the model file, default the one the
    checkpoint names). ``progress`` and Ctrl-C as in :meth:`Model.run`."""
    return _run(
        None if model is None else str(model),
        Path(out_dir),
        progress,
        verbose=False,
        continue_on_failure=False,
        stop_after_step=None,
        restart=True,
        tmp=None,
    )


def _run(
    model: Optional[str],
    out: Path,
    progress: Optional[Progress],
    *,
    verbose: bool,
    continue_on_failure: bool,
    stop_after_step: Optional[int],
    restart: bool,
    tmp: Optional[tempfile.TemporaryDirectory],
    no_fields: bool = False,
) -> Result:
    (code, kind, message, summary), raised = _native.run(
        model,
        str(out),
        progress,
        verbose=verbose,
        continue_on_failure=continue_on_failure,
        stop_after_step=stop_after_step,
        restart=restart,
        no_fields=no_fields,
    )
    if kind == "input":
        raise InputError(message)
    if kind == "restart":
        raise RestartError(message, code)
    if kind in ("io", "busy"):
        raise OutputError(message, code)
    result = Result(
        out,
        exit_code=code,
        error=message,
        summary=None if summary is None else json.loads(summary),
        tmp=tmp,
    )
    if raised is not None:
        if isinstance(raised, KeyboardInterrupt):
            raise Interrupted(message or "interrupted", result) from None
        try:
            raised.result = result  # type: ignore[attr-defined]
        except AttributeError:
            pass
        raise raised
    return result


def set_path(data: Dict[str, Any], key: str, value: Any) -> None:
    """Set ``value`` at the dotted key path ``key`` of model data in place. A segment
    picks a list item by position (``steps.2.increments``) or by its ``name``
    (``materials.concrete.E``); the last segment may add a key to a table."""
    parts = key.split(".")
    node: Any = data
    for i, part in enumerate(parts):
        last = i == len(parts) - 1
        where = ".".join(parts[: i + 1])
        if isinstance(node, list):
            idx = _list_index(node, part, key, where)
            if last:
                node[idx] = value
            else:
                node = node[idx]
        elif isinstance(node, dict):
            if last:
                node[part] = value
            elif part in node:
                node = node[part]
            else:
                raise KeyError(f"{key}: the model has no '{where}'")
        else:
            raise KeyError(f"{key}: '{'.'.join(parts[:i])}' is a value, not a table or list")


def get_path(data: Mapping[str, Any], key: str) -> Any:
    """The value at the dotted key path ``key`` (as :func:`set_path` reads it)."""
    node: Any = data
    parts = key.split(".")
    for i, part in enumerate(parts):
        where = ".".join(parts[: i + 1])
        if isinstance(node, list):
            node = node[_list_index(node, part, key, where)]
        elif isinstance(node, dict) and part in node:
            node = node[part]
        else:
            raise KeyError(f"{key}: the model has no '{where}'")
    return node


def _list_index(items: List[Any], part: str, key: str, where: str) -> int:
    if part.lstrip("-").isdigit():
        idx = int(part)
        if -len(items) <= idx < len(items):
            return idx % len(items)
        raise KeyError(f"{key}: '{where}': index {idx} out of range (the list has {len(items)} items)")
    named = [j for j, x in enumerate(items) if isinstance(x, dict) and x.get("name") == part]
    if len(named) != 1:
        names = [x.get("name") for x in items if isinstance(x, dict)]
        raise KeyError(f"{key}: '{where}': no item named '{part}' (names: {names})")
    return named[0]
