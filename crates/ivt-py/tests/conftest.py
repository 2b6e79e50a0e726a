"""Shared fixtures: the `ivt` command line, whose --json output is the
reference the bindings are cross-checked against (SPEC §6)."""

import json
import os
import pathlib
import subprocess
from typing import Any, Callable, Dict, List

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


# No silent skips: scripts/py-test runs pytest with `-rs --fail-on-skip`, so a
# skipped test is listed with its reason and fails the run.
_SKIPPED: List[str] = []


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addoption(
        "--fail-on-skip",
        action="store_true",
        help="fail the session if any test is skipped (CI: every test must run)",
    )


def pytest_runtest_logreport(report: pytest.TestReport) -> None:
    if report.skipped and not hasattr(report, "wasxfail"):
        _SKIPPED.append(report.nodeid)


def pytest_terminal_summary(terminalreporter: Any) -> None:
    if _SKIPPED and terminalreporter.config.getoption("--fail-on-skip"):
        terminalreporter.write_line(
            f"--fail-on-skip: {len(_SKIPPED)} skipped test(s): {', '.join(_SKIPPED)}", red=True
        )


def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    if _SKIPPED and session.config.getoption("--fail-on-skip") and exitstatus == 0:
        session.exitstatus = pytest.ExitCode.TESTS_FAILED
