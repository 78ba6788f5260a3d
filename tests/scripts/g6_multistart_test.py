#!/usr/bin/env python3
"""Tests of scripts/g6_multistart.py (the global phase behind configs/studies/best/contact_best_mu03_g6.yaml).

    g6_multistart_test.py ABUOPT

The sampler: lhs() puts one point in each of the n strata of every variable; sample(48, seed 5) is repair() of
that hypercube mapped onto the drawing ranges (frequencies untouched, so they are stratified over their bounds);
every sampled point meets the exact constraints it claims (per inclined-sine segment the peak angular acceleration
2 pi * 2 |H| / dt <= 314.16 rad/s^2, with H the segment's frequency step; T <= 19 s) and stays in the bounds; the
same seed gives the same points, another seed other points; `sample` writes the incumbent first, unchanged by
repair() (contact_best_mu03_shake_6balls in this family). repair() on hand-made points: a too steep leg raised to
1.02 x its floor, a too long profile shrunk to T = 18.98 s with every leg's slack above its floor scaled by one
factor. segments() of a hand-made point against hand-written segments, T and the peak. Through abuopt: the
`config --x` output of the incumbent and three LHS points is accepted by `abuopt optimize --max-evaluations 1
--threads 1` (4 starts), abuopt's evaluated profile is the point's (1e-5 relative), its peak angular acceleration
metric is 2 pi x peak_fdot (1e-6 relative) and <= 314.16, its startup time is T <= 19 s; `config --x
result.json` gives back that x. The study is reproduced (its points 73, 97, 99 of sample --n 127 --seed 5;
config --x of the incumbent = configs/studies/mu03/f3_mu03_g6_local.yaml below its header). Bad --x (18 or 20 values, a
non-number) exits non-zero naming the problem.
"""
import json
import math
import os
import random
import subprocess
import sys
import tempfile

from script_check import ROOT, check, failures, load_script

g6 = load_script("g6_multistart")
SCRIPT = os.path.join(ROOT, "scripts", "g6_multistart.py")
ACC_MAX = 314.16  # rad/s^2, the 2003 profile's peak (2 pi 50 Hz/s)
N, SEED = 48, 5


def chk(cond, what):
    check(cond, what)
    return cond


def seg_acc(segs):
    """Peak angular acceleration [rad/s^2] of each inclined-sine segment: 2 pi * 2 |H| / dt."""
    f0, out = 0.0, []
    for f, d in segs:
        out.append(2 * math.pi * 2 * abs(f - f0) / d)
        f0 = f
    return out


def meets_constraints(x):
    """(ok, worst acceleration, T, bounds ok) of a point on the exact constraints the sampler claims."""
    acc = max(seg_acc(g6.segments(x)))
    T = g6.startup_time(x)
    inb = all(g6.BOUNDS[n][0] - 1e-12 <= v <= g6.BOUNDS[n][1] + 1e-12 for n, v in zip(g6.NAMES, x))
    return acc <= ACC_MAX and T <= g6.T_MAX + 1e-12 and inb, acc, T, inb


