#!/usr/bin/env python3
"""Space-filling multi-start for the wide shake family at mu 0.03 (configs/studies/mu03/f3_mu03_g6.yaml).

The family (19 variables, every dwell at the resonance speed F_BAND fixed):
  0 -> f1 (dt1) -> e0 (dt2) -> F_BAND (dt3)         run-up with an optional early shake (e0 anywhere in 12 - 40 Hz;
                                                     e0 between f1 and F_BAND is no shake)
  hold dw1, then three times: -> e_k (dte_k) -> F_BAND (dtr_k), hold dw_{k+1}   (excursions e_k in 15 - 40 Hz;
                                                     e_k near F_BAND with short legs is no shake)
  -> 100 Hz (dtlast)

Steps (each resumable: an existing output is kept):
  sample   N points of a Latin hypercube over the family, repaired to be feasible on the exact constraints
           (peak angular acceleration 2 pi * 2 |H| / dt <= 314.16 rad/s^2, T <= 19 s); the amplitude is not repaired (screen measures it)
  screen   each point once: abuopt montecarlo on the in-sample set (LHS, seed 21, RUNS starts, mu 0.03)
  local    abuopt optimize (COBYLA, BUDGET evaluations, RUNS LHS starts) from the K best screened points
Usage:
  g6_multistart.py sample --n 48 --seed 5 --out DIR
  g6_multistart.py screen --out DIR --runs 256
  g6_multistart.py local --out DIR --k 6 --runs 256 --budget 40
  g6_multistart.py config --x "v0,v1,..." --runs 512 --budget 80 > CFG   (optimize config from a point)
"""
import argparse
import json
import math
import os
import random
import subprocess
import sys
import time

ABUOPT = os.environ.get("ABUOPT", "/work/main/build/app/abuopt")
F_BAND = 28.92
T_MAX = 19.0
FDOT_MAX = 50.0  # Hz/s: 314.16 rad/s^2 / (2 pi)

NAMES = ["f1", "dt1", "e0", "dt2", "dt3", "dw1",
         "e1", "dte1", "dtr1", "dw2", "e2", "dte2", "dtr2", "dw3", "e3", "dte3", "dtr3", "dw4", "dtlast"]
BOUNDS = {"f1": (15, 28.4), "dt1": (0.6, 3), "e0": (12, 40), "dt2": (0.05, 2), "dt3": (0.05, 3), "dw1": (0.05, 6),
          "e1": (15, 40), "dte1": (0.05, 1.5), "dtr1": (0.05, 1.5), "dw2": (0.05, 6),
          "e2": (15, 40), "dte2": (0.05, 1.5), "dtr2": (0.05, 1.5), "dw3": (0.05, 6),
          "e3": (15, 40), "dte3": (0.05, 1.5), "dtr3": (0.05, 1.5), "dw4": (0.05, 8), "dtlast": (2.8, 8)}

BALLS = {6: (4.66667e-05, 0.00208008), 5: (5.6e-05, 0.00221042), 2: (1.4e-04, 0.003)}


def segments(x):
    """Profile segments (end frequency, duration) of a point of the family."""
    v = dict(zip(NAMES, x))
    s = [(v["f1"], v["dt1"]), (v["e0"], v["dt2"]), (F_BAND, v["dt3"]), (F_BAND, v["dw1"])]
    for k in (1, 2, 3):
        s += [(v[f"e{k}"], v[f"dte{k}"]), (F_BAND, v[f"dtr{k}"]), (F_BAND, v[f"dw{k + 1}"])]
    s.append((100.0, v["dtlast"]))
    return s


def startup_time(x):
    return sum(d for _, d in segments(x))


def peak_fdot(x):
    f0, peak = 0.0, 0.0
    for f, d in segments(x):
        peak = max(peak, 2 * abs(f - f0) / d)
        f0 = f
    return peak


def repair(x):
    """Durations raised to the acceleration limit (x 1.02), then the slack above those floors shrunk to T <= 19 s."""
    v = dict(zip(NAMES, x))
    floor = {}
    f0 = 0.0
    legs = [("f1", "dt1"), ("e0", "dt2"), (None, "dt3"), (None, "dw1")]
    for k in (1, 2, 3):
        legs += [(f"e{k}", f"dte{k}"), (None, f"dtr{k}"), (None, f"dw{k + 1}")]
    legs.append((None, "dtlast"))
    for fname, dname in legs:
        f = v[fname] if fname else (100.0 if dname == "dtlast" else F_BAND)
        lo = BOUNDS[dname][0]
        if not dname.startswith("dw"):
            lo = max(lo, 1.02 * 2 * abs(f - f0) / FDOT_MAX)
        floor[dname] = lo
        v[dname] = min(max(v[dname], lo), BOUNDS[dname][1])
        f0 = f
    T = sum(v[d] for _, d in legs)
    target = T_MAX - 0.02
    if T > target:
        base = sum(floor.values())
        slack = T - base
        fac = max(0.0, (target - base) / slack)
        for _, d in legs:
            v[d] = floor[d] + fac * (v[d] - floor[d])
    return [v[n] for n in NAMES]


