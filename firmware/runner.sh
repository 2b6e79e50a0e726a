#!/usr/bin/env bash
# cargo runner: QEMU for the qemu image, probe-rs for the rig image.
set -euo pipefail
elf=$1; shift
case "$(basename "$elf")" in
  ivt-fw-rig) exec probe-rs run --chip STM32F411CEUx "$elf" "$@" ;;
  *) exec qemu-system-arm -cpu cortex-m4 -machine mps2-an386 -nographic \
       -semihosting-config enable=on,target=native -kernel "$elf" "$@" ;;
esac
