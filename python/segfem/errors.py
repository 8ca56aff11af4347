"""Exceptions raised by segfem (docs/python.md, "Errors").

Each carries ``exit_code``, the status the command line ``segfem run`` exits with for the
same failure (docs/running.md), and its message is exactly the one the command line prints
after ``error:``.
"""

from __future__ import annotations

from typing import Any, Optional


class SegfemError(Exception):
    """Base of segfem's exceptions; ``exit_code`` is the command line's exit status."""

    exit_code: int = 1

    def __init__(self, message: str, exit_code: Optional[int] = None) -> None:
        super().__init__(message)
        if exit_code is not None:
            self.exit_code = exit_code

    @property
    def message(self) -> str:
        """The message, as the command line prints it after ``error:``."""
        return str(self.args[0]) if self.args else ""


class InputError(SegfemError, ValueError):
    """A model that does not validate (exit status 2).

    Attributes: ``file`` (the model file or label), ``line`` (1-based, where the parser
    knows it, else None), ``key`` (key path such as ``regions[2].thickness``, may be
    empty) and ``problem`` (what is wrong).
    """

    exit_code = 2

    def __init__(
        self,
        message: str,
        file: str = "",
        line: Optional[int] = None,
        key: str = "",
        problem: str = "",
    ) -> None:
        super().__init__(message)
        self.file = file
        self.line = line
        self.key = key
        self.problem = problem or message


class RestartError(SegfemError):
    """A restart is impossible: no or a damaged checkpoint, or the model changed (exit 2)."""

    exit_code = 2


class OutputError(SegfemError, OSError):
    """Result files could not be written or read (exit status 1)."""

    exit_code = 1


class AnalysisError(SegfemError):
    """The analysis did not end as ``completed``; raised by :meth:`Result.check`.

    ``status`` is the summary's status (``failed``, ``implausible``, ``stopped``) and
    ``result`` the :class:`~segfem.Result` with everything written so far.
    """

    def __init__(self, message: str, exit_code: int, status: str, result: Any) -> None:
        super().__init__(message, exit_code)
        self.status = status
        self.result = result


class Interrupted(KeyboardInterrupt):
    """Ctrl-C stopped a run after its current increment (the command line exits 130).

    A ``KeyboardInterrupt``, so that scripts stop as usual; ``result`` holds the results
    written so far (the run can go on with ``segfem.restart(result.out_dir)``) and the
    message says where the run stopped.
    """

    exit_code = 130

    def __init__(self, message: str, result: Any) -> None:
        super().__init__(message)
        self.result = result