def sampler():
    dim = len(g6.NAMES)
    u = g6.lhs(N, dim, random.Random(SEED))
    strata_ok = all(sorted(int(u[i][j] * N) for i in range(N)) == list(range(N)) for j in range(dim))
    check(len(u) == N and strata_ok, f"lhs({N}, {dim}): one point in each of the {N} strata of every variable")

    pts = g6.sample(N, SEED)
    check(len(pts) == N and all(len(x) == dim for x in pts), f"sample({N}, {SEED}): {N} points of {dim} values")
    # sample() = repair() of the hypercube mapped onto the drawing ranges (re-derived here from the docstring's
    # rules: dwells drawn in 0.05 - 4 s, the short legs dt2, dt3, dte_k, dtr_k in 0.05 - 1 s, the rest in the bounds)
    pre = []
    for ui in u:
        x = []
        for name, v in zip(g6.NAMES, ui):
            lo, hi = g6.BOUNDS[name]
            if name.startswith("dw"):
                hi = 4.0
            elif name.startswith(("dte", "dtr")) or name in ("dt2", "dt3"):
                hi = 1.0
            x.append(lo + v * (hi - lo))
        pre.append(x)
    check(all(max(abs(a - b) for a, b in zip(g6.repair(p), x)) < 1e-12 for p, x in zip(pre, pts)),
          "the sampled points are repair() of that hypercube on the drawing ranges")
    freqs = [j for j, n in enumerate(g6.NAMES) if not n.startswith(("dt", "dw"))]
    kept = all(pts[i][j] == pre[i][j] for i in range(N) for j in freqs)
    lo_hi = [g6.BOUNDS[n] for n in g6.NAMES]
    strat = all(sorted(int((pts[i][j] - lo_hi[j][0]) / (lo_hi[j][1] - lo_hi[j][0]) * N) for i in range(N))
                == list(range(N)) for j in freqs)
    check(kept and strat,
          f"repair() leaves the {len(freqs)} frequencies alone: each still one point per stratum of its bounds")
    changed = sum(1 for i in range(N) for j in range(dim) if j not in freqs and abs(pts[i][j] - pre[i][j]) > 1e-12)
    print(f"     (repair changed {changed} of {N * (dim - len(freqs))} sampled durations)")

    res = [meets_constraints(x) for x in pts]
    worst_acc = max(r[1] for r in res)
    worst_T = max(r[2] for r in res)
    check(all(r[0] for r in res),
          f"all {N} points: every segment's 2 pi 2|H|/dt <= {ACC_MAX} (worst {worst_acc:.2f}), T <= 19 s "
          f"(worst {worst_T:.4f}), in the bounds ({sum(r[3] for r in res)}/{N})")
    check(all(abs(2 * math.pi * g6.peak_fdot(x) - max(seg_acc(g6.segments(x)))) < 1e-9 * ACC_MAX for x in pts),
          "peak_fdot() x 2 pi is the segments' peak angular acceleration")
    check(g6.sample(N, SEED) == pts, f"the same seed {SEED} gives the same points (bit for bit)")
    other = g6.sample(N, SEED + 1)
    check(all(a != b for a, b in zip(other, pts)), f"seed {SEED + 1} gives other points")

    inc = g6.incumbent()
    raw = [23.9543, 1.58617, 26.4388, 1.90560, 1.90560, 1.59569, 26.6328, 0.181885, 0.118198, 1.52349, 25.8424,
           0.279053, 0.264536, 1.25489, g6.F_BAND, 0.05, 0.05, 1.25489, 5.06174]
    ok, acc, T, _ = meets_constraints(inc)
    check(inc == raw and ok,
          f"the incumbent is unchanged by repair() and feasible (peak {acc:.2f} rad/s^2, T {T:.4f} s)")
    # its profile is contact_best_mu03_shake_6balls: 23.9543 Hz / 1.58617 s, then to 28.92 in 3.8112 s (two halves
    # through the midpoint 26.4388 Hz), the two shakes, and a 2.60978 s dwell (the third shake absent: e3 = F_BAND)
    s = g6.segments(inc)
    check(abs(s[1][0] - (23.9543 + 28.9232) / 2) < 1e-3 and abs(s[1][1] + s[2][1] - 3.8112) < 1e-4
          and abs(sum(d for _, d in s[9:13]) - 2.60978) < 1e-5,
          "the incumbent is contact_best_mu03_shake_6balls (second ramp halved at 26.4388 Hz, last dwell 2.60978 s)")

    with tempfile.TemporaryDirectory() as tmp:
        r = subprocess.run([sys.executable, SCRIPT, "sample", "--n", str(N), "--seed", str(SEED), "--out", tmp],
                           capture_output=True, text=True)
        js = json.load(open(os.path.join(tmp, "points.json"))) if r.returncode == 0 else {"points": []}
        check(r.returncode == 0 and js.get("names") == g6.NAMES and js["points"] == [inc] + pts,
              f"`sample --n {N} --seed {SEED}` writes the incumbent then the {N} points ({len(js['points'])} written)")
    return pts


