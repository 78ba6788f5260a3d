#!/usr/bin/env python3
"""Where balls stop when they slide into the equilibrium set: the stop depth against the approach rate
(issue 10, the limit analysis of docs/studies/startup-profile.md section 8.9).

A profile decides how the balls enter the set of the speed at which they stop through the rate at which
it approaches that speed. This runner measures it directly: for a hold frequency f_h and an approach
duration D,

    up:    0 -> 25 Hz in 1 s, 25 Hz -> f_h in D (inclined sine), hold f_h for 6 s, -> 100 Hz in 4.3 s
    down:  0 -> 25 Hz in 1 s, -> 30 Hz in 5 s, 30 Hz -> f_h in D (the sweep back of the best designs),
           hold f_h for 6 s, -> 100 Hz in 4.3 s

and, with --family oscillate, the non-monotonic profiles of the issue (balls stuck at one speed are
outside the set of another, so they slide again): n cycles of amplitude A and period P around f_c,

    oscillate: 0 -> 25 Hz in 1 s, -> f_c + A in 3 s, n x [-> f_c - A in P/2, -> f_c + A in P/2],
               -> f_d in P/2, hold f_d for 6 s, -> 100 Hz in 4.3 s

each on the same random starts (abuopt montecarlo), and reports per case the final |I_r| in units of
r_lock(mu) (mean, p10, median, p90, the share at or below the goal's 0.44 r_lock) and the stop depth
|I_r| / r_in(f_s) at each run's settling frequency f_s (r_in: the inscribed disc of the set,
docs/equilibrium_sets.md section 4; 1 = on the boundary, 0 = at a balancing point).

    python3 scripts/stop_depth_study.py --out results/stop_depth [--runs 1024] [--mu 0.02 0.03]
    python3 scripts/stop_depth_study.py --family oscillate --out results/stop_depth_osc --runs 256 \
        [--center 28.9 29.2 29.5] [--amplitude 0.2 0.5 1 1.5] [--period 0.5 1 2 4] [--cycles 1 2 4] [--dwell 28.93 29]

Writes OUT/stop_depth.csv, OUT/stop_depth.md and OUT/stop_depth.png (gnuplot). Needs python3 only.
"""
import argparse
import csv
import json
import math
import os
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from startup_study import frequency_at  # noqa: E402  (the inclined-sine profile, one definition)

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# The report's ABU (spec table 3.2; configs/eqset.yaml): M = table + imbalance + two balls.
TABLE_MASS, IMB_MASS, ECC, BALL_MASS, L = 0.324, 5.6e-4, 3.7e-3, 1.4e-4, 1.15e-2
DAMPING, STIFFNESS = 1.28, 1.07e4
M = TABLE_MASS + IMB_MASS + 2 * BALL_MASS
OMEGA_N = math.sqrt(STIFFNESS / M)
BBAR = DAMPING / (2 * math.sqrt(STIFFNESS * M))
GOAL_FRACTION = 0.44  # 7.0e-7 / r_lock(0.02): the mean-|I_r| goal in units of r_lock
HOLD_S, LAST_S, FIRST = 6.0, 4.3, (25.0, 1.0)


def r_in(f_hz, mu):
    """Inscribed disc of the set at f [1e-7 kg m]: M L mu / ((1 + mu) |G(W)|), G = W^2 / (1 - W^2 + 2 i bbar W)."""
    w = 2 * math.pi * f_hz / OMEGA_N
    g = w * w / abs(complex(1 - w * w, 2 * BBAR * w))
    return M * L * mu / ((1 + mu) * g) / 1e-7


def r_lock(mu):
    """min_f r_in(f) = 2 bbar sqrt(1 - bbar^2) M L mu / (1 + mu) [1e-7 kg m] (15.90 at mu = 0.02)."""
    return 2 * BBAR * math.sqrt(1 - BBAR * BBAR) * M * L * mu / (1 + mu) / 1e-7


def segments(kind, f_h, d):
    s = [FIRST]
    if kind == "down":
        s.append((30.0, 5.0))
    return s + [(f_h, d), (f_h, HOLD_S), (100.0, LAST_S)]


def oscillation_segments(f_c, amp, period, cycles, f_d):
    """0 -> 25 Hz in 1 s, -> f_c + A in 3 s, cycles x (down to f_c - A, up to f_c + A, P/2 each), -> f_d in P/2,
    hold f_d, -> 100 Hz. Peak rate of a half cycle 2 (2 A) / (P / 2) = 8 A / P Hz/s."""
    s = [FIRST, (f_c + amp, 3.0)]
    for _ in range(cycles):
        s += [(f_c - amp, period / 2), (f_c + amp, period / 2)]
    return s + [(f_d, period / 2), (f_d, HOLD_S), (100.0, LAST_S)]


