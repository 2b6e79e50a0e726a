"""The benchmark gate: the instruction count of every user-facing call in the
suite (Python calls of py_calls.py, CLI commands of CLI below), measured by
callgrind and compared with the committed baseline (baseline.json beside this
file). Run by scripts/bench-gate (and so by ./scripts/test):

    gate.py                    measure, print the table, exit 1 if any call
                               costs more than 5 % over its baseline (or a call
                               has no baseline)
    gate.py --update "why"     measure and write the counts that changed into
                               the baseline, each with `why`
    gate.py --only NAME ...    just these benchmarks
    gate.py --ivt BIN --python PY --baseline FILE
                               measure another build (e.g. main's release binary
                               and a venv holding main's wheel)

Counts are instructions (callgrind's Ir), deterministic for one build: every
run gets the same environment (below), the same relative paths in a fresh
temporary directory, one BLAS thread and a fixed hash seed. A Python figure is
the call alone: the interpreter and the imports run uninstrumented and each
call is measured in a process of its own inside region.c's
`ivt_bench_measure`, after one warm-up call and a full garbage collection;
it includes the ctypes callback that makes the call (a few thousand
instructions). A CLI figure is the whole process, start to exit.
"""

import argparse
import concurrent.futures
import datetime
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
LIMIT = 1.05  # a call may cost at most 5 % more than its baseline

# The CLI benchmarks: argv after `ivt`, run in the temporary directory that
# `prepare` filled. The drive scene runs 6 s of its 60 (the default scene's
# start-up, idle and load step) to keep the step short.
CLI = {
    "cli sim drive (6 s)": ["--json", "sim", "drive.toml", "--out", "out"],
    "cli hb duffing-frc": ["--json", "hb", "duffing-frc"],
    "cli hb string": ["--json", "hb", "string", "--modes", "3", "--harmonics", "9"],
    "cli rig identify": ["--json", "rig", "identify", "commissioning.mcap", "--out", "plant.toml"],
}


def clean_env(home):
    """The one environment every measured process gets."""
    env = {
        "PATH": "/usr/bin:/bin",
        "HOME": str(home),
        "LC_ALL": "C.UTF-8",
        "PYTHONHASHSEED": "0",
        "PYTHONDONTWRITEBYTECODE": "1",
        "OPENBLAS_NUM_THREADS": "1",
        "OMP_NUM_THREADS": "1",
        "MKL_NUM_THREADS": "1",
    }
    # Set on some processors so that OpenBLAS picks a kernel that works there:
    # passed on as the machine has them.
    for key in ("OPENBLAS_CORETYPE", "OPENBLAS_L2_SIZE"):
        if key in os.environ:
            env[key] = os.environ[key]
    return env


def prepare(work, ivt):
    """The CLI benchmarks' inputs: the default scene shortened to 6 s and a
    commissioning recording of the simulated rig's stepper sweep (Fig. 47)."""
    scene = (ROOT / "scenes" / "drive.toml").read_text()
    short = re.sub(r"(?m)^duration_s = 60\.0$", "duration_s = 6.0", scene)
    if short == scene:
        raise SystemExit("bench gate: scenes/drive.toml has no `duration_s = 60.0` line to shorten")
    (work / "drive.toml").write_text(short)
    subprocess.run([ivt, "--json", "rig", "commission", "--sim", "--sequence", "sweep", "--out",
                    "commissioning.mcap"], cwd=work, env=clean_env(work), check=True, capture_output=True)


def totals(path):
    """Ir of one callgrind output file."""
    for line in Path(path).read_text().splitlines():
        if line.startswith("totals:") or line.startswith("summary:"):
            return int(line.split()[1])
    raise SystemExit(f"bench gate: no totals in {path}")


def valgrind(out_file, extra):
    return ["valgrind", "--tool=callgrind", "--dump-instr=no", "--dump-line=no",
            f"--callgrind-out-file={out_file}", *extra]


def measure_cli(name, ivt, work):
    """Ir of `ivt ARGS` from start to exit, in its own copy of the inputs."""
    run_dir = work / re.sub(r"\W+", "_", name)
    shutil.copytree(work / "inputs", run_dir)
    out = run_dir.parent / (run_dir.name + ".cg")
    # stdout into a file: the answer is written as a user's would be (ivt
    # refuses a closed stdout)
    with open(run_dir.parent / (run_dir.name + ".stdout"), "w") as answer:
        proc = subprocess.run(valgrind(out, []) + [ivt, *CLI[name]], cwd=run_dir, env=clean_env(run_dir),
                              stdout=answer, stderr=subprocess.PIPE, text=True)
    if proc.returncode != 0:
        raise SystemExit(f"bench gate: `ivt {' '.join(CLI[name])}` failed:\n{proc.stderr[-2000:]}")
    return {name: totals(out)}


