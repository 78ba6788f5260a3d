#!/usr/bin/env python3
"""Test of abuopt.BatchProblem (python/src/problem_bindings.cpp) and examples/python/optuna_study.py
(run by ctest as package_python_batch; no pytest needed). Exit 77 (skipped) without the module or NumPy.

  PYTHONPATH=build/python python3 python/tests/test_problem_bindings.py --cli build/app/abuopt --source . --work /tmp/t
"""
import argparse
import csv
import math
import os
import subprocess
import sys

SKIP = 77


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cli", required=True)
    ap.add_argument("--source", required=True)
    ap.add_argument("--work", required=True)
    a = ap.parse_args()
    try:
        import numpy as np
        import abuopt
    except ImportError as e:
        print(f"SKIP: {e}")
        return SKIP
    os.makedirs(a.work, exist_ok=True)
    failures = []

    def check(cond, what):
        print(("ok   " if cond else "FAIL ") + what)
        if not cond:
            failures.append(what)

    # 1. An analytic benchmark as a batch: hs071 at its known optimum and at a corner.
    p = abuopt.BatchProblem.benchmark("hs071")
    check(p.names == ["x1", "x2", "x3", "x4"] and list(p.lower) == [1] * 4, "hs071 names and bounds")
    X = np.array([[1.0, 4.74299963, 3.82114998, 1.37940829], [1, 1, 1, 1], [5, 5, 5, 5]])
    r = p.evaluate(X)
    check(r["objective"].shape == (3,) and r["inequality"].shape == (3, 1) and r["equality"].shape == (3, 1),
          f"shapes {r['objective'].shape} {r['inequality'].shape} {r['equality'].shape}")
    check(abs(r["objective"][0] - 17.0140173) < 1e-5, f"f at the optimum {r['objective'][0]} = 17.0140173 +- 1e-5")
    check(r["objective"][1] == 1 * 1 * 3 + 1, f"f(1,1,1,1) = {r['objective'][1]} = 4")
    check(abs(r["max_violation"][0]) < 1e-6 and r["max_violation"][1] > 0, "violation: 0 at the optimum, > 0 at (1,1,1,1)")
    check(bool(r["ok"].all()), "every evaluation ok")
    check(p.evaluations == 3 and abs(p.best_known - 17.0140173) < 1e-5, "evaluations counted, best_known")
    r2 = p(X[::-1].copy())
    check(list(r2["objective"]) == list(r["objective"][::-1]), "row order is kept")
    for bad, what in ((np.zeros((2, 3)), "(n, 3) for 4 variables"), (np.full((1, 4), 9.0), "outside the bounds")):
        try:
            p.evaluate(bad)
            check(False, f"ConfigError for {what}")
        except abuopt.ConfigError as e:
            check(True, f"ConfigError for {what}: {e}")

    # 2. The startup-profile problem: a batch of two designs agrees with StartupProfileProblem one by one.
    cfg = os.path.join(a.source, "configs", "optimize", "cobyla.yaml")
    bp = abuopt.BatchProblem(cfg, runs=8, threads=1, batch_threads=2)
    sp = abuopt.StartupProfileProblem(cfg, runs=8, threads=1)
    x0 = np.array(bp.x0)
    X = np.array([x0, x0 * 0.5 + np.asarray(bp.lower) * 0.5])
    r = bp.evaluate(X)
    for i in range(2):
        one = sp.evaluate(list(X[i]))
        check(r["objective"][i] == one["objective"], f"design {i}: batch f {r['objective'][i]} == one by one {one['objective']}")
        check(list(r["inequality"][i]) == list(one["constraints"]), f"design {i}: constraints equal")
    v = bp.validate(X[:1])
    check(v["objective"].shape == (1,) and math.isfinite(v["objective"][0]), f"out of sample f = {v['objective'][0]}")

    # 3. optuna_study.py on hs071 (a plain benchmark of a compare config), read back by compare.
    out = os.path.join(a.work, "optuna")
    script = os.path.join(a.source, "examples", "python", "optuna_study.py")
    cfg = os.path.join(a.work, "compare.yaml")
    with open(cfg, "w") as f:
        f.write("problems:\n  - {benchmark: hs071, max_evaluations: 20, starts: 2, seed: 5, constraint_tolerance: 1.0e-2}\n"
                f"solvers:\n  - {{label: COBYLA, algorithm: cobyla}}\n  - {{label: TPE, external: {out}}}\n")
    res = subprocess.run([sys.executable, script, cfg, "--problem", "hs071", "--out", out, "--batch", "4"],
                         capture_output=True, text=True)
    print(res.stdout, res.stderr)
    check(res.returncode == 0, f"optuna_study.py exits 0 ({res.returncode})")
    if "not installed" not in res.stdout:
        with open(os.path.join(out, "hs071", "start1.csv")) as f:
            rows = list(csv.DictReader(f))
        check(len(rows) == 20 and rows[0]["evaluation"] == "1", f"20 evaluations written ({len(rows)})")
        check([float(rows[0][n]) for n in ("x1", "x2", "x3", "x4")] == [1, 5, 5, 1], "the first trial is hs071's start")
        res = subprocess.run([a.cli, "compare", cfg, "--out", os.path.join(a.work, "cmp")], capture_output=True, text=True)
        print(res.stdout[-2000:], res.stderr[-2000:])
        check(res.returncode == 0, f"compare reads the Optuna runs (exit {res.returncode})")
        with open(os.path.join(a.work, "cmp", "runs.csv")) as f:
            runs = [r for r in csv.DictReader(f) if r["solver"] == "TPE"]
        check(len(runs) == 2 and all(r["evaluations"] == "20" for r in runs), "both TPE runs in runs.csv")
    print(f"{len(failures)} failures")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