def config_text(segs, mu, runs, seed):
    prof = "".join(f"    - {{end_frequency_hz: {f:.6g}, duration_s: {d:.6g}}}\n" for f, d in segs)
    return (f"abu:\n  friction_mu: {mu}\n  ball_contact: hard\nprofile:\n  start_frequency_hz: 0\n  segments:\n{prof}"
            "motor:\n  kind: ideal\nsimulation:\n  method: event_driven\n  rtol: 1.0e-6\n"
            f"montecarlo:\n  design: random\n  runs: {runs}\n  seed: {seed}\n  threads: 0\n")


def quantile(v, q):
    s = sorted(v)
    return s[min(len(s) - 1, int(q * len(s)))]


def run_case(a, kind, f_h, d, mu):
    segs = segments(kind, f_h, d)
    peak_rate = 2 * abs(f_h - (30.0 if kind == "down" else 25.0)) / d  # Hz/s at the middle of the approach
    row = {"kind": kind, "f_hold_hz": f_h, "approach_s": d, "approach_peak_hz_s": peak_rate}
    return measure(a, f"{kind}_f{f_h:g}_D{d:g}_mu{mu:g}", segs, mu, row)


def run_oscillation(a, f_c, amp, period, cycles, f_d, mu):
    segs = oscillation_segments(f_c, amp, period, cycles, f_d)
    row = {"kind": "oscillate", "center_hz": f_c, "amplitude_hz": amp, "period_s": period, "cycles": cycles,
           "f_hold_hz": f_d, "peak_rate_hz_s": max(8 * amp / period, 2 * abs(f_c + amp - f_d) / (period / 2))}
    return measure(a, f"osc_c{f_c:g}_A{amp:g}_P{period:g}_n{cycles}_d{f_d:g}_mu{mu:g}", segs, mu, row)


def measure(a, name, segs, mu, row):
    out = os.path.join(a.out, name)
    os.makedirs(out, exist_ok=True)
    cfg = os.path.join(out, "config.yaml")
    text = config_text(segs, mu, a.runs, a.seed)
    summary = os.path.join(out, "summary.json")
    if not (os.path.exists(summary) and os.path.exists(cfg) and open(cfg).read() == text):  # resumable
        with open(cfg, "w") as f:
            f.write(text)
        r = subprocess.run(["nice", "-n", str(a.nice), a.abuopt, "montecarlo", cfg, "--threads", str(a.threads),
                            "--out", out], capture_output=True, text=True)
        if r.returncode not in (0, 3):
            sys.exit(f"abuopt montecarlo failed on {cfg} (status {r.returncode}):\n{r.stderr}")
    rows = [r for r in csv.DictReader(open(os.path.join(out, "runs.csv"))) if r["status"] == "ok"]
    rl = r_lock(mu)
    ir = [float(r["ir_magnitude_kgm"]) / 1e-7 for r in rows]
    depth = [float(r["ir_magnitude_kgm"]) / 1e-7 / r_in(frequency_at(segs, float(r["settling_time_s"])), mu)
             for r in rows if r["settled"] == "1"]
    n = len(ir)
    mean = sum(ir) / n
    sd = math.sqrt(sum((x - mean) ** 2 for x in ir) / (n - 1))
    with open(summary) as f:
        wall = json.load(f).get("wall_time_s", float("nan"))
    return {**row, "mu": mu, "r_lock": rl, "runs": len(rows), "mean": mean, "hw95": 1.96 * sd / math.sqrt(n),
            "mean_over_rlock": mean / rl, "p10_over_rlock": quantile(ir, 0.1) / rl,
            "median_over_rlock": quantile(ir, 0.5) / rl, "p90_over_rlock": quantile(ir, 0.9) / rl,
            "share_at_goal_depth": sum(1 for x in ir if x <= GOAL_FRACTION * rl) / n,
            "depth_median": quantile(depth, 0.5) if depth else float("nan"),
            "depth_p10": quantile(depth, 0.1) if depth else float("nan"),
            "depth_p90": quantile(depth, 0.9) if depth else float("nan"),
            "wall_s": wall}


