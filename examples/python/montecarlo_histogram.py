#!/usr/bin/env python3
"""Monte Carlo of the 2003 report's final startup profile into a histogram of the residual imbalance.

  python3 examples/python/montecarlo_histogram.py [CONFIG] [--runs N] [--design D] [--seed S] [--out PNG]

Default: configs/montecarlo_final_profile.yaml with its 32 x 32 grid of initial ball angles (1024 runs,
the report's table 4.4). With matplotlib (Debian: python3-matplotlib) it writes a PNG of |I_r| and
I_r,x with the %MI threshold (the imbalance without balls) marked; without it, a text histogram.
ABUOPT_QUICK=1 runs 64 LHS runs instead (the test suite's setting).
"""
import argparse
import os
import sys

import numpy as np

from _find_abuopt import REPO, import_abuopt

abuopt = import_abuopt()


def text_histogram(values, edges, width=50):
    counts, _ = np.histogram(values, bins=edges)
    top = max(counts.max(), 1)
    for c, lo, hi in zip(counts, edges[:-1], edges[1:]):
        print(f"  {lo:6.2f} .. {hi:6.2f} | {'#' * round(width * c / top):<{width}} {c}")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("config", nargs="?", default=os.path.join(REPO, "configs", "montecarlo_final_profile.yaml"))
    ap.add_argument("--runs", type=int)
    ap.add_argument("--design")
    ap.add_argument("--seed", type=int)
    ap.add_argument("--threads", type=int)
    ap.add_argument("--out", default=os.path.join(REPO, "results", "python", "montecarlo_histogram.png"))
    a = ap.parse_args()
    if os.environ.get("ABUOPT_QUICK") and a.runs is None:
        a.runs, a.design = 64, a.design or "lhs"

    mc = abuopt.montecarlo(a.config, runs=a.runs, design=a.design, seed=a.seed, threads=a.threads)
    s = mc["summary"]
    ok = mc["ok"]
    ir = mc["residual_imbalance"][ok] * 1e7     # 1e-7 kg m, as the report's tables
    irx = mc["residual_imbalance_x"][ok] * 1e7
    threshold = float(np.median(mc["imbalance_kgm"])) * 1e7
    print(f"{a.config}: {s['runs']} runs, {s['ok']} ok, {s['wall_time_s']:.2f} s")
    for name, key in [("|I_r|", "magnitude"), ("I_r,x", "report_x")]:
        m = s[key]
        lo, hi = m["pct_mi_ci95"]
        print(f"  {name}: mean {m['mean'] * 1e7:.3f}e-7 kg m, max {m['max'] * 1e7:.3f}e-7 kg m, "
              f"%MI {m['pct_mi']:.2f} % (95 % interval {lo:.2f} .. {hi:.2f} %)")
    print("  %MI: percentage of runs whose residual imbalance exceeds the imbalance without balls "
          f"({threshold:.2f}e-7 kg m)")

    edges = np.linspace(0.0, max(ir.max(), irx.max(), threshold) * 1.05, 31)
    try:
        import matplotlib
        matplotlib.use(os.environ.get("MPLBACKEND", "Agg"))
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed (Debian: python3-matplotlib): text histogram of |I_r| [1e-7 kg m] instead")
        text_histogram(ir, edges)
        return 0
    fig, ax = plt.subplots(figsize=(7, 4.5), constrained_layout=True)
    ax.hist([ir, irx], bins=edges, label=[r"$|I_r|$", r"$I_{r,x}$ (report eq. 4.2)"], color=["#3b6ea5", "#e8a33d"])
    ax.axvline(threshold, color="k", ls="--", lw=1, label=f"imbalance without balls ({threshold:.2f})")
    ax.set_xlabel(r"residual imbalance [$10^{-7}$ kg m]")
    ax.set_ylabel("runs")
    ax.set_title(f"residual imbalance, {s['runs']} runs")
    ax.legend()
    os.makedirs(os.path.dirname(os.path.abspath(a.out)), exist_ok=True)
    fig.savefig(a.out, dpi=120)
    print(f"wrote {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
