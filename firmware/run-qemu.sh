#!/usr/bin/env bash
# Firmware builds and QEMU checks (scripts/test calls `test`).
#
#   firmware/run-qemu.sh build     build the qemu images (PIL server, bench) and the rig image
#   firmware/run-qemu.sh pil       PIL-vs-SIL tests (ivt-sim: scenes, commissioning) and `ivt rig record` end to end (needs `build`)
#   firmware/run-qemu.sh panic     prove from the release ELFs that the pulse path cannot reach the panic handler
#   firmware/run-qemu.sh budgets   flash/RAM, instructions per pulse, stack; fails over the targets
#   firmware/run-qemu.sh test      all of the above
#   firmware/run-qemu.sh run [ELF] run an image under QEMU with UART0 on stdio
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
cd "$here"
# Debian's toolchain for the firmware only; the host tests below use the
# workspace's own cargo/rustc (exporting RUSTC would rebuild the world).
CARGO="env RUSTC=/usr/bin/rustc RUSTC_BOOTSTRAP=1 /usr/bin/cargo"
out=target/thumbv7em-none-eabihf/release

build() {
  $CARGO build --release --features qemu --bins
  $CARGO build --release --features rig --bins
}

# --workspace (not -p ivt-sim): the workspace's feature set, so the test
# binaries `cargo test --workspace` built are reused instead of rebuilding
# every crate under ivt-sim with the narrower features of one package.
pil() {
  (cd .. && export IVT_FW_ELF="$here/$out/ivt-fw-qemu" &&
    cargo test --workspace --release --test pil -- --include-ignored &&
    cargo test --workspace --release --test commission -- --include-ignored &&
    cargo test --workspace --release --test rig_record -- --include-ignored)
}

# Checks are chained with && (not left to `set -e`): `test` calls them in a
# `||` list, where errexit is off inside the function.
panic_check() {
  python3 panic_reach.py "$out/ivt-fw-bench" --root ivt_fw_pulse --must-reach ivt_fw_canary &&
    python3 panic_reach.py "$out/ivt-fw-qemu" --root ivt_fw_pulse --root ivt_fw_sequenced_pulse &&
    python3 panic_reach.py "$out/ivt-fw-rig" --root ivt_fw_pulse --root ivt_fw_sequenced_pulse --root TIM2 --root TIM3
}

budgets() {
  python3 budgets.py "$out"
}

# Build, then every check even if an earlier one fails (a budget overrun must
# not hide the PIL results); fail at the end, naming the failed checks.
all_checks() {
  build
  local failed=()
  panic_check || failed+=(panic)
  budgets || failed+=(budgets)
  pil || failed+=(pil)
  if [ ${#failed[@]} -gt 0 ]; then
    echo "firmware checks failed: ${failed[*]}" >&2
    return 1
  fi
}

case "${1:-test}" in
  build) build ;;
  pil) pil ;;
  panic) panic_check ;;
  budgets) budgets ;;
  test) all_checks ;;
  run) exec qemu-system-arm -cpu cortex-m4 -machine mps2-an386 -display none -monitor none \
         -semihosting-config enable=on,target=native -serial stdio -serial null \
         -kernel "${2:-$out/ivt-fw-bench}" ;;
  *) echo "usage: $0 build|pil|panic|budgets|test|run [ELF]" >&2; exit 2 ;;
esac