def write_plot(out, name, body):
    """Write OUT/NAME.gp (the common preamble: a 1000 x 650 PNG OUT/NAME.png, grid) followed by body, and run
    gnuplot on it in OUT if gnuplot is installed (the data files body names are relative to OUT)."""
    with open(os.path.join(out, name + ".gp"), "w") as f:
        f.write(f"set terminal pngcairo size 1000,650 noenhanced\nset output '{name}.png'\nset grid\n" + body)
    gp = shutil.which("gnuplot")
    if gp:
        subprocess.run([gp, name + ".gp"], cwd=out, capture_output=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=os.path.join("results", "stop_depth"))
    ap.add_argument("--abuopt", default=os.path.join(ROOT, "build", "app", "abuopt"))
    ap.add_argument("--runs", type=int, default=1024)
    ap.add_argument("--seed", type=int, default=9001)
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--nice", type=int, default=10)
    ap.add_argument("--mu", type=float, nargs="+", default=[0.02, 0.03])
    ap.add_argument("--hold", type=float, nargs="+", default=[28.85, 29.0, 29.2])
    ap.add_argument("--approach", type=float, nargs="+", default=[0.25, 0.5, 1, 2, 4, 8, 16, 32])
    ap.add_argument("--family", choices=["approach", "oscillate"], default="approach")
    ap.add_argument("--center", type=float, nargs="+", default=[28.9, 29.2, 29.5], help="oscillate: f_c [Hz]")
    ap.add_argument("--amplitude", type=float, nargs="+", default=[0.2, 0.5, 1.0, 1.5], help="oscillate: A [Hz]")
    ap.add_argument("--period", type=float, nargs="+", default=[0.5, 1, 2, 4], help="oscillate: P [s]")
    ap.add_argument("--cycles", type=int, nargs="+", default=[1, 2, 4], help="oscillate: n")
    ap.add_argument("--dwell", type=float, nargs="+", default=[28.93, 29.0], help="oscillate: f_d [Hz]")
    a = ap.parse_args()
    if a.runs < 2:
        sys.exit(f"--runs {a.runs}: must be >= 2")
    if not os.access(a.abuopt, os.X_OK):
        sys.exit(f"--abuopt {a.abuopt}: not an executable")
    os.makedirs(a.out, exist_ok=True)
    if a.family == "oscillate":
        return oscillate(a)
    rows = []
    for mu in a.mu:
        for kind in ("up", "down"):
            for f_h in a.hold:
                for d in a.approach:
                    r = run_case(a, kind, f_h, d, mu)
                    rows.append(r)
                    print(f"{kind:4s} f_h {f_h:6.2f} Hz D {d:6.2f} s mu {mu:.2f}: mean {r['mean']:6.2f} "
                          f"= {r['mean_over_rlock']:.3f} r_lock, <= 0.44 r_lock {100 * r['share_at_goal_depth']:5.1f} %, "
                          f"depth median {r['depth_median']:.2f}", flush=True)
    keys = list(rows[0])
    with open(os.path.join(a.out, "stop_depth.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)
    lines = [f"# Stop depth against the approach ({a.runs} random starts, seed {a.seed}, contact hard)", "",
             "| approach | f_h [Hz] | D [s] | peak rate [Hz/s] | mu | mean \\|I_r\\| [95 %] | mean / r_lock | p10 | median | "
             "p90 | share <= 0.44 r_lock | depth median (p10, p90) |",
             "|" + "---|" * 12]
    for r in rows:
        lines.append(f"| {r['kind']} | {r['f_hold_hz']:g} | {r['approach_s']:g} | {r['approach_peak_hz_s']:.2f} | "
                     f"{r['mu']:g} | {r['mean']:.2f} +- {r['hw95']:.2f} | {r['mean_over_rlock']:.3f} | "
                     f"{r['p10_over_rlock']:.3f} | {r['median_over_rlock']:.3f} | {r['p90_over_rlock']:.3f} | "
                     f"{100 * r['share_at_goal_depth']:.1f} % | {r['depth_median']:.2f} ({r['depth_p10']:.2f}, "
                     f"{r['depth_p90']:.2f}) |")
    best = min(rows, key=lambda r: r["mean_over_rlock"])
    lines += ["", f"least mean / r_lock: {best['mean_over_rlock']:.3f} ({best['kind']}, f_h {best['f_hold_hz']:g} Hz, "
              f"D {best['approach_s']:g} s, mu {best['mu']:g}); the goal needs {GOAL_FRACTION}"]
    with open(os.path.join(a.out, "stop_depth.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines[-1:]))
    # Plot: mean |I_r| / r_lock (p10..p90 bars) against the approach duration, per case.
    dat = os.path.join(a.out, "stop_depth.dat")
    series = []
    with open(dat, "w") as f:
        for mu in a.mu:
            for kind in ("up", "down"):
                for f_h in a.hold:
                    f.write(f"# {kind} {f_h} {mu}\n")
                    for r in rows:
                        if (r["kind"], r["f_hold_hz"], r["mu"]) == (kind, f_h, mu):
                            f.write(f"{r['approach_s']} {r['mean_over_rlock']:.4f} {r['median_over_rlock']:.4f} "
                                    f"{r['share_at_goal_depth']:.4f}\n")
                    f.write("\n\n")
                    series.append(f"{kind} to {f_h:g} Hz, mu {mu:g}")
    plots = ", ".join(f"'stop_depth.dat' index {k} using 1:2 with linespoints lw 1.5 dt {1 if 'up' in s else 2} "
                      f"pt {k % 13 + 1} title '{s}'" for k, s in enumerate(series))
    write_plot(a.out, "stop_depth",
               f"set title 'mean |I_r| / r_lock(mu) against the approach duration ({a.runs} starts, contact hard)'\n"
               "set xrange [0.2:40]\nset xlabel 'approach duration D to the hold frequency [s] (log)'\nset logscale x\n"
               "set ylabel 'mean |I_r| / r_lock(mu)'\nset yrange [0:1.4]\nset key outside right\n"
               f"plot {plots}, {GOAL_FRACTION} with lines lw 2 lc rgb 'black' title 'goal 7.0e-7 = 0.44 r_lock'\n")


def oscillate(a):
    for k, v in (("--amplitude", a.amplitude), ("--period", a.period), ("--cycles", a.cycles)):
        if min(v) <= 0:
            sys.exit(f"{k} {min(v):g}: must be > 0")
    rows = []
    for mu in a.mu:
        for f_c in a.center:
            for amp in a.amplitude:
                for period in a.period:
                    for n in a.cycles:
                        for f_d in a.dwell:
                            r = run_oscillation(a, f_c, amp, period, n, f_d, mu)
                            rows.append(r)
                            print(f"osc f_c {f_c:5.2f} A {amp:4.2f} P {period:4.2f} n {n} f_d {f_d:5.2f} mu {mu:.2f}: "
                                  f"mean {r['mean']:6.2f} = {r['mean_over_rlock']:.3f} r_lock, <= 0.44 r_lock "
                                  f"{100 * r['share_at_goal_depth']:5.1f} %", flush=True)
    with open(os.path.join(a.out, "stop_depth_osc.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    lines = [f"# Oscillations through the band ({a.runs} random starts, seed {a.seed}, contact hard)", ""]
    for mu in a.mu:
        sub = sorted((r for r in rows if r["mu"] == mu), key=lambda r: r["mean_over_rlock"])
        means = [r["mean_over_rlock"] for r in sub]
        lines += [f"mu {mu:g}: {len(sub)} cases, mean / r_lock from {means[0]:.3f} to {means[-1]:.3f} (median "
                  f"{quantile(means, 0.5):.3f}); the ten deepest:", "",
                  "| f_c [Hz] | A [Hz] | P [s] | n | f_d [Hz] | peak rate [Hz/s] | mean \\|I_r\\| [95 %] | mean / r_lock | "
                  "median | p90 | share <= 0.44 r_lock |", "|" + "---|" * 11]
        for r in sub[:10]:
            lines.append(f"| {r['center_hz']:g} | {r['amplitude_hz']:g} | {r['period_s']:g} | {r['cycles']} | "
                         f"{r['f_hold_hz']:g} | {r['peak_rate_hz_s']:.1f} | {r['mean']:.2f} +- {r['hw95']:.2f} | "
                         f"{r['mean_over_rlock']:.3f} | {r['median_over_rlock']:.3f} | {r['p90_over_rlock']:.3f} | "
                         f"{100 * r['share_at_goal_depth']:.1f} % |")
        lines.append("")
        for key, label in (("center_hz", "f_c"), ("amplitude_hz", "A"), ("period_s", "P"), ("cycles", "n"),
                           ("f_hold_hz", "f_d")):
            vals = sorted({r[key] for r in sub})
            lines.append(f"least mean / r_lock per {label}: " + ", ".join(
                f"{v:g}: {min(r['mean_over_rlock'] for r in sub if r[key] == v):.3f}" for v in vals))
        lines.append("")
    with open(os.path.join(a.out, "stop_depth_osc.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))
    with open(os.path.join(a.out, "stop_depth_osc.dat"), "w") as f:
        for mu in a.mu:
            f.write(f"# mu {mu}: peak rate, mean / r_lock, cycles\n")
            for r in rows:
                if r["mu"] == mu:
                    f.write(f"{r['peak_rate_hz_s']:.4f} {r['mean_over_rlock']:.4f} {r['cycles']}\n")
            f.write("\n\n")
    plots = ", ".join(f"'stop_depth_osc.dat' index {k} using 1:2 with points pt {7 + k} ps 0.8 title 'mu {mu:g}'"
                      for k, mu in enumerate(a.mu))
    write_plot(a.out, "stop_depth_osc",
               f"set title 'oscillations through the band: mean |I_r| / r_lock(mu) per case ({a.runs} starts, "
               "contact hard)'\nset logscale x\nset xlabel 'peak rate of the profile after 25 Hz [Hz/s] (log)'\n"
               "set ylabel 'mean |I_r| / r_lock(mu)'\nset yrange [0:*]\nset key top left\n"
               f"plot {plots}, {GOAL_FRACTION} with lines lw 2 lc rgb 'black' title 'goal 7.0e-7 = 0.44 r_lock'\n")


if __name__ == "__main__":
    main()
