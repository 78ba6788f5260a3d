#!/usr/bin/env python3
"""Tests of scripts/robust_evidence.py (the paired figures of docs/studies/robust-designs.md).

    robust_evidence_test.py ABUOPT

r_lock against the table of the study document (docs/equilibrium_sets.md section 4's closed form); the paired
statistics of `pair` against hand-computed values on a small synthetic runs.csv (means, the paired difference's
interval, the ratio interval, Wilson %MI with the per-run threshold m_I e); the corners verdict (the issue's rule:
the two intervals apart) on 16 synthetic corners with one made worse and one better; and `pair` on two real
`abuopt montecarlo` runs of 8 draws of the same seed (a profile against itself: difference 0, ratio 1).
"""
import contextlib
import io
import math
import os
import subprocess
import sys
import tempfile

from script_check import ROOT, check, failures, load_script

ev = load_script("robust_evidence")
HEADER = "index,mu,imbalance_mass_kg,stiffness_N_per_m,ir_magnitude_kgm,ir_x_kgm,max_amplitude_mm,status\n"


def write_runs(folder, rows):
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, "runs.csv"), "w") as f:
        f.write(HEADER)
        for i, (mag, x, amp) in enumerate(rows):
            f.write(f"{i},0.03,5.6e-4,10700,{mag * 1e-7},{x * 1e-7},{amp},ok\n")


def output_of(fn, *args):
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        fn(*args)
    return buf.getvalue()


def main(abuopt):
    # r_lock(mu, k) [1e-7 kg m] as tabulated in the study document (two balls, m_I 5.6e-4 kg)
    for mu, k, want in ((0.02, 10700, 15.90), (0.03, 10700, 23.62), (0.04, 11235, 30.44), (0.02, 10165, 16.32)):
        got = ev.r_lock(mu, k, 5.6e-4) * 1e7
        check(abs(got - want) < 0.006, f"r_lock(mu {mu}, k {k}) = {got:.3f} (table {want})")

    with tempfile.TemporaryDirectory() as tmp:
        # base |I_r| = 10, 20, 30, 40; design = base - 1, -2, -3, -2 (paired differences -1, -2, -3, -2)
        base = [(10, 5, 0.5), (20, 15, 0.6), (30, 25, 0.7), (40, 35, 0.4)]
        design = [(9, 5, 0.5), (18, 15, 0.6), (27, 25, 0.65), (38, 35, 0.4)]
        write_runs(os.path.join(tmp, "b"), base)
        write_runs(os.path.join(tmp, "d"), design)
        b, d = ev.load(os.path.join(tmp, "b")), ev.load(os.path.join(tmp, "d"))
        s = ev.stats(b, d, sorted(b))
        m = s["mag"]
        check(abs(m["mb"] - 25) < 1e-9 and abs(m["md"] - 23) < 1e-9, "means 25 and 23")
        sd = math.sqrt(((1 - 2) ** 2 + 0 + (3 - 2) ** 2 + 0) / 3)  # the differences -1, -2, -3, -2: mean -2
        check(abs(m["diff"] + 2) < 1e-9 and abs(m["hdiff"] - 1.96 * sd / 2) < 1e-9, "paired difference -2 +- 1.96 sd / 2")
        lo, hi = -2 - 1.96 * sd / 2, -2 + 1.96 * sd / 2
        check(abs(m["r_lo"] - 25 / (25 + hi)) < 1e-9 and abs(m["r_hi"] - 25 / (25 + lo)) < 1e-9,
              "the ratio interval is base / (base + difference bound)")
        # %MI: threshold m_I e = 5.6e-4 x 3.7e-3 = 20.72e-7 -> base 30, 40 (2 of 4); design 27, 38 (2 of 4)
        check(abs(m["mi_b"][0] - 50) < 1e-9 and abs(m["mi_d"][0] - 50) < 1e-9, "%MI 50 % with the per-run threshold")
        p, lo_w, hi_w = ev.wilson(2, 4)
        check(abs(lo_w - 15.004) < 0.01 and abs(hi_w - 84.996) < 0.01, f"Wilson interval of 2/4: [{lo_w:.3f}, {hi_w:.3f}]")
        check(abs(s["amp_b"] - 0.7) < 1e-12 and abs(s["amp_d"] - 0.65) < 1e-12, "peak amplitude: the max over runs")
        out = output_of(ev.pair, os.path.join(tmp, "b"), os.path.join(tmp, "d"))
        check("ratio base/design 1.087" in out, "pair prints the ratio 25/23 = 1.087")

        # 16 corners: the design equal to the base but 1.5x at one corner and 0.5x at another
        rows = [(10 + (i % 5), 5, 0.5) for i in range(40)]
        n = 0
        for mu in ("0.02", "0.04"):
            for fi in ("0.5", "1.5"):
                for fk in ("0.95", "1.05"):
                    for e in ("0.5", "0.95"):
                        tail = f"_{mu}_{fi}_{fk}_{e}"
                        f = 1.5 if n == 3 else (0.5 if n == 7 else 1.0)
                        write_runs(os.path.join(tmp, "cb" + tail), rows)
                        write_runs(os.path.join(tmp, "cd" + tail), [(v * f, x, a) for v, x, a in rows])
                        n += 1
        out = output_of(ev.corners, os.path.join(tmp, "cb"), os.path.join(tmp, "cd"))
        check("worse at 1 of 16" in out and "better at 1," in out, "corners: one worse, one better, 14 overlapping")
        check(out.count("| WORSE |") == 1 and out.count("| better |") == 1, "the verdict column agrees")

        # two real runs of the same config and seed: a profile against itself
        cfg = os.path.join(ROOT, "configs", "studies", "robust", "mc_2003_full.yaml")
        for name in ("r1", "r2"):
            r = subprocess.run([abuopt, "montecarlo", cfg, "--runs", "8", "--threads", "1", "--out",
                                os.path.join(tmp, name)], capture_output=True, text=True)
            check(r.returncode == 0, f"abuopt montecarlo {name} runs")
        out = output_of(ev.pair, os.path.join(tmp, "r1"), os.path.join(tmp, "r2"))
        check("paired runs: 8" in out and "difference +0.00 [+0.00, +0.00]" in out and "1.000 [1.000, 1.000]" in out,
              "the same draws twice: difference 0, ratio 1")
        out = output_of(ev.depth, os.path.join(tmp, "r1"))
        check("(8) |" in out, "depth reads a real runs.csv")

    if failures:
        print(f"{len(failures)} check(s) failed")
        sys.exit(1)


if __name__ == "__main__":
    main(sys.argv[1])
