"""The guide's (docs/guide) Python and command-line blocks run as a reader would
run them, chapter by chapter:

- each chapter runs in a fresh temporary directory (its cwd) that holds what
  a checkout holds and the chapters read: ``scenes/`` (the shipped scenes),
  ``examples/`` (the example models), the manifests ``Cargo.toml``,
  ``crates/`` and ``firmware/``, and ``bench/`` (the benchmark gate's
  baseline; symlinks into the repository, read only);
- as a user copies it: the chapter becomes one script run by a fresh venv's
  Python that holds the wheel (``$IVT_WHEEL``) with its extras and nothing of
  the repository (:func:`reader_python`);
- its ```python blocks run top to bottom at the top level of that script, so a
  later block uses what an earlier one defined; their assertions are the checks;
- its ```console blocks run in the same directory, in document order with the
  Python blocks: every line ``$ ivt ...`` runs with the built CLI ($IVT_BIN,
  else target/release/ivt) first on PATH and must exit 0 (a line ending in
  ``\\`` continues on the next). ``$ cargo run --release [-- ARGS]`` is the same
  program and runs as ``ivt [ARGS]``. The only ``$`` lines not run are those in
  ``NOT_RUN`` (the check itself, or a machine this is not), each named there;
  any other ``$`` line fails the test;
- lines without ``$`` in a console block, and ```text blocks, are output shown;
- its figures: every image the chapter shows (``![alt](path.png)``, the path
  relative to the chapter) is a file its blocks wrote at that path in its
  directory — a Python block with :mod:`ivt.plot` or matplotlib, or an
  ``ivt ... --plot`` line — and is copied into the rendered book beside the
  chapter's page (``target/guide``, or ``$IVT_GUIDE_BOOK``), where
  scripts/check-book-browser opens it. A figure is therefore drawn by the
  code the chapter shows each time this test runs: it cannot go stale, and
  none is committed. Every chapter shows at least one.

```rust blocks are doctests (src/lib.rs includes every chapter); tests/guide.rs
refuses any other fence language.
"""

import os
import pathlib
import re
import shlex
import shutil
import subprocess
import sys
from typing import Dict, List, Tuple

import pytest

REPO = pathlib.Path(__file__).resolve().parents[3]
GUIDE = REPO / "docs" / "guide" / "src"

# `$` commands shown but not run, each with its reason.
NOT_RUN: Dict[str, str] = {
    "./scripts/test": "the check that runs this test",
    "./scripts/py-test": "the check that runs this test",
    "scripts/bench-gate": "the benchmark gate: its own step of scripts/test (valgrind, a minute)",
    "python bench/gate/gate.py": "the gate on another build (valgrind, a minute)",
    ".venv/bin/python bench/gate/gate.py": "the gate against another baseline (valgrind, a minute)",
    "cargo install": "installs a tool into the user's ~/.cargo",
    "pip install": "installs into the user's environment (reader_python's venv holds the wheel)",
    "python -m venv": "creates the user's environment",
    "source ": "activates the user's environment",
    "firmware/run-qemu.sh": "scripts/test runs the firmware step itself",
    "cd ": "moves into a checkout; the runner's cwd is the chapter's directory",
    "git clone": "needs the network",
    "probe-rs": "needs the STM32F411 rig board",
    "RUSTC=/usr/bin/rustc": "the firmware with Debian's toolchain: scripts/test builds and tests it "
    "(firmware/run-qemu.sh test); `--features rig` flashes the rig board",
    "ivt rig record --port": "needs the rig's serial port",
    "cargo doc": "scripts/guide builds the Rust reference",
    "pdoc ": "scripts/py-test builds the Python reference",
    "ivt rig commission --port": "needs the rig's serial port",
}

FENCE = re.compile(r"^(\s*)(`{3,}|~{3,})\s*([^\s`]*)")
# A Markdown image: ![alt](path).
IMAGE = re.compile(r"!\[[^\]]*\]\(([^)\s]+)\)")


def book_dir() -> pathlib.Path:
    """The rendered book the chapters' figures are copied into."""
    env = os.environ.get("IVT_GUIDE_BOOK")
    return pathlib.Path(env) if env else REPO / "target" / "guide"


# What a chapter's directory holds of a checkout (symlinks, read only).
CHECKOUT = ("scenes", "examples", "Cargo.toml", "crates", "firmware", "bench")


