"""The wheel as users meet it: installed into a fresh venv outside the
repository, it runs a shipped scene, and its native extension is small.
(Every chapter of the guide runs in such a venv too: test_guide.py.)

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
    # --no-compile: Python compiles what the run imports (pip's compiling of
    # every installed module took 45 of the install's 66 s)
    pip = [str(py), "-m", "pip", "install", "-q", "--disable-pip-version-check", "--no-compile"]
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