def lhs(n, dim, rng):
    cols = []
    for _ in range(dim):
        p = list(range(n))
        rng.shuffle(p)
        cols.append([(p[i] + rng.random()) / n for i in range(n)])
    return [[cols[j][i] for j in range(dim)] for i in range(n)]


def sample(n, seed):
    rng = random.Random(seed)
    pts = []
    for u in lhs(n, len(NAMES), rng):
        x = []
        for name, ui in zip(NAMES, u):
            lo, hi = BOUNDS[name]
            if name.startswith("dw"):
                hi = min(hi, 4.0)  # dwells drawn in 0.05 - 4 s (the bounds stay wider)
            if name.startswith(("dte", "dtr")) or name in ("dt2", "dt3"):
                hi = min(hi, 1.0)  # legs drawn short; repair() raises them to the acceleration limit
            x.append(lo + ui * (hi - lo))
        pts.append(repair(x))
    return pts


def incumbent():
    """contact_best_mu03_shake(_6balls) in this family: its second ramp split in two halves, no third shake."""
    return repair([23.9543, 1.58617, 26.4388, 1.90560, 1.90560, 1.59569,
                   26.6328, 0.181885, 0.118198, 1.52349, 25.8424, 0.279053, 0.264536,
                   1.25489, F_BAND, 0.05, 0.05, 1.25489, 5.06174])


def header_common(balls):
    m, d = BALLS[balls]
    return (f"abu:\n  friction_mu: 0.03\n  ball_contact: hard\n  ball_count: {balls}\n"
            f"  ball_mass_kg: {m}\n  ball_diameter_m: {d}\n")


def profile_yaml(x):
    lines = ["profile:", "  start_frequency_hz: 0", "  segments:"]
    for f, dt in segments(x):
        lines.append(f"    - {{end_frequency_hz: {f:.9g}, duration_s: {dt:.9g}}}")
    return "\n".join(lines) + "\n"


def montecarlo_config(x, balls=6, runs=256, seed=21, design="lhs"):
    return (header_common(balls) + profile_yaml(x) +
            "motor:\n  kind: ideal\nsimulation:\n  method: event_driven\n  rtol: 1.0e-6\n"
            f"montecarlo:\n  design: {design}\n  runs: {runs}\n  seed: {seed}\n  threads: 1\n")


def optimize_config(x, balls=6, runs=256, budget=40, step=0.1, comment="", t_max=19):
    v = dict(zip(NAMES, x))

    def var(n):
        lo, hi = BOUNDS[n]
        return f"{{min: {lo}, max: {hi}, x0: {min(max(v[n], lo), hi):.9g}}}"

    seg = [f"    - end_frequency_hz: {var('f1')}\n      duration_s: {var('dt1')}",
           f"    - end_frequency_hz: {var('e0')}     # the optional early shake (e0 between f1 and {F_BAND}: none)\n"
           f"      duration_s: {var('dt2')}",
           f"    - end_frequency_hz: {F_BAND}           # into the band\n      duration_s: {var('dt3')}",
           f"    - hold: true                    # first dwell\n      duration_s: {var('dw1')}"]
    for k in (1, 2, 3):
        seg += [f"    - end_frequency_hz: {var(f'e{k}')}   # excursion {k}\n      duration_s: {var(f'dte{k}')}",
                f"    - end_frequency_hz: {F_BAND}           # back into the band\n      duration_s: {var(f'dtr{k}')}",
                f"    - hold: true\n      duration_s: {var(f'dw{k + 1}')}"]
    seg.append(f"    - end_frequency_hz: 100\n      duration_s: {var('dtlast')}")
    return (comment + header_common(balls) +
            "profile:                       # template: the report's final profile (the design sets every segment)\n"
            "  start_frequency_hz: 0\n  segments:\n"
            "    - {end_frequency_hz: 25.0, duration_s: 1.0}\n    - {end_frequency_hz: 29.5, duration_s: 10.0}\n"
            "    - {end_frequency_hz: 100.0, duration_s: 8.0}\n"
            "motor:\n  kind: ideal\nsimulation:\n  method: event_driven\n  rtol: 1.0e-6\n"
            "montecarlo:                    # the SAME initial angles for every design (common random numbers)\n"
            f"  design: lhs\n  runs: {runs}\n  seed: 21\n  threads: 0\n"
            "design:\n  segments:\n" + "\n".join(seg) + "\n"
            "objective:\n  kind: mean                   # mean |I_r| [1e-7 kg m] at mu = 0.03\n"
            "  definition: magnitude\n"
            f"constraints:\n  max_startup_time_s: {t_max:g}\n  max_pct_mi: 100\n"
            "  max_amplitude_mm: 0.551      # the 2003 profile's peak amplitude at mu = 0.03\n"
            "  max_angular_acceleration_rad_s2: 314.16   # the 2003 profile's peak (first segment, 2 pi 50 Hz/s)\n"
            "validation:\n  enabled: false               # validated outside on 1024 fresh starts, seeds 9001 - 9003\n"
            f"optimizer:\n  algorithm: cobyla\n  max_evaluations: {budget}\n  initial_step: {step}\n"
            "  xtol_rel: 1.0e-3\n  constraint_tolerance: 1.0e-6\n")


