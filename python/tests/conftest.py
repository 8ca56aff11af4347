"""Shared fixtures: the repository's examples and the segfem command line to compare with."""

import os
import shutil
import signal
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"

# The Ctrl-C tests send SIGINT and expect Python's KeyboardInterrupt. Python installs that
# handler only if SIGINT was not ignored when it started, and a shell without job control
# starts background commands (`.ci/run &`, nohup) with SIGINT ignored: restore it here.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)


@pytest.fixture(scope="session")
def cli() -> str:
    """The segfem binary: $SEGFEM_BIN, else target/release/segfem of this repository
    (CARGO_TARGET_DIR honoured), else `segfem` on PATH."""
    env = os.environ.get("SEGFEM_BIN")
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    for c in (env, target / "release" / "segfem", shutil.which("segfem")):
        if c and Path(c).is_file():
            return str(c)
    pytest.fail("no segfem binary: build it with `cargo build --release` or set SEGFEM_BIN")


@pytest.fixture
def seed_beam(tmp_path: Path) -> Path:
    p = tmp_path / "seed-beam.toml"
    shutil.copy(EXAMPLES / "seed-beam-elastic.toml", p)
    return p


@pytest.fixture
def cantilever(tmp_path: Path) -> Path:
    p = tmp_path / "cantilever.toml"
    shutil.copy(EXAMPLES / "cantilever.toml", p)
    return p
