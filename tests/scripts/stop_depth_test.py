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
import importlib.util
import os
import subprocess
import sys
import tempfile
import types

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
spec = importlib.util.spec_from_file_location("stop_depth_study", os.path.join(ROOT, "scripts", "stop_depth_study.py"))
sd = importlib.util.module_from_spec(spec)
spec.loader.exec_module(sd)
failures = []


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        failures.append(what)


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
    if failures:
        print(f"{len(failures)} check(s) failed")
        sys.exit(1)


if __name__ == "__main__":
    main(sys.argv[1])
