#!/usr/bin/env python3
"""Measure the firmware budgets and fail over the targets (the guide, docs/guide/src/rig/firmware.md).

- flash / static RAM of each image: `arm-none-eabi-size` (flash = text + data,
  RAM = data + bss);
- instructions per pulse: run the bench image under QEMU with
  `-singlestep -d exec,nochain` (every executed instruction is one logged
  translation block) and count, for each call of `ivt_fw_pulse`, the lines
  from its entry up to the return address (the instruction after the `bl`);
- stack: the bench image paints the stack and reports the high-water marks
  of start-up and of the pulse loop via semihosting.

usage: budgets.py OUT_DIR [--json]
"""
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile

TARGET_INSN = 300
TARGET_FLASH = 32 * 1024
TARGET_RAM = 8 * 1024
PPR = 1200


def size(elf):
    out = subprocess.run(["arm-none-eabi-size", elf], check=True, capture_output=True, text=True).stdout
    text, data, bss = map(int, out.splitlines()[1].split()[:3])
    return {"flash": text + data, "ram_static": data + bss}


def symbol(elf, name):
    out = subprocess.run(["arm-none-eabi-nm", elf], check=True, capture_output=True, text=True).stdout
    for line in out.splitlines():
        parts = line.split()
        if len(parts) == 3 and parts[2] == name:
            return int(parts[0], 16) & ~1
    raise SystemExit(f"{name} not in {elf}")


def bench(elf):
    entry = symbol(elf, "ivt_fw_pulse")
    with tempfile.TemporaryDirectory() as d:
        log = os.path.join(d, "exec.log")
        run = subprocess.run(
            ["qemu-system-arm", "-cpu", "cortex-m4", "-machine", "mps2-an386",
             "-display", "none", "-monitor", "none", "-serial", "null", "-serial", "null",
             "-semihosting-config", "enable=on,target=native",
             "-singlestep", "-d", "exec,nochain", "-D", log, "-kernel", elf],
            capture_output=True, text=True, timeout=600)
        if run.returncode != 0:
            # The execution log is ~140 MB: say how much room there was.
            free = shutil.disk_usage(d).free / 1e9
            raise SystemExit(f"QEMU exited {run.returncode} ({free:.1f} GB free in {d}):\n{run.stderr[-3000:]}")
        report = dict(l.split("=", 1) for l in run.stdout.split() if "=" in l)
        counts, prev_pc, ret, n = [], None, None, 0
        pat = re.compile(r"\[[0-9a-f]+/([0-9a-f]+)/")
        with open(log) as f:
            for line in f:
                m = pat.search(line)
                if not m:
                    continue
                pc = int(m.group(1), 16)
                if ret is None:
                    if pc == entry:
                        ret, n = prev_pc + 4, 1  # `bl` is 4 bytes
                elif pc == ret:
                    counts.append(n)
                    ret = None
                else:
                    n += 1
                prev_pc = pc
    return counts, report


def main():
    out = sys.argv[1]
    imgs = {name: size(os.path.join(out, name)) for name in ("ivt-fw-qemu", "ivt-fw-rig", "ivt-fw-bench")}
    counts, rep = bench(os.path.join(out, "ivt-fw-bench"))
    pulses = int(rep["pulses"])
    assert len(counts) == pulses, f"counted {len(counts)} calls, bench ran {pulses}"
    steady = counts[2 * PPR:]
    res = {
        "images": imgs,
        "insn_per_pulse": {
            "max": max(counts), "median": statistics.median(counts), "min": min(counts),
            "max_after_ring_full": max(steady), "median_after_ring_full": statistics.median(steady),
            "pulses": pulses,
        },
        "stack_pulse_loop_bytes": int(rep["stack_high_water_bytes"]),
        "stack_init_bytes": int(rep["stack_init_bytes"]),
    }
    ram_pulse = imgs["ivt-fw-bench"]["ram_static"] + max(res["stack_pulse_loop_bytes"], res["stack_init_bytes"])
    res["ram_statics_plus_peak_stack"] = ram_pulse
    print(json.dumps(res, indent=1) if "--json" in sys.argv else "")
    print("image          flash B   static RAM B")
    for k, v in imgs.items():
        print(f"{k:14} {v['flash']:7}   {v['ram_static']:7}")
    i = res["insn_per_pulse"]
    print(f"instructions per ivt_fw_pulse: max {i['max']}, median {i['median']}, min {i['min']} "
          f"over {pulses} pulses (after the ring is full: max {i['max_after_ring_full']})")
    print(f"stack: pulse loop {res['stack_pulse_loop_bytes']} B, start-up {res['stack_init_bytes']} B; "
          f"statics + peak stack = {ram_pulse} B")
    fails = []
    if i["max"] > TARGET_INSN:
        fails.append(f"{i['max']} instructions per pulse > {TARGET_INSN}")
    for k in ("ivt-fw-qemu", "ivt-fw-rig"):
        if imgs[k]["flash"] > TARGET_FLASH:
            fails.append(f"{k} flash {imgs[k]['flash']} > {TARGET_FLASH}")
    if ram_pulse > TARGET_RAM:
        fails.append(f"RAM (statics + peak stack) {ram_pulse} > {TARGET_RAM}")
    for f in fails:
        print("OVER BUDGET:", f)
    sys.exit(1 if fails else 0)


if __name__ == "__main__":
    main()