def measure_python(name, python, work):
    """Ir of the named call of py_calls.py, in a process of its own: another
    call's warm-up in the same process moved a small call's count (`py
    duffing` by 27 % when the FRC's warm-up ran its job twice) through the
    allocators' state it left."""
    names = [name]
    region = work / "region.so"
    py_dir = work / ("python_" + re.sub(r"\W+", "_", name))
    py_dir.mkdir()
    shutil.copy(HERE / "py_calls.py", py_dir / "py_calls.py")
    out = py_dir / "cg.out"
    cmd = valgrind(out, ["--instr-atstart=no", "--collect-atstart=no"]) + [python, "py_calls.py", region, *names]
    proc = subprocess.run(cmd, cwd=py_dir, env=clean_env(py_dir), capture_output=True, text=True)
    if proc.returncode != 0:
        raise SystemExit(f"bench gate: the Python calls failed:\n{proc.stderr[-3000:]}")
    found = {}
    for dump in py_dir.glob("cg.out.*"):
        text = dump.read_text()
        m = re.search(r"(?m)^desc: Trigger: Client Request: (.+)$", text)
        if m:
            found[m.group(1)] = totals(dump)
    missing = set(names) - set(found)
    if missing:
        raise SystemExit(f"bench gate: no count for {sorted(missing)}")
    return found


def py_names():
    sys.path.insert(0, str(HERE))
    try:
        import py_calls  # noqa: PLC0415  (numpy and ivt: only the names are needed)
    finally:
        sys.path.pop(0)
    return list(py_calls.CALLS)


def measure(names, ivt, python, jobs):
    """Every named benchmark, each Python call and each CLI command in a
    process of its own, `jobs` at a time."""
    work = Path(tempfile.mkdtemp(prefix="ivt-bench-gate-"))
    try:
        (work / "inputs").mkdir()
        cli = [n for n in names if n in CLI]
        if cli:
            prepare(work / "inputs", ivt)
        py = [n for n in names if n not in CLI]
        if py:
            region = work / "region.so"
            subprocess.run(["cc", "-O2", "-shared", "-fPIC", "-o", region, HERE / "region.c"], check=True)
        with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
            futures = [pool.submit(measure_python, n, python, work) for n in py]
            futures += [pool.submit(measure_cli, n, ivt, work) for n in cli]
            counts = {}
            for f in futures:
                counts.update(f.result())
        return counts
    finally:
        shutil.rmtree(work, ignore_errors=True)


def table(names, base, now):
    """(lines, failures): name, baseline, now, ratio of each benchmark."""
    lines = [f"{'benchmark':30} {'baseline Ir':>15} {'now Ir':>15} {'ratio':>7}"]
    failures = []
    for n in names:
        b = base.get(n, {}).get("instructions")
        if b is None:
            lines.append(f"{n:30} {'(none)':>15} {now[n]:>15,} {'':>7}  no baseline")
            failures.append(n)
            continue
        ratio = now[n] / b
        verdict = ""
        if ratio > LIMIT:
            verdict = f"  FAIL: > {LIMIT:.2f}× baseline"
            failures.append(n)
        elif ratio < 1 / LIMIT:
            verdict = "  cheaper: update the baseline to keep the gain"
        lines.append(f"{n:30} {b:>15,} {now[n]:>15,} {ratio:>7.3f}{verdict}")
    return lines, failures


def commit_of_tree():
    try:
        return subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True,
                              check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return None


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--update", metavar="WHY", help="write the changed counts into the baseline with this reason")
    ap.add_argument("--only", nargs="+", metavar="NAME", help="only these benchmarks")
    ap.add_argument("--ivt", default=str(ROOT / "target" / "release" / "ivt"), help="the ivt binary")
    ap.add_argument("--python", default=sys.executable, help="a Python whose `import ivt` is the build to measure")
    ap.add_argument("--baseline", default=str(HERE / "baseline.json"), help="the baseline file")
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="processes at once")
    args = ap.parse_args()
    if shutil.which("valgrind") is None:
        raise SystemExit("bench gate: valgrind is not installed (apt-get install valgrind)")

    names = list(CLI) + py_names()
    if args.only:
        unknown = set(args.only) - set(names)
        if unknown:
            raise SystemExit(f"bench gate: unknown benchmark(s) {sorted(unknown)}; known: {names}")
        names = [n for n in names if n in args.only]
    t0 = time.monotonic()
    now = measure(names, os.path.abspath(args.ivt), args.python, args.jobs)
    path = Path(args.baseline)
    doc = json.loads(path.read_text()) if path.exists() else {"benchmarks": {}}
    base = doc["benchmarks"]
    lines, failures = table(names, base, now)
    print("\n".join(lines))
    print(f"bench gate: {len(names)} benchmarks measured in {time.monotonic() - t0:.0f} s")
    if args.update is not None:
        if not args.update.strip():
            raise SystemExit("bench gate: --update needs the reason the counts changed")
        stamp = {"why": args.update.strip(), "date": datetime.date.today().isoformat(), "commit": commit_of_tree()}
        changed = [n for n in names if base.get(n, {}).get("instructions") != now[n]]
        for n in changed:
            base[n] = {"instructions": now[n], **stamp}
        doc["benchmarks"] = dict(sorted(base.items()))
        path.write_text(json.dumps(doc, indent=1, ensure_ascii=False) + "\n")
        print(f"bench gate: {len(changed)} count(s) written to {path}")
        return 0
    if failures:
        print(f"bench gate: FAILED: {', '.join(failures)} (more than {LIMIT:.2f}× the baseline or no baseline). "
              "If the cost is intended, run `scripts/bench-gate --update \"why\"` and commit "
              f"{path.relative_to(ROOT) if path.is_relative_to(ROOT) else path} with the change.")
        return 1
    print("bench gate: ok")
    return 0


if __name__ == "__main__":
    sys.exit(main())