def profile_of_point():
    # a hand-made point: f1 20 Hz / 1 s, early shake to 35 Hz in 0.5 s, back to F_BAND in 0.6 s, dwell 2 s;
    # excursions to 18 Hz (0.7 / 0.8 s, dwell 1.5 s), 33 Hz (0.4 / 0.3 s, dwell 1 s), none (e3 = F_BAND, 0.05 s legs,
    # dwell 1.2 s); to 100 Hz in 4 s
    x = [20, 1.0, 35, 0.5, 0.6, 2.0, 18, 0.7, 0.8, 1.5, 33, 0.4, 0.3, 1.0, 28.92, 0.05, 0.05, 1.2, 4.0]
    F = 28.92
    want = [(20, 1.0), (35, 0.5), (F, 0.6), (F, 2.0), (18, 0.7), (F, 0.8), (F, 1.5), (33, 0.4), (F, 0.3), (F, 1.0),
            (F, 0.05), (F, 0.05), (F, 1.2), (100, 4.0)]
    check(g6.segments(x) == want, "segments() of a hand-made point = the 14 hand-written (end frequency, duration)")
    check(abs(g6.startup_time(x) - 14.1) < 1e-12, f"its T = {g6.startup_time(x):.4f} s (hand: 14.1)")
    # steepest leg: 20 -> 35 Hz in 0.5 s, 2 * 15 / 0.5 = 60 Hz/s (next: the last ramp, 2 * 71.08 / 4 = 35.54)
    check(abs(g6.peak_fdot(x) - 60.0) < 1e-12, f"its peak 2|H|/dt = {g6.peak_fdot(x):.4f} Hz/s (hand: 60)")
    # repair: dt2 raised to 1.02 * 2 * 15 / 50 = 0.612 s, nothing else; T 14.212 s < 18.98, no shrink
    r = g6.repair(x)
    want_r = list(x)
    want_r[3] = 0.612
    check(max(abs(a - b) for a, b in zip(r, want_r)) < 1e-12 and abs(g6.peak_fdot(r) - 50 / 1.02) < 1e-9,
          f"repair() raises only dt2 to 0.612 s: peak {g6.peak_fdot(r):.4f} Hz/s = 50 / 1.02, "
          f"{2 * math.pi * g6.peak_fdot(r):.2f} rad/s^2")
    # a too long point (every duration at its upper bound, T = 3 + 2 + 3 + 6 + 2 (1.5 + 1.5 + 6) + 1.5 + 1.5 + 8
    # + 8 = 51 s): shrunk to T = 18.98 s, every leg's slack
    # above its floor scaled by one common factor
    y = [g6.BOUNDS[n][1] if n.startswith(("dt", "dw")) else v for n, v in zip(g6.NAMES, x)]
    ry = g6.repair(y)
    floors, f0 = {}, 0.0
    for n, (f, _) in zip([n for n in g6.NAMES if n.startswith(("dt", "dw"))], g6.segments(y)):
        floors[n] = g6.BOUNDS[n][0] if n.startswith("dw") else max(g6.BOUNDS[n][0], 1.02 * 2 * abs(f - f0) / 50)
        f0 = f
    facs = [(v2 - floors[n]) / (v - floors[n]) for n, v, v2 in zip(g6.NAMES, y, ry) if n in floors]
    ok, acc, T, _ = meets_constraints(ry)
    check(abs(g6.startup_time(y) - 51.0) < 1e-9 and abs(T - 18.98) < 1e-9 and ok
          and max(facs) - min(facs) < 1e-12 and 0 < facs[0] < 1,
          f"repair() of a {g6.startup_time(y):.2f} s point: T = {T:.4f} s, slack factor {facs[0]:.5f} on all "
          f"{len(facs)} durations, peak {acc:.2f} rad/s^2")
    # profile_yaml(): the same segments, 9 significant digits
    lines = [l for l in g6.profile_yaml(x).splitlines() if "end_frequency_hz" in l]
    check(len(lines) == 14 and lines[1].strip() == "- {end_frequency_hz: 35, duration_s: 0.5}",
          f"profile_yaml(): 14 segment lines ({lines[1].strip()})")


def reproduces_study():
    """The study's global phase (configs/studies/mu03/f3_mu03_g6_local.yaml header: sample --n 127 --seed 5) is
    reproduced: its points 73, 97 (the start of contact_best_mu03_g6) and 99 as the lock6 run wrote them (6 digits),
    and `config --x` of the incumbent with --runs 256 --budget 50 is that shipped config below its header."""
    pts = [g6.incumbent()] + g6.sample(127, 5)
    study = {73: [25.28469, 2.288961, 20.93848, 0.947359, 0.325646, 0.703232, 23.346849, 0.227385, 0.601044,
                  1.351823, 22.359816, 0.562475, 0.590376, 3.030381, 33.037105, 0.961864, 0.5319, 1.563664, 5.16434],
             97: [17.857137, 1.522974, 25.102558, 0.538856, 0.225384, 3.259175, 22.190169, 0.677177, 0.478646,
                  1.396052, 27.730327, 0.431484, 0.835069, 0.866226, 23.828077, 0.438372, 0.818898, 1.912607,
                  5.579082],
             99: [15.149472, 1.326122, 34.586482, 0.79303, 0.231192, 3.221955, 18.587446, 0.824677, 0.84394,
                  1.697445, 24.401515, 0.305732, 0.184354, 0.522603, 22.742609, 0.252038, 0.485598, 3.259434,
                  5.03188]}
    worst = max(abs(a - b) for i, x in study.items() for a, b in zip(pts[i], x))
    check(len(pts) == 128 and worst < 6e-7,
          f"sample --n 127 --seed 5 gives the study's points 73, 97, 99 (worst difference {worst:.1e})")
    r = subprocess.run([sys.executable, SCRIPT, "config", "--x", ",".join(repr(v) for v in g6.incumbent()),
                        "--runs", "256", "--budget", "50"], capture_output=True, text=True)
    shipped = open(os.path.join(ROOT, "configs", "studies", "mu03", "f3_mu03_g6_local.yaml")).read()
    body = "".join(l for l in shipped.splitlines(keepends=True) if not l.startswith("#"))
    check(r.returncode == 0 and r.stdout == body,
          "config --x INCUMBENT --runs 256 --budget 50 = configs/studies/mu03/f3_mu03_g6_local.yaml below its header")


