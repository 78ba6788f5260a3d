#!/usr/bin/env python3
"""Tests of scripts/stop_depth_study.py (the stop-depth measurement of docs/studies/startup-profile.md 8.1).

    stop_depth_test.py ABUOPT

The closed forms the runner divides by are checked against the simulator's own numbers: r_in(f, mu)
against the `r_in` column of `abuopt eqset --scan` (docs/equilibrium_sets.md section 4) at several
speeds and two frictions, r_lock against its published 15.90e-7 kg m and as the minimum of r_in over
f; the profile's frequency at time t against the inclined-sine closed form at the segment ends and
middles; and a tiny case (8 runs) runs through abuopt and gives statistics consistent with runs.csv.
"""
import csv
import os
import subprocess
import sys
import tempfile
import types

from script_check import ROOT, check, failures, load_script

sd = load_script("stop_depth_study")


def main(abuopt):
    for mu in (0.02, 0.03):
        r = subprocess.run([abuopt, "eqset", os.path.join(ROOT, "configs", "eqset.yaml"), "--scan", "27:31:0.25",
                            "--grid", "8", "--mu", str(mu)], capture_output=True, text=True)
        check(r.returncode == 0, f"abuopt eqset --scan at mu {mu} runs")
        rows = [l.split() for l in r.stdout.splitlines() if l.strip() and not l.lstrip().startswith("#")
                and l.split()[0][0].isdigit()]
        check(len(rows) == 17, f"17 frequencies scanned at mu {mu}")
        for row in rows:
            f, rin = float(row[0]), float(row[2])
            mine = sd.r_in(f, mu)
            check(abs(mine - rin) <= 5e-4 * rin + 0.006, f"r_in({f} Hz, mu {mu}) = {mine:.3f} (eqset {rin})")
    check(abs(sd.r_lock(0.02) - 15.90) < 0.005, f"r_lock(0.02) = {sd.r_lock(0.02):.4f} (published 15.90)")
    check(abs(sd.r_lock(0.03) - 23.62) < 0.005, f"r_lock(0.03) = {sd.r_lock(0.03):.4f} (section 8.5: 23.62)")
    scan = min(sd.r_in(28 + k * 1e-4, 0.02) for k in range(20001))
    check(abs(scan - sd.r_lock(0.02)) < 1e-6 * sd.r_lock(0.02), "r_lock is the minimum of r_in over f")
    segs = sd.segments("down", 28.85, 2.0)
    check(segs == [(25.0, 1.0), (30.0, 5.0), (28.85, 2.0), (28.85, 6.0), (100.0, 4.3)], "the down profile's segments")
    check(abs(sd.frequency_at(segs, 1.0) - 25.0) < 1e-12 and abs(sd.frequency_at(segs, 0.5) - 12.5) < 1e-12
          and abs(sd.frequency_at(segs, 7.0) - 29.425) < 1e-12 and abs(sd.frequency_at(segs, 10.0) - 28.85) < 1e-12,
          "frequency_at: segment ends and middles (an inclined sine is at half height in its middle)")
    with tempfile.TemporaryDirectory() as tmp:
        a = types.SimpleNamespace(out=tmp, abuopt=abuopt, runs=8, seed=5, threads=1, nice=0)
        row = sd.run_case(a, "up", 29.0, 1.0, 0.02)
        runs = list(csv.DictReader(open(os.path.join(tmp, "up_f29_D1_mu0.02", "runs.csv"))))
        ir = [float(r["ir_magnitude_kgm"]) / 1e-7 for r in runs if r["status"] == "ok"]
        check(row["runs"] == len(ir) == 8, "a case of 8 runs: 8 ok runs")
        check(abs(row["mean"] - sum(ir) / len(ir)) < 1e-12 and
              abs(row["mean_over_rlock"] - sum(ir) / len(ir) / sd.r_lock(0.02)) < 1e-12,
              "the case's mean and mean / r_lock are those of runs.csv")
        again = sd.run_case(a, "up", 29.0, 1.0, 0.02)  # resumed: kept, same numbers
        check(again["mean"] == row["mean"], "a finished case is kept and gives the same numbers")
    # The release family: the step at the acceleration limit (an inclined sine peaks at 2 H / D), the fold of the
    # 1-D Coulomb oscillator, and a tiny case paired run by run with the state at the end of the dwell at f_1.
    segs = sd.release_segments([29.45, 28.9], [3.0, 6.0], 3.0, 0.0)
    check(segs[:3] == [(25.0, 1.0), (29.45, 3.0), (29.45, 3.0)] and segs[4:] == [(28.9, 6.0), (100.0, 4.3)]
          and segs[3][0] == 28.9 and abs(2 * 0.55 / segs[3][1] - sd.MAX_RATE_HZ_S) < 1e-9,
          f"release: the step 29.45 -> 28.9 Hz takes 2 x 0.55 / {sd.MAX_RATE_HZ_S:.3f} s ({segs[3][1]:.4f} s)")
    stairs = sd.release_segments([30.5, 29.45, 28.9], [2.0, 2.0, 6.0], 0.25, 0.4)
    check([f for f, _ in stairs] == [25.0, 30.5, 30.5, 29.45, 29.45, 28.9, 28.9, 100.0]
          and [d for _, d in stairs][3:7] == [0.4, 2.0, 0.4, 6.0], "release: a staircase of two steps")
    with tempfile.TemporaryDirectory() as tmp:
        a = types.SimpleNamespace(out=tmp, abuopt=abuopt, runs=8, seed=5, threads=1, nice=0, dwell2=2.0)
        row = sd.run_release(a, [29.45, 28.9], 0.25, 1.0, 0.0, 0.02)
        rin1, rin2 = sd.r_in(29.45, 0.02), sd.r_in(28.9, 0.02)
        check(abs(row["predicted_fold_over_rlock"] - abs(2 * rin2 - rin1) / sd.r_lock(0.02)) < 1e-12
              and abs(row["q"] - rin1 / rin2) < 1e-12, "release: the fold |2 r_in(f_2) - r_in(f_1)| and q")
        probe = os.path.join(tmp, "probe_29.45_a0.25_t1_mu0.02")
        cfg = open(os.path.join(probe, "config.yaml")).read()
        check("end_time_s: 2.25\n" in cfg and "duration_s: 1}" in cfg and "end_frequency_hz: 28.9" not in cfg,
              "release: the probe is the profile cut at the end of the dwell at f_1 (t = 1 + 0.25 + 1 s)")
        full = list(csv.DictReader(open(os.path.join(tmp, "rel_29.45_28.9_a0.25_t1_s0_mu0.02", "runs.csv"))))
        cut = list(csv.DictReader(open(os.path.join(probe, "runs.csv"))))
        check(len(full) == len(cut) == 8 and all(x["beta0_1"] == y["beta0_1"] and x["beta0_2"] == y["beta0_2"]
                                                 for x, y in zip(full, cut)),
              "release: the probe runs the same starts, run by run")
        u1 = [float(x["ir_magnitude_kgm"]) / 1e-7 for x in cut]
        check(abs(row["share_collected"] - sum(1 for u in u1 if u >= 0.9 * rin1) / 8) < 1e-12,
              f"release: the collected share is that of the probe's runs ({row['share_collected']:.3f})")
        again = sd.run_release(a, [29.45, 28.9], 0.25, 1.0, 0.0, 0.02)
        check(again["mean"] == row["mean"], "release: a finished case is kept and gives the same numbers")
    if failures:
        print(f"{len(failures)} check(s) failed")
        sys.exit(1)


if __name__ == "__main__":
    main(sys.argv[1])
