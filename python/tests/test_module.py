#!/usr/bin/env python3
"""Test of the Python module abuopt (run by ctest as package_python; no pytest needed).

Checks that the module gives the command line's numbers (the same library functions on the same
inputs must agree to the last bit), the shapes of the Monte Carlo arrays, the ConfigError messages,
and runs the examples in quick mode. Exit 77 (ctest: skipped) when the module or NumPy is absent.

  PYTHONPATH=build/python python3 python/tests/test_module.py --cli build/app/abuopt --source . --work /tmp/t
"""
import argparse
import json
import math
import os
import subprocess
import sys

SKIP = 77


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cli", required=True, help="the abuopt executable")
    ap.add_argument("--source", required=True, help="the source tree (configs/, examples/)")
    ap.add_argument("--work", required=True, help="scratch directory")
    a = ap.parse_args()
    try:
        import numpy as np
    except ImportError:
        print(f"SKIP: numpy is not installed for {sys.executable} (Debian: python3-numpy)")
        return SKIP
    try:
        import abuopt
    except ImportError as e:
        print(f"SKIP: the module abuopt cannot be imported ({e}); PYTHONPATH={os.environ.get('PYTHONPATH')}")
        return SKIP
    os.makedirs(a.work, exist_ok=True)
    cfg = os.path.join(a.source, "configs", "montecarlo_final_profile.yaml")
    failures = []

    def check(cond, what):
        print(("ok    " if cond else "FAIL  ") + what)
        if not cond:
            failures.append(what)

    def cli_json(*args):
        r = subprocess.run([a.cli, *args, "--json"], capture_output=True, text=True)
        if r.returncode != 0:
            raise RuntimeError(f"abuopt {' '.join(args)} exited {r.returncode}: {r.stderr}")
        return json.loads(r.stdout)

    # 1. simulate: the same start as `abuopt simulate`, the same numbers (exact: same code, same input).
    beta0 = [0.5, 2.0]
    py = abuopt.simulate(cfg, beta0=beta0)
    cli = cli_json("simulate", cfg, "--beta0", "0.5,2.0")
    for key in ["status", "beta_final", "residual_imbalance", "residual_imbalance_x", "imbalance_without_balls",
                "settled", "settling_time", "max_amplitude_mm", "events", "steps", "rhs_evaluations", "end_time_s"]:
        same = np.array_equal(py[key], cli[key]) if isinstance(py[key], np.ndarray) else py[key] == cli[key]
        check(same, f"simulate {key}: module {py[key]} == CLI {cli[key]}")
    check(isinstance(py["beta_final"], np.ndarray) and isinstance(py["beta0"], np.ndarray),
          "simulate returns arrays (beta0, beta_final) as montecarlo does")

    # 2. The same config as a dict (what the YAML file holds) gives the same run.
    config_dict = {
        "abu": {"table_mass_kg": 0.324, "damping_Ns_per_m": 1.28, "stiffness_N_per_m": 1.07e4,
                "ball_track_radius_m": 1.15e-2, "imbalance_mass_kg": 5.6e-4, "eccentricity_m": 3.7e-3,
                "friction_mu": 0.02,
                "balls": [{"mass_kg": 1.4e-4, "diameter_m": 3.0e-3}, {"mass_kg": 1.4e-4, "diameter_m": 3.0e-3}]},
        "profile": {"start_frequency_hz": 0, "segments": [
            {"end_frequency_hz": 25.0, "duration_s": 1.0}, {"end_frequency_hz": 29.5, "duration_s": 10.0},
            {"end_frequency_hz": 100.0, "duration_s": 8.0}]},
        "motor": {"kind": "ideal"},
        "simulation": {"method": "event_driven", "rtol": 1.0e-6},
        "montecarlo": {"design": "grid", "grid": 32, "runs": 1024, "seed": 1, "threads": 0,
                       "friction": {"fixed": 0.02}},
    }
    pyd = abuopt.simulate(config_dict, beta0=np.array(beta0))
    check(pyd["residual_imbalance"] == py["residual_imbalance"] and np.array_equal(pyd["beta_final"], py["beta_final"]),
          "simulate(dict) == simulate(YAML path)")

    # 3. Bad input: abuopt.ConfigError (a ValueError) naming the key, value and rule.
    def error_of(fn):
        try:
            fn()
        except abuopt.ConfigError as e:
            return e
        return None

    bad = json.loads(json.dumps(config_dict))
    bad["profile"]["segments"][1]["duration_s"] = -2
    e = error_of(lambda: abuopt.simulate(bad, beta0=beta0))
    check(e is not None and isinstance(e, ValueError) and "profile.segments[1].duration_s = -2" in str(e),
          f"ConfigError for a negative duration names the key: {e}")
    bad = json.loads(json.dumps(config_dict))
    bad["abu"]["frictoin_mu"] = 0.02
    e = error_of(lambda: abuopt.simulate(bad, beta0=beta0))
    check(e is not None and "abu.frictoin_mu" in str(e), f"ConfigError for an unknown key names it: {e}")
    e = error_of(lambda: abuopt.montecarlo(cfg, runs=0, design="random"))
    check(e is not None and "montecarlo.runs" in str(e), f"ConfigError for runs=0 names montecarlo.runs: {e}")
    e = error_of(lambda: abuopt.simulate(cfg, beta0=[0.1]))
    check(e is not None and "beta0" in str(e), f"ConfigError for one angle of two balls: {e}")
    r = subprocess.run([a.cli, "simulate", cfg, "--beta0", "0.1"], capture_output=True, text=True)
    check(r.returncode == 2, "the CLI rejects the same beta0 (exit 2)")
    try:
        abuopt.simulate({"abu": {"friction_mu": object()}}, beta0=beta0)
        check(False, "a non-YAML value in a dict config is a TypeError")
    except TypeError as t:
        check("abu.friction_mu" in str(t), f"a non-YAML value in a dict config is a TypeError naming it: {t}")

    # 4. montecarlo: the arrays' shapes, and the summary equal to `abuopt montecarlo --json`'s.
    runs, seed = 48, 5
    mc = abuopt.montecarlo(cfg, runs=runs, design="lhs", seed=seed, threads=2)
    cli = cli_json("montecarlo", cfg, "--runs", str(runs), "--design", "lhs", "--seed", str(seed), "--threads", "2")
    for key in ["residual_imbalance", "residual_imbalance_x", "status", "ok", "settled", "settling_time",
                "max_amplitude_mm", "events"]:
        check(mc[key].shape == (runs,), f"montecarlo {key} shape {mc[key].shape} == ({runs},)")
    check(mc["beta0"].shape == (runs, 2) and mc["beta_final"].shape == (runs, 2),
          f"montecarlo beta0/beta_final shapes {mc['beta0'].shape}, {mc['beta_final'].shape} == ({runs}, 2)")
    timing = {"wall_time_s"}
    summary = mc["summary"]
    cli_summary = {k: v for k, v in cli.items() if k not in ("study", "provenance")}  # CLI-only: the config file's provenance
    same = {k for k in cli_summary if k not in timing and summary.get(k) == cli_summary[k]}
    differ = sorted(set(cli_summary) - timing - same)
    check(not differ and set(summary) == set(cli_summary), f"montecarlo summary == CLI --json (differ: {differ})")
    ok = mc["ok"]
    mean = float(np.mean(mc["residual_imbalance"][ok]))
    check(math.isclose(mean, summary["magnitude"]["mean"], rel_tol=1e-12),
          f"mean of the |I_r| array {mean} == summary magnitude.mean {summary['magnitude']['mean']}")
    mi = int(np.sum(mc["residual_imbalance"][ok] > mc["imbalance_kgm"][ok]))
    check(mi == summary["magnitude"]["mi_count"], f"runs above the imbalance {mi} == summary mi_count")
    check(all(s == "ok" for s in mc["status"][ok]), "status 'ok' where ok")
    mc1 = abuopt.montecarlo(cfg, runs=runs, design="lhs", seed=seed, threads=1)
    check(np.array_equal(mc1["residual_imbalance"], mc["residual_imbalance"]), "montecarlo: 1 thread == 2 threads")

    # 5. equilibrium_set: the CLI's coverage on the same grid.
    ecfg = os.path.join(a.source, "configs", "eqset.yaml")
    eq = abuopt.equilibrium_set(ecfg, 30.0, grid=48)
    cli = cli_json("eqset", ecfg, "--freq", "30", "--grid", "48", "--out", os.path.join(a.work, "eqset"))
    check(eq["amplitude_mm"].shape == (48, 48) and eq["in_set"].shape == (48, 48) and eq["margins"].shape == (48, 48, 2),
          "equilibrium_set shapes")
    check(eq["coverage"] == cli["coverage"] and float(np.mean(eq["in_set"])) == cli["coverage"],
          f"equilibrium_set coverage {eq['coverage']} == CLI {cli['coverage']} == mean(in_set)")
    check(eq["amplitude_mm"].min() == cli["amplitude_mm"]["min"] and eq["amplitude_mm"].max() == cli["amplitude_mm"]["max"],
          "equilibrium_set amplitude range == CLI")

    # 6. StartupProfileProblem: names, bounds, x0; evaluate(x0) twice costs one Monte Carlo.
    qcfg = os.path.join(a.source, "configs", "optimize", "quick.yaml")
    p = abuopt.StartupProfileProblem(qcfg, runs=8, threads=2)
    check(p.names == ["f1", "dt1", "f2", "dt2", "dt3"], f"problem names {p.names}")
    check(len(p.bounds) == 5 and all(lo < hi for lo, hi in p.bounds), f"problem bounds {p.bounds}")
    check(list(p.x0) == [25.0, 1.0, 29.5, 10.0, 8.0], f"problem x0 {p.x0}")
    ev = p.evaluate(p.x0)
    ev2 = p.evaluate(list(p.x0))
    check(ev["ok"] and ev2["objective"] == ev["objective"] and p.evaluations == 1,
          f"evaluate(x0) objective {ev['objective']}, repeated without a new Monte Carlo ({p.evaluations})")
    check(ev["constraints"].shape == (len(p.constraint_names),), f"constraints {p.constraint_names} = {ev['constraints']}")
    check(math.isclose(ev["metrics"]["ir_magnitude_mean"], ev["objective"], rel_tol=1e-12),
          "objective (kind mean, magnitude) == metric ir_magnitude_mean")
    # The startup-time constraint in closed form: sum of durations / 20 s - 1.
    i = p.constraint_names.index("startup_time")
    check(math.isclose(ev["constraints"][i], 19.0 / 20.0 - 1.0, rel_tol=1e-12), "startup_time constraint = 19/20 - 1")

    # 7. What a newcomer expects of a NumPy/SciPy-style library: __version__, FileNotFoundError for a
    # missing file, a config of several commands accepted by each (eqset ignores its montecarlo section).
    ver = subprocess.run([a.cli, "--version"], capture_output=True, text=True).stdout
    check(isinstance(abuopt.__version__, str) and abuopt.__version__ in ver,
          f"abuopt.__version__ {abuopt.__version__!r} is the CLI's ({ver.strip()})")
    try:
        abuopt.simulate(os.path.join(a.work, "no_such.yaml"), beta0=beta0)
        check(False, "a missing config file is FileNotFoundError")
    except FileNotFoundError as f:
        check(f.filename == os.path.join(a.work, "no_such.yaml"), f"a missing config file is FileNotFoundError: {f}")
    eqm = abuopt.equilibrium_set(cfg, 29.0, grid=16)
    check(eqm["in_set"].shape == (16, 16), "equilibrium_set reads montecarlo_final_profile.yaml (montecarlo section ignored)")

    # 8. Archive: what `abuopt optimize` stored, read back, equal to `abuopt archive best --json`.
    out = os.path.join(a.work, "opt")
    r = subprocess.run([a.cli, "optimize", qcfg, "--max-evaluations", "4", "--threads", "2", "--out", out],
                       capture_output=True, text=True)
    check(r.returncode == 0, f"abuopt optimize quick.yaml --max-evaluations 4 (exit {r.returncode}) {r.stderr[-300:]}")
    arc = abuopt.Archive(os.path.join(out, "archive.sqlite"))
    probs = arc.problems()
    check(len(probs) == 1 and probs[0]["runs"][0]["command"] == "optimize", f"Archive.problems: {len(probs)} problem")
    ev = arc.evaluations()
    n = len(ev["id"])
    check(n >= 4 and ev["x"].shape == (n, 5) and ev["inequality"].shape == (n, len(probs[0]["inequality"])),
          f"Archive.evaluations: {n} rows, x {ev['x'].shape}")
    best = arc.best()
    cli_best = cli_json("archive", "best", os.path.join(out, "archive.sqlite"))
    check(best is not None and best["objective"] == cli_best["objective"] and best["id"] == cli_best["id"],
          f"Archive.best == abuopt archive best: {best and best['objective']} vs {cli_best['objective']}")
    feasible = ev["objective"][ev["feasible"]]
    check(best["objective"] == feasible.min(), "Archive.best is the lowest feasible objective")
    hist = arc.history()
    check(hist["best_feasible"][-1] == best["objective"], "Archive.history ends at the best feasible objective")
    few = arc.evaluations(where=[f"objective<={best['objective']}"])
    check(len(few["id"]) >= 1 and np.all(few["objective"] <= best["objective"]), "Archive.evaluations(where=...) filters")

    # 6b. Hardening (issue 29): bad numbers raise as on the command line; a dict that contains
    # itself, a path with a NUL, too many runs are errors, not a crash; Ctrl-C stops a long call.
    for bad_angle in (float("nan"), float("inf"), -float("inf")):
        e = error_of(lambda: abuopt.simulate(cfg, beta0=[bad_angle, 1.0]))
        check(e is not None and "beta0[0]" in str(e), f"simulate beta0=[{bad_angle}, 1] raises naming beta0[0]: {e}")
    eqcfg = os.path.join(a.source, "configs", "eqset.yaml")
    e = error_of(lambda: abuopt.equilibrium_set(eqcfg, 1e300, grid=8))
    check(e is not None and "freq" in str(e) and "1e6" in str(e), f"equilibrium_set above 1e6 Hz raises: {e}")
    e = error_of(lambda: abuopt.equilibrium_set({"abu": {"ball_count": 3}}, 29.0, grid=8, other_angles=[float("nan")]))
    check(e is not None and "other_angles[0] = nan" in str(e), f"other_angles=[nan] (3 balls) raises: {e}")
    loop = {}
    loop["abu"] = loop
    e = error_of(lambda: abuopt.simulate(loop, beta0=beta0))
    check(e is not None and "levels deep" in str(e), f"a dict that contains itself raises: {e}")
    e = error_of(lambda: abuopt.simulate(cfg + "\0.txt", beta0=beta0))
    check(e is not None and "NUL" in str(e), f"a path with an embedded NUL raises (not cut at the NUL): {e}")
    e = error_of(lambda: abuopt.montecarlo(cfg, runs=2000000, design="random"))
    check(e is not None and "max_runs" in str(e), f"2e6 runs without max_runs raises naming it: {e}")
    child = ("import abuopt, sys\n"
             "try:\n"
             f"    abuopt.montecarlo({cfg!r}, runs=100000, design='random')\n"
             "    print('ENDED')\n"
             "except KeyboardInterrupt:\n"
             "    print('INTERRUPTED')\n")
    import signal
    import time
    proc = subprocess.Popen([sys.executable, "-c", child], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, env=dict(os.environ))
    time.sleep(3.0)  # the import and the config first
    sent = time.monotonic()
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=120)
    latency = time.monotonic() - sent
    print(f"Ctrl-C during montecarlo(100000 runs): ended {latency:.2f} s after SIGINT")
    check("INTERRUPTED" in out and latency < 2.0,
          f"Ctrl-C stops a long montecarlo with KeyboardInterrupt within 2 s ({latency:.2f} s; {out.strip()} {err[-300:]})")

    # 9. The examples, quick mode (ABUOPT_QUICK=1 set by ctest).
    env = dict(os.environ, ABUOPT_QUICK="1", MPLBACKEND="Agg")
    for script, args in [("montecarlo_histogram.py", ["--out", os.path.join(a.work, "histogram.png")]),
                         ("scipy_cobyla.py", [])]:
        path = os.path.join(a.source, "examples", "python", script)
        r = subprocess.run([sys.executable, path, *args], capture_output=True, text=True, env=env)
        print(r.stdout[-1500:], r.stderr[-1500:])
        check(r.returncode == 0, f"example {script} runs (exit {r.returncode})")

    if failures:
        print(f"{len(failures)} check(s) failed")
        return 1
    print("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
