#!/usr/bin/env python3
"""Prove from a release ELF that no function reachable from a root calls the
panic machinery.

Builds the static call graph from `arm-none-eabi-objdump -d`: every direct
branch (b, bl, b<cond>, cbz/cbnz, including tail calls) to another function is
an edge. A reachable indirect call or jump through a register (`blx rN`,
`bx rN` other than `bx lr`, `mov pc, rN`, `ldr pc, ...`) makes the proof
impossible and is reported as a failure, as is any reachable symbol of the
panic machinery (`rust_begin_unwind` — the `#[panic_handler]` —, `core::panicking::*`,
`*panic*`). `--must-reach SYM` is the positive control: SYM must reach the
panic machinery, or the checker itself is broken.

usage: panic_reach.py ELF --root SYM [--root SYM ...] [--must-reach SYM]
"""
import argparse
import re
import subprocess
import sys

FUNC = re.compile(r"^([0-9a-f]+) <(.+)>:$")
INSN = re.compile(r"^\s*([0-9a-f]+):\s+(\S+)\s*(.*)$")
TARGET = re.compile(r"<([^>+]+)(\+0x[0-9a-f]+)?>")
BRANCH = re.compile(r"^(b|bl|blx|cbz|cbnz)(eq|ne|cs|cc|hs|lo|mi|pl|vs|vc|hi|ls|ge|lt|gt|le|al)?(\.w|\.n)?$")
PANIC = re.compile(r"rust_begin_unwind|panicking|panic", re.I)


def call_graph(elf):
    dis = subprocess.run(
        ["arm-none-eabi-objdump", "-d", "-C", "--no-show-raw-insn", elf],
        check=True, capture_output=True, text=True).stdout
    edges, indirect, cur = {}, {}, None
    for line in dis.splitlines():
        m = FUNC.match(line)
        if m:
            cur = m.group(2)
            edges.setdefault(cur, set())
            continue
        m = INSN.match(line)
        if not m or cur is None:
            continue
        mnem, ops = m.group(2), m.group(3)
        if BRANCH.match(mnem):
            t = TARGET.search(ops)
            if t and t.group(1) != cur:
                edges[cur].add(t.group(1))
            if mnem.startswith("blx") and not t:
                indirect.setdefault(cur, []).append(f"{m.group(1)}: {mnem} {ops}")
        elif mnem.startswith("bx") and ops.strip() != "lr":
            indirect.setdefault(cur, []).append(f"{m.group(1)}: {mnem} {ops}")
        elif (mnem.startswith("mov") and ops.startswith("pc")) or \
             (mnem.startswith("ldr") and ops.startswith("pc")):
            indirect.setdefault(cur, []).append(f"{m.group(1)}: {mnem} {ops}")
    return edges, indirect


def reach(edges, root):
    seen, todo, parent = {root}, [root], {root: None}
    while todo:
        f = todo.pop()
        for g in edges.get(f, ()):
            if g not in seen:
                seen.add(g)
                parent[g] = f
                todo.append(g)
    return seen, parent


def path(parent, f):
    p = []
    while f is not None:
        p.append(f)
        f = parent[f]
    return " <- ".join(p)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("elf")
    ap.add_argument("--root", action="append", required=True)
    ap.add_argument("--must-reach", action="append", default=[])
    a = ap.parse_args()
    edges, indirect = call_graph(a.elf)
    ok = True
    for root in a.root:
        if root not in edges:
            print(f"FAIL {a.elf}: root {root} not in the ELF"); ok = False; continue
        seen, parent = reach(edges, root)
        bad = sorted(f for f in seen if PANIC.search(f))
        ind = {f: indirect[f] for f in seen if f in indirect}
        if bad or ind:
            ok = False
            for f in bad:
                print(f"FAIL {a.elf}: {root} reaches panic symbol: {path(parent, f)}")
            for f, sites in ind.items():
                print(f"FAIL {a.elf}: {root} reaches an indirect branch in {f}: {sites}")
        else:
            print(f"ok   {a.elf}: {root} reaches {len(seen)} functions, none panics, no indirect branch")
    for sym in a.must_reach:
        if sym not in edges:
            print(f"FAIL {a.elf}: control {sym} not in the ELF"); ok = False; continue
        seen, parent = reach(edges, sym)
        bad = [f for f in seen if PANIC.search(f)]
        if bad:
            print(f"ok   {a.elf}: control {sym} does reach the panic path ({path(parent, bad[0])})")
        else:
            print(f"FAIL {a.elf}: control {sym} should reach the panic path: the checker is blind")
            ok = False
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
