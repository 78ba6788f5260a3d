#!/usr/bin/env python3
"""The startup-profile problem of configs/optimize/cobyla.yaml solved with SciPy's COBYLA.

  python3 examples/python/scipy_cobyla.py [CONFIG] [--runs N] [--maxiter K] [--seed S]

abuopt.StartupProfileProblem gives the objective (mean |I_r| in 1e-7 kg m over the Monte Carlo
runs), the constraints g(x) <= 0 (startup time, %MI, amplitude) and the bounds; SciPy works on the
variables scaled to [0, 1] by their bounds (COBYLA has one step length for all variables), the bounds
as inequality constraints (SciPy 1.10's COBYLA takes no bounds). Every design is evaluated on the
same initial ball angles (common random numbers), so the objective is a deterministic function.
Default: 64 runs per evaluation and at most 40 evaluations (a few minutes on 2 cores); the
config's 128 runs and more evaluations give a sharper answer. ABUOPT_QUICK=1: 8 runs, 8 evaluations.
Without SciPy (Debian: python3-scipy) it says so and exits 0.
"""
import argparse
import os
import sys
import time

import numpy as np

from _find_abuopt import REPO, import_abuopt

abuopt = import_abuopt()


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("config", nargs="?", default=os.path.join(REPO, "configs", "optimize", "cobyla.yaml"))
    ap.add_argument("--runs", type=int, default=64, help="Monte Carlo runs per evaluation")
    ap.add_argument("--maxiter", type=int, default=40, help="COBYLA's evaluation budget")
    ap.add_argument("--seed", type=int, help="seed of the initial ball angles (default: the config's)")
    ap.add_argument("--threads", type=int)
    a = ap.parse_args()
    if os.environ.get("ABUOPT_QUICK"):
        a.runs, a.maxiter = 8, 8
    try:
        from scipy.optimize import minimize
    except ImportError:
        print("SciPy is not installed (Debian: python3-scipy): nothing to do; the problem itself is "
              "available as abuopt.StartupProfileProblem")
        return 0

    problem = abuopt.StartupProfileProblem(a.config, runs=a.runs, seed=a.seed, threads=a.threads)
    lo = np.array([b[0] for b in problem.bounds])
    hi = np.array([b[1] for b in problem.bounds])

    def x_of(z):  # scaled -> physical, clipped into the bounds (COBYLA may step slightly outside)
        return np.clip(lo + np.asarray(z) * (hi - lo), lo, hi)

    def objective(z):
        return problem.evaluate(x_of(z))["objective"]

    def constraints(z):  # SciPy: feasible when >= 0; abuopt: g(x) <= 0. The same x: no second Monte Carlo.
        return -problem.evaluate(x_of(z))["constraints"]

    z0 = (np.array(problem.x0) - lo) / (hi - lo)
    start = problem.evaluate(problem.x0)
    print(f"{problem.identity}: variables {problem.names}, constraints {problem.constraint_names}, {a.runs} runs")
    print(f"start  x0 = {np.round(problem.x0, 4).tolist()}: objective {start['objective']:.4f} (mean |I_r|, 1e-7 kg m), "
          f"g = {np.round(start['constraints'], 4).tolist()}")
    t = time.time()
    res = minimize(objective, z0, method="COBYLA",
                   constraints=[{"type": "ineq", "fun": constraints},
                                {"type": "ineq", "fun": lambda z: np.asarray(z)},
                                {"type": "ineq", "fun": lambda z: 1.0 - np.asarray(z)}],
                   options={"rhobeg": 0.15, "maxiter": a.maxiter, "tol": 1e-3})
    x = x_of(res.x)
    best = problem.evaluate(x)
    feasible = bool(best["ok"] and np.all(best["constraints"] <= 1e-6))
    print(f"COBYLA: {res.message} ({problem.evaluations} Monte Carlo evaluations, {time.time() - t:.1f} s)")
    print(f"best   x  = {np.round(x, 4).tolist()}: objective {best['objective']:.4f}, "
          f"g = {np.round(best['constraints'], 4).tolist()} ({'feasible' if feasible else 'INFEASIBLE'})")
    m = best["metrics"]
    print(f"       startup time {m['startup_time_s']:.3f} s, %MI {m['pct_mi']:.2f} %, "
          f"peak amplitude {m['amplitude_max_mm']:.4f} mm (in-sample: {a.runs} runs; validate out of sample "
          f"with `abuopt optimize` or abuopt.montecarlo)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
