"""The wheel as users meet it: installed into a fresh venv outside the
repository, it runs a shipped scene, and its native extension is small.

``scripts/py-test`` builds the wheel once and passes it as ``IVT_WHEEL``.
"""

import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path
from typing import List

import pytest

WHEEL = os.environ.get("IVT_WHEEL")
needs_wheel = pytest.mark.skipif(not WHEEL, reason="IVT_WHEEL not set (scripts/py-test sets it)")

#: Acceptance of the packaging: the installed extension stays under 15 MB.
MAX_EXTENSION_BYTES = 15_000_000


def pip_install(pip: List[str], *packages: str, cwd: Path) -> None:
    """`pip install packages`, failing with pip's own message and the free
    disk space (the CI once failed here without a message, on a disk that
    leftover test directories had filled)."""
    proc = subprocess.run([*pip, *packages], cwd=cwd, capture_output=True, text=True)
    if proc.returncode != 0:
        free = shutil.disk_usage(cwd).free / 1e9
        pytest.fail(f"pip install {' '.join(packages)}: exit {proc.returncode}, {free:.1f} GB free\n"
                    f"{proc.stdout[-2000:]}\n{proc.stderr[-4000:]}")


@needs_wheel
def test_wheel_ships_scenes_and_a_small_extension() -> None:
    assert WHEEL is not None
    with zipfile.ZipFile(WHEEL) as z:
        infos = z.infolist()
    ext = [i for i in infos if i.filename.startswith("ivt/_ivt") and i.filename.endswith((".so", ".pyd"))]
    assert len(ext) == 1, [i.filename for i in infos]
    assert ext[0].file_size < MAX_EXTENSION_BYTES, ext[0].file_size
    shipped = {Path(i.filename).stem for i in infos if i.filename.startswith("ivt/_scenes/")}
    repo = {p.stem for p in (Path(__file__).resolve().parents[3] / "scenes").glob("*.toml")}
    assert shipped == repo and "drive" in shipped


@needs_wheel
def test_fresh_venv_runs_a_shipped_scene(tmp_path: Path) -> None:
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    py = venv / "bin" / "python"
    pip = [str(py), "-m", "pip", "install", "-q", "--disable-pip-version-check"]
    pip_install(pip, str(WHEEL), cwd=tmp_path)
    script = (
        "import json, ivt\n"
        "assert 'drive' in ivt.scenes.names(), ivt.scenes.names()\n"
        # no matplotlib here: ivt works, ivt.plot says which extra it needs
        "try:\n"
        "    ivt.plot\n"
        "except ImportError as e:\n"
        "    assert \"pip install 'ivt[plot]'\" in str(e), e\n"
        "else:\n"
        "    raise AssertionError('ivt.plot imported without matplotlib')\n"
        "p = ivt.scenes.path('drive')\n"
        "r = ivt.sim.run(p)\n"
        "print(json.dumps({'path': str(p), 'scene': r['summary']['scene'],"
        " 'pulses': r['summary']['pulses'], 'ia': float(r['channels']['plant']['i_a'].max())}))\n"
    )
    out = subprocess.run(
        [str(py), "-c", script], check=True, cwd=tmp_path, capture_output=True, text=True,
        env={"PATH": os.environ.get("PATH", ""), "HOME": str(tmp_path)},
    )
    import json

    res = json.loads(out.stdout)
    repo = Path(__file__).resolve().parents[3]
    assert not Path(res["path"]).resolve().is_relative_to(repo), res["path"]
    assert res["scene"] == "drive"
    # 60 s at ≈ 100 rpm with 1200 pulses per revolution: ≈ 1.2e5 pulses.
    assert 1.0e5 < res["pulses"] < 1.4e5, res["pulses"]
    # the algebraic armature current (L_a = 0) is logged, not 0.0
    assert res["ia"] > 0.1, res["ia"]


@needs_wheel
def test_fresh_venv_runs_every_chapter_as_a_user_copies_it(tmp_path: Path) -> None:
    """Issue 31: each chapter's example, copied into a fresh venv as a user
    would (the wheel with its `plot` extra (matplotlib) + scipy, nothing of
    the repository importable), runs as shown: each chapter becomes one
    script, its Python blocks in order and its `$ ivt ...` lines as shell
    commands between them (the same lines test_guide.py runs, the same
    NOT_RUN list), run by the fresh venv's Python in an empty directory
    holding what a checkout holds (test_guide.checkout), and draws the
    figures the chapter shows."""
    from test_guide import GUIDE, NOT_RUN, as_ivt, blocks, checkout, commands, figures, ivt_bin

    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    py = venv / "bin" / "python"
    pip = [str(py), "-m", "pip", "install", "-q", "--disable-pip-version-check"]
    # the extras the chapters name: figures, finite-element models, Dask sweeps
    pip_install(pip, f"{WHEEL}[plot,fe,dask]", "numpy", "scipy", cwd=tmp_path)
    exe = ivt_bin()
    ran = 0
    for chapter in sorted(GUIDE.rglob("*.md")):
        parts = []
        for lang, _, body in blocks(chapter.read_text()):
            if lang == "python":
                parts.append(body)
            elif lang == "console":
                for cmd in map(as_ivt, commands(body)):
                    if not any(cmd.startswith(p) for p in NOT_RUN):
                        parts.append(
                            "__import__('subprocess').run("
                            f"{cmd!r}, shell=True, check=True, executable='/bin/bash')\n"
                        )
        if not any(lang == "python" for lang, _, _ in blocks(chapter.read_text())):
            continue
        work = tmp_path / chapter.relative_to(GUIDE).with_suffix("").as_posix().replace("/", "-")
        work.mkdir()
        checkout(work)
        (work / "example.py").write_text("".join(parts))
        # Run as `python -c`, as pasted into an interpreter or a notebook: a
        # process cluster's workers then do not re-run the chapter (a script
        # needs `if __name__ == "__main__":` around them, as large-models.md
        # says).
        run = subprocess.run(
            [str(py), "-c", (work / "example.py").read_text()], cwd=work, capture_output=True,
            text=True,
            env={"PATH": f"{exe.parent}{os.pathsep}{os.environ.get('PATH', '')}", "HOME": str(tmp_path)},
        )
        assert run.returncode == 0, f"{chapter.name}:\n{run.stdout[-2000:]}\n{run.stderr[-3000:]}"
        for figure in figures(chapter.read_text()):
            assert (work / figure).is_file(), f"{chapter.name}: {figure} not drawn"
        ran += 1
    assert ran >= 10, ran
