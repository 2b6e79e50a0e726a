"""Shared fixtures: the `ivt` command line, whose --json output is the
reference the bindings are cross-checked against (SPEC §6)."""

import json
import os
import pathlib
import subprocess
from typing import Any, Callable, Dict

import pytest

REPO = pathlib.Path(__file__).resolve().parents[3]


def _ivt_bin() -> pathlib.Path:
    env = os.environ.get("IVT_BIN")
    path = pathlib.Path(env) if env else REPO / "target" / "release" / "ivt"
    if not path.is_file():
        pytest.fail(
            f"ivt CLI not found at {path}: run `cargo build --release --bin ivt` "
            "or set IVT_BIN (scripts/py-test does both)"
        )
    return path


@pytest.fixture(scope="session")
def cli() -> Callable[..., Dict[str, Any]]:
    """Run `ivt ARGS --json` and return the parsed object."""
    exe = _ivt_bin()

    def run(*args: str) -> Dict[str, Any]:
        out = subprocess.run(
            [str(exe), *args, "--json"], check=True, capture_output=True, text=True
        )
        obj: Dict[str, Any] = json.loads(out.stdout)
        return obj

    return run