def run_mc(cfg_path, runs, seed, design, out=None):
    cmd = ["nice", "-n", "5", ABUOPT, "montecarlo", cfg_path, "--mu", "0.03", "--design", design,
           "--runs", str(runs), "--seed", str(seed), "--threads", "1", "--json"]
    if out:
        cmd += ["--out", out]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode not in (0, 3):
        raise RuntimeError(f"montecarlo failed ({r.returncode}): {r.stderr[-2000:]}")
    return json.loads(r.stdout)


def cmd_sample(a):
    os.makedirs(a.out, exist_ok=True)
    pts = [incumbent()] + sample(a.n, a.seed)
    with open(os.path.join(a.out, "points.json"), "w") as f:
        json.dump({"names": NAMES, "points": pts, "seed": a.seed}, f, indent=1)
    for i, x in enumerate(pts):
        print(i, f"T={startup_time(x):.2f} fdot={peak_fdot(x):.1f}", " ".join(f"{v:.2f}" for v in x))


def summary_numbers(js):
    """mean |I_r| [1e-7 kg m], peak amplitude [mm], counts."""
    s = js.get("summary", js)
    return {"mean": s["magnitude"]["mean"] / 1e-7, "irx": s["report_x"]["mean"] / 1e-7,
            "amp": s["max_amplitude_mm"]["max"], "ok": s["ok"], "runs": s["runs"],
            "pct_mi": s["magnitude"]["pct_mi"]}


def cmd_screen(a):
    pts = json.load(open(os.path.join(a.out, "points.json")))["points"]
    res_path = os.path.join(a.out, f"screen_{a.runs}.jsonl")
    done = {}
    if os.path.exists(res_path):
        for line in open(res_path):
            r = json.loads(line)
            done[r["i"]] = r
    cfg_dir = os.path.join(a.out, "cfg")
    os.makedirs(cfg_dir, exist_ok=True)
    for i, x in enumerate(pts):
        if i in done or (a.limit and i >= a.limit):
            continue
        cfg = os.path.join(cfg_dir, f"p{i:03d}.yaml")
        with open(cfg, "w") as f:
            f.write(montecarlo_config(x, balls=a.balls, runs=a.runs))
        t0 = time.time()
        js = run_mc(cfg, a.runs, 21, "lhs")
        s = summary_numbers(js)
        rec = {"i": i, "x": x, "T": startup_time(x), "wall": time.time() - t0, "summary": s}
        with open(res_path, "a") as f:
            f.write(json.dumps(rec) + "\n")
        print(f"p{i:03d} wall {rec['wall']:.1f} s  " + brief(s), flush=True)


def brief(s):
    return (f"mean {s['mean']:.3f}  amp {s['amp']:.4f} {'ok' if s['amp'] <= 0.551 else 'AMP!'}  "
            f"ok {s['ok']}/{s['runs']}")


def screened(out, runs):
    recs = [json.loads(line) for line in open(os.path.join(out, f"screen_{runs}.jsonl"))]
    return [r for r in recs if r["summary"]["ok"] == r["summary"]["runs"]]


