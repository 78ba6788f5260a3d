#!/usr/bin/env python3
"""Optuna (TPE or its CMA-ES sampler) on a problem of an `abuopt compare` config, writing runs that
`compare` reads beside its own methods.

  python3 examples/python/optuna_study.py CONFIG --problem LABEL --out DIR
        [--sampler tpe|cmaes] [--trials N] [--batch B] [--threads T]

CONFIG is a compare config (configs/compare/*.yaml); LABEL one of its problems (a startup_profile
entry or a plain analytic benchmark). For each start k of that problem (its `starts`; seed + k is the
sampler's seed) the run's evaluations go to DIR/<LABEL>/start<k>.csv:
  evaluation,ok,objective,max_violation,<variables>
and a compare config lists the directory as a solver: `- {label: Optuna-TPE, external: DIR}`.
Trials default to the problem's max_evaluations (the same budget as every other method); each run's
first trial is the problem's starting point. B trials are asked at once and evaluated as one batch
(abuopt.BatchProblem; B = 1: sequential TPE, as Optuna's default). Constraints: TPE takes them as
Optuna's constraints_func (feasible when every value <= 0); the CMA-ES sampler has none, so it gets
Deb's feasibility rules as one value, as abuopt's pagmo methods do: f when feasible, else
1e30 (1 + violation). Without Optuna (Debian: python3-optuna) it says so and exits 0.
"""
import argparse
import csv
import os
import re
import sys

import numpy as np

from _find_abuopt import import_abuopt

abuopt = import_abuopt()


def file_safe(label):
    return re.sub(r"[^A-Za-z0-9_-]", "_", label)


def load_problem(config, label, batch_threads):
    import yaml
    with open(config) as f:
        cfg = yaml.safe_load(f)
    entries = cfg.get("problems") or []
    for e in entries:
        name = e.get("label") or e.get("benchmark") or "startup_profile"
        if e.get("benchmark") == "rosenbrock" and "label" not in e:
            name = f"rosenbrock{e.get('dimension', 2)}"
        if name != label:
            continue
        if "startup_profile" in e:
            problem = abuopt.BatchProblem(e["startup_profile"], batch_threads=batch_threads)
        else:
            extra = set(e) - {"benchmark", "label", "max_evaluations", "starts", "seed", "constraint_tolerance", "f_star"}
            if extra:
                sys.exit(f"{config}: problem {label}: {sorted(extra)} not supported here (plain benchmarks only)")
            problem = abuopt.BatchProblem.benchmark(e["benchmark"])
        return problem, e
    labels = [e.get("label") or e.get("benchmark") for e in entries]
    sys.exit(f"{config}: no problem labelled {label!r} (problems: {labels})")


def run(problem, sampler_name, seed, trials, batch, tol, x0):
    import warnings
    import optuna
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    warnings.filterwarnings("ignore", category=optuna.exceptions.ExperimentalWarning)  # constraints_func
    names = problem.names
    lo, hi = np.asarray(problem.lower), np.asarray(problem.upper)
    violations = {}

    def constraints(trial):
        return trial.user_attrs["constraints"]

    if sampler_name == "tpe":
        sampler = optuna.samplers.TPESampler(seed=seed, constraints_func=constraints)
    else:
        sampler = optuna.samplers.CmaEsSampler(seed=seed, x0=dict(zip(names, x0)),
                                               sigma0=0.3 * float(np.min(hi - lo)))
    study = optuna.create_study(direction="minimize", sampler=sampler)
    study.enqueue_trial(dict(zip(names, x0)))
    rows = []
    while len(rows) < trials:
        k = min(batch, trials - len(rows))
        asked = [study.ask() for _ in range(k)]
        X = np.array([[t.suggest_float(n, lo[i], hi[i]) for i, n in enumerate(names)] for t in asked])
        r = problem.evaluate(X)
        for i, t in enumerate(asked):
            ok = bool(r["ok"][i])
            f = float(r["objective"][i])
            v = float(r["max_violation"][i])
            g = list(r["inequality"][i]) + [abs(h) - tol for h in r["equality"][i]]
            t.set_user_attr("constraints", [float(c) if ok else 1e30 for c in g] or [0.0])
            if sampler_name == "tpe":
                value = f if ok else 1e30
            else:
                value = f if ok and v <= tol else (1e30 * (1 + min(v, 1e250)) if ok else 1e300)
            study.tell(t, value)
            rows.append((len(rows) + 1, int(ok), f, v, *X[i]))
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("config")
    ap.add_argument("--problem", required=True, help="the label of a problem of the compare config")
    ap.add_argument("--out", required=True, help="directory of the runs (a compare solver's `external:`)")
    ap.add_argument("--sampler", choices=["tpe", "cmaes"], default="tpe")
    ap.add_argument("--trials", type=int, help="evaluations per run (default: the problem's max_evaluations)")
    ap.add_argument("--batch", type=int, default=1, help="trials asked and evaluated at once")
    ap.add_argument("--threads", type=int, default=1, help="designs of a batch evaluated at once")
    a = ap.parse_args()
    try:
        import optuna  # noqa: F401
    except ImportError:
        print("Optuna is not installed (Debian: python3-optuna): nothing to do")
        return 0
    problem, entry = load_problem(a.config, a.problem, a.threads)
    budget = int(entry.get("max_evaluations", 200))
    trials = a.trials or budget
    if not 1 <= trials <= budget:
        sys.exit(f"--trials {trials}: must be in [1, {budget}] (the problem's max_evaluations)")
    if a.batch < 1:
        sys.exit(f"--batch {a.batch}: must be >= 1")
    starts, seed = int(entry.get("starts", 1)), int(entry.get("seed", 1))
    tol = float(entry.get("constraint_tolerance", 1e-6))
    out = os.path.join(a.out, file_safe(a.problem))
    os.makedirs(out, exist_ok=True)
    # start 0 from the problem's starting point; the other starts from compare's random points are not
    # reproduced here (Optuna samples its own), so their first trial is the problem's point too
    for k in range(starts):
        rows = run(problem, a.sampler, seed + k, trials, a.batch, tol, problem.x0)
        path = os.path.join(out, f"start{k}.csv")
        with open(path + ".tmp", "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["evaluation", "ok", "objective", "max_violation", *problem.names])
            for row in rows:
                w.writerow([row[0], row[1], *(repr(float(v)) for v in row[2:])])
        os.replace(path + ".tmp", path)
        feasible = [r[2] for r in rows if r[1] and r[3] <= tol]
        best = min(feasible) if feasible else float("nan")
        print(f"{a.sampler} on {a.problem} start {k} (seed {seed + k}): {len(rows)} evaluations, "
              f"best feasible f = {best:.6g} -> {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
