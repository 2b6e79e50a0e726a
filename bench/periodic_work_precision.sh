#!/usr/bin/env bash
# Work–precision of periodic orbits (Duffing Eq. 49) and FRC timings: ivt's
# modified and classic IHB beside a scipy-written HB, scipy shooting and pyHarm,
# measured in one Python process. Run by hand (not in CI):
#   bench/periodic_work_precision.sh            full run (minutes): table on stdout,
#                                               bench/periodic_work_precision.json,
#                                               docs/figures/work_precision_periodic.png
#   bench/periodic_work_precision.sh --quick    seconds: one ω, a few n, no FRC
#   bench/periodic_work_precision.sh --frc-only the FRC comparisons only (≈ 2 min),
#                                               their entry of the JSON replaced
# Uses the repository's .venv (as ./scripts/py-test does), adds pyharm-os and
# matplotlib to it and builds the `ivt` extension in release.
set -euo pipefail
cd "$(dirname "$0")/.."
venv=$PWD/.venv
[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
if [ -z "${IVT_SKIP_INSTALL:-}" ]; then
  "$venv/bin/pip" install -q --disable-pip-version-check "maturin>=1.16,<2" numpy scipy matplotlib "pyharm-os==1.2.2"
fi
VIRTUAL_ENV=$venv PATH=$venv/bin:$PATH \
  "$venv/bin/maturin" develop --release -m crates/ivt-py/Cargo.toml 2>&1 | tail -n 1 >&2
if [ "${1:-}" = "--quick" ]; then
  exec "$venv/bin/python" bench/periodic_work_precision.py --quick
fi
if [ "${1:-}" = "--frc-only" ]; then
  exec "$venv/bin/python" bench/periodic_work_precision.py --frc-only --json bench/periodic_work_precision.json
fi
mkdir -p docs/figures
"$venv/bin/python" bench/periodic_work_precision.py \
  --json bench/periodic_work_precision.json --png docs/figures/work_precision_periodic.png
