#!/usr/bin/env python3
"""Test of abuopt.optimize, abuopt.sweep and abuopt.pareto (run by ctest as python_studies).

Each is run on a small config and compared with the command that calls the same library functions
on the same input (`abuopt optimize|sweep|pareto --json`): the numbers must be equal to the last bit.
Also: the archive they write agrees with the result (abuopt.Archive), a rerun resumes from it,
bad input raises ConfigError / FileNotFoundError, Ctrl-C raises KeyboardInterrupt within seconds.
Exit 77 (ctest: skipped) when the module or NumPy is absent.

  PYTHONPATH=build/python python3 python/tests/test_studies.py --cli build/app/abuopt --source . --work /tmp/t
"""
import argparse
import csv
import json
import os
import shutil
import subprocess
import sys
import threading
import time
import _thread

SKIP = 77


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cli", required=True, help="the abuopt executable")
    ap.add_argument("--source", required=True, help="the source tree (configs/)")
    ap.add_argument("--work", required=True, help="scratch directory")
    a = ap.parse_args()
    try:
        import numpy as np
        import abuopt
    except ImportError as e:
        print(f"SKIP: {e}")
        return SKIP
    shutil.rmtree(a.work, ignore_errors=True)
    os.makedirs(a.work)
    failures = []

    def check(cond, what):
        print(("ok    " if cond else "FAIL  ") + what)
        if not cond:
            failures.append(what)

    def cli_json(*args):
        r = subprocess.run([a.cli, *args, "--json"], capture_output=True, text=True)
        if r.returncode != 0:
            raise RuntimeError(f"abuopt {' '.join(args)} exited {r.returncode}: {r.stderr[-2000:]}")
        return json.loads(r.stdout)

    def work(name):
        return os.path.join(a.work, name)

    quick = os.path.join(a.source, "configs", "optimize", "quick.yaml")
    quick_text = open(quick).read()

    # 1. optimize == `abuopt optimize` on quick.yaml with 4 evaluations (COBYLA, 16 runs each; 32 validation runs)
    t = time.time()
    res = abuopt.optimize(quick, max_evaluations=4, threads=2, out=work("py_opt"))
    print(f"optimize: {time.time() - t:.1f} s")
    cli = cli_json("optimize", quick, "--max-evaluations", "4", "--threads", "2", "--out", work("cli_opt"))
    cli_x = np.array([cli["best"]["x"][n] for n in res.names])
    check(isinstance(res, abuopt.OptimizeResult) and isinstance(res, dict) and res.x is res["x"],
          "optimize returns an OptimizeResult (a dict with attribute access)")
    check(isinstance(res.x, np.ndarray) and res.x.shape == (5,), f"x is an array of the 5 variables: {res.x}")
    check(np.array_equal(res.x, cli_x), f"optimize x {res.x} == CLI best x {cli_x}")
    check(res.fun == cli["best"]["objective"], f"optimize fun {res.fun} == CLI {cli['best']['objective']}")
    check(res.nfev == cli["evaluations"] == 4, f"nfev {res.nfev} == CLI evaluations {cli['evaluations']} == 4")
    check(res.reason == cli["reason"] and res.feasible == cli["best"]["feasible"] and res.maxcv == cli["best"]["max_violation"],
          f"reason {res.reason}, feasible {res.feasible}, maxcv {res.maxcv} == CLI")
    cli_g = np.array([cli["best"]["constraints"][n] for n in res.constraint_names])
    check(np.array_equal(res.constraints, cli_g), f"constraints {res.constraints} == CLI {cli_g}")
    check(res.problem_id == cli["problem_id"], "problem_id == CLI")
    check(res.objective_label.startswith("mean |I_r| [1e-7 kg m]"), f"objective_label {res.objective_label!r}")
    v, cv = res.validation, cli["validation"]
    check(v is not None and v["best_out_of_sample"]["objective"] == cv["best"]["out_of_sample"]["objective"]
          and v["report_out_of_sample"]["objective"] == cv["report_profile"]["out_of_sample"]["objective"],
          f"validation out of sample == CLI ({v and v['best_out_of_sample']['objective']})")
    check(v["worse_than_report_profile"] == cv["worse_than_report_profile"], "worse_than_report_profile == CLI")
    h = res.history
    check(h["x"].shape == (4, 5) and h["objective"].shape == (4,) and np.array_equal(h["x"][0], res.x0),
          "history: 4 rows, the first at x0")
    check(h["best_feasible"][-1] == res.fun, "history best_feasible ends at fun")

    # 2. The archive it wrote: abuopt.Archive agrees with the result
    check(res.archive == os.path.join(work("py_opt"), "archive.sqlite") and os.path.isfile(res.archive),
          f"archive path {res.archive}")
    arc = abuopt.Archive(res.archive)
    ev = arc.evaluations()
    best = arc.best()
    check(len(ev["id"]) == res.nfev, f"archive holds {len(ev['id'])} evaluations == nfev {res.nfev}")
    check(best is not None and best["objective"] == res.fun and [best["x"][n] for n in res.names] == list(res.x),
          f"Archive.best {best and best['objective']} == result fun {res.fun}, same x")
    check(arc.problems()[0]["runs"][0]["command"] == "optimize (python)", "archive metadata: command 'optimize (python)'")
    check(np.array_equal(ev["objective"], h["objective"]), "archived objectives == history objectives, in order")

    # 3. A rerun resumes from the archive; out=None keeps it in memory and gives the same result
    again = abuopt.optimize(quick, max_evaluations=4, threads=2, out=work("py_opt"), validate=False)
    check(again.archive_hits == 4 and np.array_equal(again.x, res.x) and again.fun == res.fun and again.validation is None,
          f"rerun: {again.archive_hits} of 4 from the archive, same x and fun, no validation")
    mem = abuopt.optimize(quick, max_evaluations=4, threads=1, validate=False)
    check(mem.archive is None and mem.archive_hits == 0 and np.array_equal(mem.x, res.x) and mem.fun == res.fun,
          "out=None: archive in memory, same x and fun (1 thread == 2 threads)")

    # 4. Bad input
    def raises(exc, fn):
        try:
            fn()
        except exc as e:
            return e
        except Exception as e:  # noqa: BLE001
            return f"wrong exception {type(e).__name__}: {e}"
        return None

    e = raises(abuopt.ConfigError, lambda: abuopt.optimize(quick, max_evaluations=0))
    check(isinstance(e, abuopt.ConfigError) and "optimizer.max_evaluations = 0" in str(e), f"max_evaluations=0: {e}")
    e = raises(abuopt.ConfigError, lambda: abuopt.sweep(quick, runs=0))
    check(isinstance(e, abuopt.ConfigError) and "montecarlo.runs" in str(e), f"sweep runs=0: {e}")
    e = raises(FileNotFoundError, lambda: abuopt.optimize(work("no_such.yaml")))
    check(isinstance(e, FileNotFoundError) and e.filename == work("no_such.yaml"), f"missing config: {e}")
    e = raises(abuopt.ConfigError, lambda: abuopt.pareto(quick))
    check(isinstance(e, abuopt.ConfigError) and "pareto" in str(e), f"pareto without a pareto section: {e}")

    # 5. sweep == `abuopt sweep`: a 2 x 2 grid over dt2, dt3
    sweep_cfg = work("sweep.yaml")
    with open(sweep_cfg, "w") as f:
        f.write(quick_text + "sweep:\n  method: grid\n  variables: [dt2, dt3]\n  points: 2\n")
    sw = abuopt.sweep(sweep_cfg, threads=2)
    cli = cli_json("sweep", sweep_cfg, "--threads", "2", "--out", work("cli_sweep"))
    with open(os.path.join(work("cli_sweep"), "sweep.csv")) as f:
        rows = list(csv.DictReader(f))
    check(sw.x.shape == (4, 5) and sw.swept == ["dt2", "dt3"] and sw.method == "grid", f"sweep: 4 points, {sw.swept}")
    cli_obj = np.array([float(r["objective"]) for r in rows])
    check(np.array_equal(sw.objective, cli_obj), f"sweep objectives {sw.objective} == sweep.csv {cli_obj}")
    check(np.array_equal(sw.x[:, res.names.index("dt2")], [float(r["dt2"]) for r in rows]), "sweep dt2 == sweep.csv")
    check(np.array_equal(sw.unit, [[0, 0], [0, 1], [1, 0], [1, 1]]), f"grid unit design {sw.unit.tolist()}")
    bf = cli.get("best_feasible")
    check(bf is not None and sw.best is not None and sw.objective[sw.best] == bf["objective"],
          f"sweep best {sw.best} objective == CLI best_feasible {bf and bf['objective']}")
    check(sw.archive is None and sw.computed == 4, "sweep without out: 4 computed, archive in memory")

    # 6. pareto == `abuopt pareto`: two bounds on the startup time, 3 evaluations per start
    pareto_cfg = work("pareto.yaml")
    with open(pareto_cfg, "w") as f:
        f.write(quick_text.replace("  max_startup_time_s: 20\n", "").replace("max_evaluations: 10", "max_evaluations: 3")
                + "pareto:\n  max_startup_time_s: [12, 20]\n")
    t = time.time()
    pa = abuopt.pareto(pareto_cfg, threads=2, out=work("py_pareto"))
    print(f"pareto: {time.time() - t:.1f} s")
    cli = cli_json("pareto", pareto_cfg, "--threads", "2", "--out", work("cli_pareto"))
    check(pa.x.shape == (2, 5) and list(pa.max_startup_time_s) == [12, 20], "pareto: 2 bounds")
    cp = cli["points"]
    check(list(pa.objective) == [p["in_sample"]["objective"] for p in cp], f"pareto objectives {pa.objective} == CLI")
    check(list(pa.startup_time_s) == [p["startup_time_s"] for p in cp], f"pareto startup times {pa.startup_time_s} == CLI")
    check(list(pa.out_of_sample_objective) == [p["out_of_sample"]["objective"] for p in cp],
          f"pareto out-of-sample {pa.out_of_sample_objective} == CLI")
    check(list(pa.dominated) == [p["dominated"] for p in cp] and list(pa.evaluations) == [p["evaluations"] for p in cp],
          "pareto dominated, evaluations == CLI")
    check(np.array_equal(pa.front, pa.feasible & ~pa.dominated) and pa.front.any(), f"front {pa.front}")
    check(pa.report_profile["out_of_sample"]["objective"] == cli["report_profile"]["out_of_sample"]["objective"],
          "pareto report profile out of sample == CLI")
    check(list(pa.feasible) == [p["feasible"] for p in cp], f"pareto feasible {pa.feasible} == CLI")
    check(np.all(pa.startup_time_s[pa.feasible] <= pa.max_startup_time_s[pa.feasible] * (1 + 1e-6)),
          "each feasible point meets its bound (constraint tolerance 1e-6)")

    # 7. Ctrl-C: KeyboardInterrupt within seconds, the points so far stay in the archive (a 20 x 20 sweep)
    big = work("sweep_big.yaml")
    with open(big, "w") as f:
        f.write(quick_text + "sweep:\n  method: grid\n  variables: [dt2, dt3]\n  points: 20\n")
    timer = threading.Timer(1.5, _thread.interrupt_main)
    t = time.time()
    timer.start()
    try:
        abuopt.sweep(big, threads=2, out=work("py_ctrl_c"))
        check(False, "Ctrl-C raises KeyboardInterrupt")
    except KeyboardInterrupt:
        dt = time.time() - t
        n = len(abuopt.Archive(os.path.join(work("py_ctrl_c"), "archive.sqlite")).evaluations()["id"])
        check(dt < 15 and 1 <= n < 400, f"KeyboardInterrupt after {dt:.1f} s, {n} of 400 points archived")
    timer.cancel()

    # 8. Ctrl-C during pareto ends the series: no further bound is started (30 bounds, 10 evaluations each)
    many = work("pareto_many.yaml")
    with open(many, "w") as f:
        f.write(quick_text.replace("  max_startup_time_s: 20\n", "")
                + "pareto:\n  max_startup_time_s: [" + ", ".join(str(5 + k) for k in range(30)) + "]\n")
    timer = threading.Timer(1.0, _thread.interrupt_main)
    t = time.time()
    timer.start()
    try:
        abuopt.pareto(many, threads=2, out=work("py_pareto_ctrl_c"))
        check(False, "Ctrl-C raises KeyboardInterrupt in pareto")
    except KeyboardInterrupt:
        dt = time.time() - t
        probs = abuopt.Archive(os.path.join(work("py_pareto_ctrl_c"), "archive.sqlite")).problems()
        check(dt < 10 and 1 <= len(probs) < 30, f"pareto: KeyboardInterrupt after {dt:.1f} s, {len(probs)} of 30 bounds started")
    timer.cancel()

    if failures:
        print(f"{len(failures)} check(s) failed")
        return 1
    print("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