def through_abuopt(abuopt, pts):
    starts = [("incumbent", g6.incumbent())] + [(f"LHS point {i}", pts[i]) for i in (0, 17, 41)]
    with tempfile.TemporaryDirectory() as tmp:
        for label, x in starts:
            r = subprocess.run([sys.executable, SCRIPT, "config", "--x", ",".join(repr(v) for v in x), "--runs", "4",
                                "--budget", "1"], capture_output=True, text=True)
            if not chk(r.returncode == 0 and "design:" in r.stdout, f"{label}: `config --x` exits 0"):
                print(r.stderr[-2000:])
                continue
            cfg = os.path.join(tmp, "c.yaml")
            out = os.path.join(tmp, label.replace(" ", "_"))
            with open(cfg, "w") as f:
                f.write(r.stdout)
            o = subprocess.run([abuopt, "optimize", cfg, "--max-evaluations", "1", "--threads", "1", "--out", out],
                               capture_output=True, text=True)
            res_path = os.path.join(out, "result.json")
            if not chk(o.returncode in (0, 3) and os.path.exists(res_path),
                         f"{label}: abuopt optimize accepts it (exit {o.returncode})"):
                print(o.stderr[-2000:])
                continue
            b = json.load(open(res_path))["best"]
            got = [(s["end_frequency_hz"], s["duration_s"]) for s in b["profile"]["segments"]]
            want = g6.segments(x)
            rel = max((abs(a - c) / max(abs(c), 1e-300) for gs, ws in zip(got, want) for a, c in zip(gs, ws)),
                      default=math.inf)
            check(len(got) == len(want) and b["profile"]["start_frequency_hz"] == 0 and rel <= 1e-5,
                  f"{label}: abuopt's evaluated profile is the point's ({len(got)} segments, worst relative "
                  f"difference {rel:.1e})")
            m = b["metrics"]
            acc, want_acc = m["peak_angular_acceleration_rad_s2"], 2 * math.pi * g6.peak_fdot(x)
            check(abs(acc - want_acc) <= 1e-6 * want_acc and acc <= ACC_MAX
                  and b["constraints"]["angular_acceleration"] <= 0,
                  f"{label}: abuopt's peak angular acceleration {acc:.3f} rad/s^2 = 2 pi peak_fdot "
                  f"{want_acc:.3f}, <= {ACC_MAX}")
            check(abs(m["startup_time_s"] - g6.startup_time(x)) < 1e-6 and m["startup_time_s"] <= 19
                  and b["constraints"]["startup_time"] <= 0 and m["runs"] == 4,
                  f"{label}: abuopt's startup time {m['startup_time_s']:.4f} s = T <= 19 s, on 4 starts")
            # and back: config from that result.json has the same x0 (9 significant digits)
            back = g6.x_of_result(res_path)
            check(max(abs(a - c) / abs(c) for a, c in zip(back, x)) < 1e-8,
                  f"{label}: x_of_result() of abuopt's result.json gives back the point (names in NAMES order)")


def bad_input():
    good = g6.incumbent()
    cases = [("18 values", ",".join(repr(v) for v in good[:-1]), "18 values"),
             ("20 values", ",".join(repr(v) for v in good + [1.0]), "20 values"),
             ("a non-number", ",".join(["abc"] + [repr(v) for v in good[1:]]), "abc")]
    for label, xs, must in cases:
        r = subprocess.run([sys.executable, SCRIPT, "config", "--x", xs], capture_output=True, text=True)
        check(r.returncode != 0 and must in r.stderr and "--x" in r.stderr and "Traceback" not in r.stderr
              and "design:" not in r.stdout,
              f"config --x with {label}: exit {r.returncode}, message: {r.stderr.strip()[:90]}")


def main():
    abuopt = sys.argv[1] if len(sys.argv) > 1 else os.environ.get("ABUOPT", "/work/main/build/app/abuopt")
    os.environ["ABUOPT"] = abuopt
    pts = sampler()
    profile_of_point()
    reproduces_study()
    through_abuopt(abuopt, pts)
    bad_input()
    print(f"{len(failures)} failure(s)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