def checkout(work: pathlib.Path) -> None:
    """Link the parts of the repository a chapter reads into `work`."""
    for name in CHECKOUT:
        (work / name).symlink_to(REPO / name, target_is_directory=(REPO / name).is_dir())


def ivt_bin() -> pathlib.Path:
    env = os.environ.get("IVT_BIN")
    path = pathlib.Path(env) if env else REPO / "target" / "release" / "ivt"
    if not path.is_file():
        pytest.fail(f"ivt CLI not found at {path}: cargo build --release --bin ivt, or set IVT_BIN")
    return path


def blocks(text: str) -> List[Tuple[str, int, str]]:
    """(language, first line number, body) of every fenced block, in order;
    the opening fence's indentation is removed from the body."""
    out: List[Tuple[str, int, str]] = []
    lines = text.splitlines()
    i = 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        indent, fence, lang = len(m.group(1)), m.group(2), m.group(3).split(",")[0]
        body: List[str] = []
        start = i + 1
        i += 1
        while i < len(lines) and not (
            lines[i].strip().startswith(fence) and set(lines[i].strip()) == {fence[0]}
        ):
            line = lines[i]
            body.append(line[indent:] if line[:indent].strip() == "" else line.lstrip())
            i += 1
        out.append((lang, start + 1, "\n".join(body) + "\n"))
        i += 1
    return out


def prose(text: str) -> str:
    """The chapter without its fenced blocks (what is rendered as text)."""
    lines = text.splitlines()
    keep = [True] * len(lines)
    for _, start, body in blocks(text):
        # the opening fence is line start - 1 (1-based), the closing one after the body
        first = start - 2
        for i in range(first, min(len(lines), first + body.count("\n") + 2)):
            keep[i] = False
    return "\n".join(line for line, k in zip(lines, keep) if k)


def figures(text: str) -> List[str]:
    """The image paths a chapter shows, relative to the chapter, in order."""
    return IMAGE.findall(prose(text))


def commands(body: str) -> List[str]:
    """The ``$`` lines of a console block, continuation lines joined."""
    out: List[str] = []
    pending = None
    for line in body.splitlines():
        if pending is not None:
            pending += " " + line.strip()
        elif line.startswith("$ "):
            pending = line[2:].strip()
        else:
            continue
        if pending.endswith("\\"):
            pending = pending[:-1].rstrip()
        else:
            out.append(pending)
            pending = None
    assert pending is None, "a console line ends in \\ with nothing after it"
    return out


def as_ivt(cmd: str) -> str:
    """``cargo run --release [-- ARGS]`` is ``ivt [ARGS]``; others unchanged."""
    m = re.match(r"cargo run --release(?: --bin ivt)?(?:\s+--\s*(.*))?$", cmd)
    if m:
        return ("ivt " + (m.group(1) or "")).strip()
    return cmd


def chapters() -> List[str]:
    return sorted(
        p.relative_to(GUIDE).as_posix() for p in GUIDE.rglob("*.md") if p.name != "SUMMARY.md"
    )


def test_every_chapter_shows_a_figure_of_its_own() -> None:
    """Each chapter shows at least one figure; each figure path is relative,
    stays in the chapter's directory of the book, is a PNG, and names no
    file of the guide's sources nor another chapter's figure."""
    seen: Dict[str, str] = {}
    for chapter in chapters():
        shown = figures((GUIDE / chapter).read_text())
        assert shown, f"{chapter} shows no figure"
        for path in shown:
            rel = pathlib.PurePosixPath(path)
            assert not rel.is_absolute() and ".." not in rel.parts and rel.suffix == ".png", (
                f"{chapter}: figure {path} must be a relative .png inside the chapter's directory"
            )
            book_path = (pathlib.PurePosixPath(chapter).parent / rel).as_posix()
            assert not (GUIDE / book_path).exists(), f"{chapter}: {path} is a source file"
            assert book_path not in seen, f"{chapter} and {seen.get(book_path)} both show {book_path}"
            seen[book_path] = chapter


def test_figure_reader() -> None:
    text = "![a](x.png)\n```python\n# ![b](not-a-figure.png)\n```\ntext ![c](out/y.png) end\n"
    assert figures(text) == ["x.png", "out/y.png"]


def test_block_reader() -> None:
    text = "x\n```python\na = 1\n```\n- item\n  ```console\n  $ ivt kin \\\n  plant\n  out\n  ```\n"
    got = blocks(text)
    assert got == [("python", 3, "a = 1\n"), ("console", 7, "$ ivt kin \\\nplant\nout\n")]
    assert commands(got[1][2]) == ["ivt kin plant"]
    assert as_ivt("cargo run --release") == "ivt"
    assert as_ivt("cargo run --release -- sim scenes/drive.toml") == "ivt sim scenes/drive.toml"


