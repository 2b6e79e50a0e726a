"""Table, fitted exponent and PNG of bench/sthb_scaling.sh (see there).

Input: JSON lines {"solver", "modes", "harmonics", "points", "jacobians",
"cpu_s", "wall_s"} (a baseline line may carry "timeout_s" instead).
Fits log(CPU per point) = a + b log(N·M) by least squares over the sizes of
each solver and prints a Markdown table.
"""
import argparse
import json

import numpy as np


def fit(rows):
    """Exponent b and prefactor of CPU-per-point ∝ (N·M)^b."""
    x = np.log([r["modes"] * r["harmonics"] for r in rows])
    y = np.log([r["cpu_s"] / r["points"] for r in rows])
    b, a = np.polyfit(x, y, 1)
    return b, np.exp(a)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("lines")
    ap.add_argument("--json", required=True)
    ap.add_argument("--png", required=True)
    args = ap.parse_args()
    rows = [json.loads(l) for l in open(args.lines) if l.strip()]
    done = {s: [r for r in rows if r["solver"] == s and "cpu_s" in r] for s in ("sthb", "baseline")}
    fits = {s: fit(r) for s, r in done.items() if len(r) >= 2}
    json.dump({"rows": rows, "fits": {s: {"exponent": b, "prefactor": a} for s, (b, a) in fits.items()}},
              open(args.json, "w"), indent=1)
    base = {(r["modes"], r["harmonics"]): r for r in rows if r["solver"] == "baseline"}
    print("| N × M | N·M | points | CPU whole curve | CPU per point | before issue 28: CPU whole curve (per point) |")
    print("|---|---|---|---|---|---|")
    for r in done["sthb"]:
        key = (r["modes"], r["harmonics"])
        b = base.get(key)
        if b is None:
            old = "—"
        elif "cpu_s" in b:
            old = f"{b['cpu_s']:.2f} s ({1e3 * b['cpu_s'] / b['points']:.1f} ms)"
        else:
            old = f"> {b['timeout_s']} s (cut)"
        print(f"| {key[0]} × {key[1]} | {key[0] * key[1]} | {r['points']} | {r['cpu_s']:.2f} s "
              f"| {1e3 * r['cpu_s'] / r['points']:.2f} ms | {old} |")
    for s, (b, _) in fits.items():
        print(f"\n{s}: CPU per point ∝ (N·M)^{b:.2f} over N·M = "
              f"{min(r['modes'] * r['harmonics'] for r in done[s])}–{max(r['modes'] * r['harmonics'] for r in done[s])}")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    colors = {5: "tab:blue", 10: "tab:green", 20: "tab:red"}
    for s, style, label in (("sthb", "o-", "this tree"), ("baseline", "s--", "before issue 28")):
        for n in sorted({r["modes"] for r in done[s]}):
            rs = sorted((r for r in done[s] if r["modes"] == n), key=lambda r: r["harmonics"])
            nm = np.array([n * r["harmonics"] for r in rs])
            per = np.array([1e3 * r["cpu_s"] / r["points"] for r in rs])
            ax.loglog(nm, per, style, color=colors.get(n), label=f"{label}, N = {n} (M = "
                      + ", ".join(str(r["harmonics"]) for r in rs) + ")")
        if s in fits:
            b, a = fits[s]
            x = np.array([40.0, 800.0])
            ax.loglog(x, 1e3 * a * x ** b, ":", color="gray" if s == "sthb" else "orange",
                      label=f"{label}: fit over all sizes ∝ (N·M)^{b:.2f}")
    ax.set_xlabel("N·M (modes × harmonics)")
    ax.set_ylabel("CPU ms per curve point (with stability)")
    ax.set_title("STHB string, whole curve ω 1–6, k_d = 10")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(args.png, dpi=120)


if __name__ == "__main__":
    main()