def cmd_local(a):
    """COBYLA from the K best screened points that meet the amplitude bound (plus any --also indices)."""
    recs = [r for r in screened(a.out, a.screen_runs) if r["summary"]["amp"] <= 0.551]
    recs.sort(key=lambda r: r["summary"]["mean"])
    starts = [r["i"] for r in recs[:a.k]]
    for i in (int(t) for t in a.also.split(",") if t):
        if i not in starts:
            starts.append(i)
    pts = json.load(open(os.path.join(a.out, "points.json")))["points"]
    tag = f"local_{a.runs}_{a.budget}"
    os.makedirs(os.path.join(a.out, tag), exist_ok=True)
    for i in starts:
        d = os.path.join(a.out, tag, f"p{i:03d}")
        if os.path.exists(os.path.join(d, "result.json")):
            continue
        cfg = os.path.join(a.out, tag, f"p{i:03d}.yaml")
        with open(cfg, "w") as f:
            f.write(optimize_config(pts[i], balls=a.balls, runs=a.runs, budget=a.budget, step=a.step))
        t0 = time.time()
        r = subprocess.run(["nice", "-n", "5", ABUOPT, "optimize", cfg, "--threads", "1", "--out", d],
                           capture_output=True, text=True)
        if r.returncode not in (0, 3):
            print(f"p{i:03d}: optimize failed ({r.returncode}) {r.stderr[-500:]}", flush=True)
            continue
        res = json.load(open(os.path.join(d, "result.json")))
        b = res["best"]
        print(f"p{i:03d} start {next(q['summary']['mean'] for q in recs if q['i'] == i) if i in [q['i'] for q in recs] else float('nan'):.3f}"
              f" -> {b['objective']:.3f} feasible {b['feasible']} evals {res['evaluations']} {time.time() - t0:.0f} s"
              f" x {json.dumps(b['x'])}", flush=True)


OPT_NAMES = ["f1", "dt1", "f2", "dt2", "dt3", "dt4", "f5", "dt5", "dt6", "dt7", "f8", "dt8", "dt9", "dt10",
             "f11", "dt11", "dt12", "dt13", "dt14"]  # abuopt optimize's names of NAMES, in the same order


def x_of_result(path):
    """The best x of an abuopt optimize result.json, in NAMES order."""
    b = json.load(open(path))["best"]["x"]
    return [b[n] for n in OPT_NAMES]


def cmd_config(a):
    if a.x.endswith(".json"):
        x = x_of_result(a.x)
    else:
        try:
            x = [float(t) for t in a.x.split(",")]
        except ValueError as e:
            sys.exit(f"g6_multistart.py config: --x: {e}")
    if len(x) != len(NAMES):  # zip() in segments()/optimize_config() would silently drop extra values
        sys.exit(f"g6_multistart.py config: --x has {len(x)} values, the family has {len(NAMES)} ({','.join(NAMES)})")
    sys.stdout.write(optimize_config(x, balls=a.balls, runs=a.runs, budget=a.budget, step=a.step, t_max=a.t_max))


def main():
    p = argparse.ArgumentParser()
    sub = p.add_subparsers(dest="cmd", required=True)
    s = sub.add_parser("sample")
    s.add_argument("--n", type=int, default=48)
    s.add_argument("--seed", type=int, default=5)
    s.add_argument("--out", required=True)
    s = sub.add_parser("screen")
    s.add_argument("--out", required=True)
    s.add_argument("--runs", type=int, default=256)
    s.add_argument("--balls", type=int, default=6)
    s.add_argument("--limit", type=int, default=0)
    s = sub.add_parser("local")
    s.add_argument("--out", required=True)
    s.add_argument("--k", type=int, default=8)
    s.add_argument("--also", default="")
    s.add_argument("--screen-runs", type=int, default=256)
    s.add_argument("--runs", type=int, default=256)
    s.add_argument("--budget", type=int, default=60)
    s.add_argument("--step", type=float, default=0.1)
    s.add_argument("--balls", type=int, default=6)
    s = sub.add_parser("config")
    s.add_argument("--x", required=True, help="comma-separated values in NAMES order, or a result.json")
    s.add_argument("--runs", type=int, default=256)
    s.add_argument("--budget", type=int, default=40)
    s.add_argument("--step", type=float, default=0.1)
    s.add_argument("--balls", type=int, default=6)
    s.add_argument("--t-max", type=float, default=19, help="max_startup_time_s (the side result: 25)")
    a = p.parse_args()
    {"sample": cmd_sample, "screen": cmd_screen, "local": cmd_local, "config": cmd_config}[a.cmd](a)


if __name__ == "__main__":
    main()
