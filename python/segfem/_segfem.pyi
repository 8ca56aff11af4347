"""Type stubs of the native module segfem._segfem (python/src/lib.rs)."""

from typing import Any, Callable, Dict, List, Optional, Tuple

__version__: str

Outcome = Tuple[int, str, Optional[str], Optional[str]]

def run(
    model: Optional[str],
    out_dir: str,
    progress: Optional[Callable[[Dict[str, Any]], Any]] = None,
    verbose: bool = False,
    continue_on_failure: bool = False,
    stop_after_step: Optional[int] = None,
    restart: bool = False,
    no_fields: bool = False,
) -> Tuple[Outcome, Optional[BaseException]]:
    """Run a model file into out_dir as `segfem run`, without the GIL; returns
    ((exit status, kind, message, summary JSON), exception raised in progress or None)."""

def check(path: str) -> Tuple[str, List[str]]:
    """Validate a model file: (model facts JSON, warnings); ValueError on bad input."""

def check_text(text: str, label: str) -> Tuple[str, List[str]]:
    """Validate model text named `label`: (model facts JSON, warnings)."""

def toml_to_json(text: str, label: str) -> str:
    """TOML text to JSON text."""

def json_to_toml(text: str) -> str:
    """JSON text to TOML text."""

def field_outputs(out_dir: str) -> List[Tuple[float, str, Optional[str], Optional[str]]]:
    """results.pvd: (time, continuum .vtu, lines .vtu, joint points .vtu) per output."""

def read_vtu(path: str) -> Dict[str, Any]:
    """A .vtu file: points, connectivity, offsets, types (bytes) and arrays."""
