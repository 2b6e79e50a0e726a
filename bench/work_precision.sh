#!/usr/bin/env bash
# Work–precision of the plant integrators against scipy's solve_ivp, measured in
# one run on this machine. Run by hand (not in CI):
#   bench/work_precision.sh
# Creates bench/.venv with scipy + matplotlib, builds `ivt` in release, runs
# `ivt --json bench work-precision` and scipy (RK45, DOP853, LSODA) on the same
# angle-domain plant, prints a Markdown table and writes
# crates/ivt-sim/work_precision.png.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ ! -x bench/.venv/bin/python ]; then
  python3 -m venv bench/.venv
  bench/.venv/bin/pip install -q scipy matplotlib
fi
cargo build --release -q
./target/release/ivt --json bench work-precision > bench/ivt_work_precision.json
bench/.venv/bin/python bench/work_precision.py bench/ivt_work_precision.json crates/ivt-sim/work_precision.png
