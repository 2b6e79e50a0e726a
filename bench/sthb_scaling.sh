#!/usr/bin/env bash
# STHB string at scale (issue 28, item 4): the whole curve ω 1–6 with stability
# (k_d = 10, defaults of `ivt hb string`) for N modes × M harmonics, CPU time
# and points per curve, cost per point against N·M with the fitted exponent.
# Run by hand (not in CI), a minute or two:
#   bench/sthb_scaling.sh                      this tree: bench/sthb_scaling.json,
#                                              docs/figures/sthb_scaling.png, table on stdout
#   bench/sthb_scaling.sh --baseline PATH      also the `ivt` CLI at PATH (the tree
#                                              before issue 28), each size cut at
#                                              $BASELINE_TIMEOUT s (default 300)
# The timings come from the ignored test `scaling` of crates/ivt-sthb/tests/sthb_scale.rs
# (CPU seconds from /proc, so a loaded machine inflates wall time, not the CPU column).
# Needs python3 with numpy and matplotlib (the repository's .venv if present).
set -euo pipefail
cd "$(dirname "$0")/.."
sizes=${SIZES:-"5x9 5x19 5x39 10x9 10x19 10x39 20x9 20x19 20x39"}
out=bench/sthb_scaling.json
py=python3
[ -x .venv/bin/python ] && py=.venv/bin/python
tmp=$(mktemp)
cut_s=${BASELINE_TIMEOUT:-300}
SIZES="$sizes" CARGO_BUILD_JOBS=${CARGO_BUILD_JOBS:-2} cargo test --release -q -p ivt-sthb \
  --test sthb_scale -- --ignored --exact scaling --nocapture 2>/dev/null |
  grep '^{' | sed 's/^{/{"solver": "sthb", /' >"$tmp"
if [ "${1:-}" = "--baseline" ]; then
  cli=$2
  for size in $sizes; do
    n=${size%x*}; m=${size#*x}
    t0=$(date +%s.%N)
    if res=$( { /usr/bin/time -f '%U %S' timeout "$cut_s" "$cli" hb string --modes "$n" --harmonics "$m" --json >"$tmp.json"; } 2>&1 ); then
      cpu=$(echo "$res" | tail -n 1 | awk '{print $1 + $2}')
      points=$("$py" -c "import json,sys; print(len(json.load(open('$tmp.json'))['points']))")
      jac=$("$py" -c "import json,sys; print(json.load(open('$tmp.json'))['jacobians'])")
      wall=$(awk "BEGIN { print $(date +%s.%N) - $t0 }")
      echo "{\"solver\": \"baseline\", \"modes\": $n, \"harmonics\": $m, \"points\": $points, \"jacobians\": $jac, \"wall_s\": $wall, \"cpu_s\": $cpu}" >>"$tmp"
    else
      echo "{\"solver\": \"baseline\", \"modes\": $n, \"harmonics\": $m, \"timeout_s\": $cut_s}" >>"$tmp"
    fi
    rm -f "$tmp.json"
  done
fi
mkdir -p docs/figures
"$py" bench/sthb_scaling.py "$tmp" --json "$out" --png docs/figures/sthb_scaling.png
rm -f "$tmp"