@pytest.fixture(scope="session")
def reader_python(tmp_path_factory: pytest.TempPathFactory) -> pathlib.Path:
    """The Python a reader runs the chapters with: a fresh venv outside the
    repository holding the wheel (``$IVT_WHEEL``, which scripts/py-test
    builds) with the extras the chapters name — figures, finite-element
    models, Dask sweeps — plus numpy and scipy, nothing of the repository
    importable. Without ``$IVT_WHEEL`` (a developer's own pytest run), the
    running interpreter and the ``ivt`` installed in it."""
    wheel = os.environ.get("IVT_WHEEL")
    if not wheel:
        return pathlib.Path(sys.executable)
    from test_wheel import pip_install

    base = tmp_path_factory.mktemp("reader")
    venv = base / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    py = venv / "bin" / "python"
    # --no-compile: Python compiles what the run imports (pip's compiling of
    # every installed module took 45 of the install's 66 s)
    pip = [str(py), "-m", "pip", "install", "-q", "--disable-pip-version-check", "--no-compile"]
    pip_install(pip, f"{wheel}[plot,fe,dask]", "numpy", "scipy", cwd=base)
    return py


def chapter_script(chapter: str) -> str:
    """The chapter as one Python script, as a reader copies it: its Python
    blocks in order, at the top level of one module (compiled with the
    chapter's path and line numbers, so a traceback points into the chapter),
    and between them its ``$`` lines as shell commands that must exit 0."""
    path = GUIDE / chapter
    where_file = str(path.relative_to(REPO))
    parts = [
        "import subprocess as _sp, sys as _sys\n",
        "def _command(where, cmd):\n"
        "    run = _sp.run(['bash', '-o', 'pipefail', '-c', cmd], capture_output=True, text=True)\n"
        "    if run.returncode != 0:\n"
        "        _sys.exit(f'{where}: `$ {cmd}` exited {run.returncode}\\n'\n"
        "                  f'stdout: {run.stdout[-2000:]}\\nstderr: {run.stderr[-2000:]}')\n",
    ]
    for lang, line, body in blocks(path.read_text()):
        where = f"{where_file}:{line}"
        if lang == "python":
            code = "\n" * (line - 1) + body
            parts.append(f"exec(compile({code!r}, {where_file!r}, 'exec'))\n")
        elif lang == "console":
            for cmd in commands(body):
                cmd = as_ivt(cmd)
                if any(cmd.startswith(p) for p in NOT_RUN):
                    continue
                assert cmd.split()[0] == "ivt", (
                    f"{where}: `$ {cmd}` is neither an ivt command nor in NOT_RUN"
                )
                parts.append(f"_command({where!r}, {cmd!r})\n")
    return "".join(parts)


@pytest.mark.parametrize("chapter", chapters())
def test_chapter_runs(chapter: str, tmp_path: pathlib.Path, reader_python: pathlib.Path) -> None:
    """The chapter run by :func:`reader_python` as ``python -c SCRIPT`` (as
    pasted into an interpreter or a notebook: a Dask process cluster's
    workers then do not re-run the chapter — a script file needs ``if
    __name__ == "__main__":`` around them, as large-models.md says), in its
    own directory (:func:`checkout`), with the built CLI first on PATH and
    HOME in that directory; then its figures are copied into the book."""
    checkout(tmp_path)
    exe = ivt_bin()
    run = subprocess.run(
        [str(reader_python), "-c", chapter_script(chapter)],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        env={"PATH": f"{exe.parent}{os.pathsep}{os.environ.get('PATH', '')}", "HOME": str(tmp_path)},
    )
    assert run.returncode == 0, f"{chapter}:\n{run.stdout[-2000:]}\n{run.stderr[-3000:]}"
    # The chapter's figures, drawn just now by its blocks, into the book.
    target = book_dir() / pathlib.PurePosixPath(chapter).parent
    for figure in figures((GUIDE / chapter).read_text()):
        drawn = tmp_path / figure
        assert drawn.is_file(), f"{chapter}: figure {figure} was not drawn by the chapter's code"
        assert drawn.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", f"{chapter}: {figure} is not a PNG"
        (target / figure).parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(drawn, target / figure)
