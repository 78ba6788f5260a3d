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

and, with --family release, the aimed release that the Coulomb-oscillator estimate of section 8.1 suggests (a
ball released at rest at |U| outside a band of half-width r_in stops at the mirror point 2 r_in - |U|): a dwell
at f_1 collects the runs outside its set on the boundary |U| ~ r_in(f_1), a fast step to f_2 with
r_in(f_1) ~ 2 r_in(f_2) would fold them to ~0,

    release:   0 -> 25 Hz in 1 s, -> f_1 in the approach time, dwell t_1 at f_1, -> f_2 in the step time (0: at the
               acceleration limit), dwell at f_2 [, further steps of a staircase], -> 100 Hz in 4.3 s

each release case also run cut at the end of the dwell at f_1 (same starts), so that every run's final |U| is
paired with its |U| at the release (OUT/stop_depth_release_runs.png against the 1-D fold);

each on the same random starts (abuopt montecarlo), and reports per case the final |I_r| in units of
r_lock(mu) (mean, p10, median, p90, the share at or below the goal's 0.44 r_lock) and the stop depth
|I_r| / r_in(f_s) at each run's settling frequency f_s (r_in: the inscribed disc of the set,
docs/equilibrium_sets.md section 4; 1 = on the boundary, 0 = at a balancing point).

    python3 scripts/stop_depth_study.py --out results/stop_depth [--runs 1024] [--mu 0.02 0.03]
    python3 scripts/stop_depth_study.py --family oscillate --out results/stop_depth_osc --runs 256 \
        [--center 28.9 29.2 29.5] [--amplitude 0.2 0.5 1 1.5] [--period 0.5 1 2 4] [--cycles 1 2 4] [--dwell 28.93 29]
    python3 scripts/stop_depth_study.py --family release --out results/stop_depth_release --runs 256 \
        [--f1 28.2 ... 29.6] [--f2 28.85 28.9 29.0] [--stairs 30.5:29.45:28.9] [--dwell1 3 8] [--dwell2 6] \
        [--step 0 0.5] [--approach-s 3 0.25]

Writes OUT/stop_depth{,_osc,_release}.csv, .md and .png (gnuplot). Needs python3 only.
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
from startup_study import MAX_RATE_HZ_S, frequency_at  # noqa: E402  (the inclined-sine profile, one definition)

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


def config_text(segs, mu, runs, seed, end_time_s=None):
    """end_time_s: stop the simulation there (the state at the end of a truncated profile); None: the default
    rule (twice the profile duration)."""
    prof = "".join(f"    - {{end_frequency_hz: {f:.6g}, duration_s: {d:.6g}}}\n" for f, d in segs)
    end = "" if end_time_s is None else f"  end_time_s: {end_time_s:.9g}\n"
    return (f"abu:\n  friction_mu: {mu}\n  ball_contact: hard\nprofile:\n  start_frequency_hz: 0\n  segments:\n{prof}"
            "motor:\n  kind: ideal\nsimulation:\n  method: event_driven\n  rtol: 1.0e-6\n" + end +
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


def montecarlo(a, out, text):
    """Run abuopt montecarlo on the config text into out (kept if it ran before on the same text: resumable);
    returns the rows of runs.csv."""
    os.makedirs(out, exist_ok=True)
    cfg = os.path.join(out, "config.yaml")
    summary = os.path.join(out, "summary.json")
    if not (os.path.exists(summary) and os.path.exists(cfg) and open(cfg).read() == text):  # resumable
        with open(cfg, "w") as f:
            f.write(text)
        r = subprocess.run(["nice", "-n", str(a.nice), a.abuopt, "montecarlo", cfg, "--threads", str(a.threads),
                            "--out", out], capture_output=True, text=True)
        if r.returncode not in (0, 3):
            sys.exit(f"abuopt montecarlo failed on {cfg} (status {r.returncode}):\n{r.stderr}")
    return list(csv.DictReader(open(os.path.join(out, "runs.csv"))))


def measure(a, name, segs, mu, row):
    out = os.path.join(a.out, name)
    summary = os.path.join(out, "summary.json")
    rows = [r for r in montecarlo(a, out, config_text(segs, mu, a.runs, a.seed)) if r["status"] == "ok"]
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


def release_segments(freqs, dwells, approach_s, step_s):
    """The aimed release: 0 -> 25 Hz in 1 s, -> f_1 in approach_s, dwell t_1 at f_1, then for each later
    frequency f_k a step -> f_k (in step_s, or with step_s = 0 as fast as the acceleration limit allows:
    peak rate 2 |f_k - f_(k-1)| / D = MAX_RATE_HZ_S) and a dwell t_k at f_k; -> 100 Hz in 4.3 s."""
    s = [FIRST, (freqs[0], approach_s), (freqs[0], dwells[0])]
    for k in range(1, len(freqs)):
        d = step_s if step_s > 0 else 2 * abs(freqs[k] - freqs[k - 1]) / MAX_RATE_HZ_S
        s += [(freqs[k], d), (freqs[k], dwells[k])]
    return s + [(100.0, LAST_S)]


def run_release(a, freqs, approach_s, dwell1, step_s, mu):
    """One release case, and the state at the end of the dwell at f_1 on the same starts (the profile cut
    there: end_time_s = its duration), paired per run: was the run collected on the boundary of the set of
    f_1 (|U| >= 0.9 r_in(f_1)), and where did it stop after the release."""
    dwells = [dwell1] * (len(freqs) - 1) + [a.dwell2]
    segs = release_segments(freqs, dwells, approach_s, step_s)
    tag = "_".join(f"{f:g}" for f in freqs)
    row = {"kind": "release", "freqs": tag, "f1_hz": freqs[0], "f_hold_hz": freqs[-1], "approach_s": approach_s,
           "dwell1_s": dwell1,
           "step_s": segs[3][1], "steps": len(freqs) - 1,
           "peak_rate_hz_s": max(2 * abs(segs[k][0] - segs[k - 1][0]) / segs[k][1] for k in range(3, len(segs) - 1, 2))}
    name = f"rel_{tag}_a{approach_s:g}_t{dwell1:g}_s{step_s:g}_mu{mu:g}"
    r = measure(a, name, segs, mu, row)
    probe_segs = segs[:3]
    t_probe = sum(d for _, d in probe_segs)
    probe = montecarlo(a, os.path.join(a.out, f"probe_{freqs[0]:g}_a{approach_s:g}_t{dwell1:g}_mu{mu:g}"),
                       config_text(probe_segs, mu, a.runs, a.seed, end_time_s=t_probe))
    final = {x["index"]: x for x in csv.DictReader(open(os.path.join(a.out, name, "runs.csv"))) if x["status"] == "ok"}
    rin1, rin_h, rl = r_in(freqs[0], mu), r_in(freqs[-1], mu), r_lock(mu)
    coll, other, moved = [], [], 0
    for x in probe:
        y = final.get(x["index"])
        if x["status"] != "ok" or y is None:
            continue
        u1 = float(x["ir_magnitude_kgm"]) / 1e-7
        uf = float(y["ir_magnitude_kgm"]) / 1e-7
        (coll if u1 >= 0.9 * rin1 else other).append((u1, uf))
        if u1 >= 0.9 * rin1 and max(abs(math.remainder(float(x[f"beta_final_{i}"]) - float(y[f"beta_final_{i}"]),
                                                       2 * math.pi)) for i in (1, 2)) > 0.01:
            moved += 1
    # The 1-D Coulomb oscillator's fold of a run released at rest on the boundary of the set of f_1 at each
    # step: |U| -> |2 r_in(f_k) - |U|| while |U| > r_in(f_k) (a run inside the set of f_k stays).
    pred = rin1
    for f in freqs[1:]:
        if pred > r_in(f, mu):
            pred = abs(2 * r_in(f, mu) - pred)
    n = len(coll) + len(other)
    mean = (lambda v: sum(v) / len(v) if v else float("nan"))
    r["_pairs"] = coll + other  # per run: |U| at the end of the dwell at f_1 and the final |U| [1e-7 kg m]
    r.update({"rin1": rin1, "rin_hold": rin_h, "q": rin1 / rin_h, "share_collected": len(coll) / n if n else float("nan"),
              "u1_collected_over_rin1": mean([u for u, _ in coll]) / rin1,
              "final_collected_over_rlock": mean([v for _, v in coll]) / rl,
              "final_others_over_rlock": mean([v for _, v in other]) / rl,
              "share_collected_moved": moved / len(coll) if coll else float("nan"),
              "predicted_fold_over_rlock": pred / rl,
              "final_collected_p10_over_rlock": quantile([v for _, v in coll], 0.1) / rl if coll else float("nan"),
              "final_collected_p90_over_rlock": quantile([v for _, v in coll], 0.9) / rl if coll else float("nan")})
    return r


def release(a):
    for k, v in (("--dwell1", a.dwell1), ("--dwell2", [a.dwell2]), ("--approach-s", a.approach_s)):
        if min(v) <= 0:
            sys.exit(f"{k} {min(v):g}: must be > 0")
    if min(a.step) < 0:
        sys.exit(f"--step {min(a.step):g}: must be >= 0 (0: the acceleration limit)")
    chains = [[f1, f2] for f1 in a.f1 for f2 in a.f2]
    for st in a.stairs:
        try:
            c = [float(v) for v in st.split(":")]
        except ValueError:
            sys.exit(f"--stairs {st}: must be frequencies separated by ':' (e.g. 29.6:29.2:28.9)")
        if len(c) < 2:
            sys.exit(f"--stairs {st}: needs at least two frequencies")
        chains.append(c)
    rows = []
    for mu in a.mu:
        for c in chains:
            for ap_s, t1, st in [(x, y, z) for x in a.approach_s for y in a.dwell1 for z in a.step]:
                    r = run_release(a, c, ap_s, t1, st, mu)
                    rows.append(r)
                    print(f"release {r['freqs']:>16s} approach {ap_s:4.2f} t1 {t1:4.1f} step {r['step_s']:5.3f} s mu {mu:.2f}: mean "
                          f"{r['mean']:6.2f} = {r['mean_over_rlock']:.3f} r_lock; collected {100 * r['share_collected']:5.1f} % "
                          f"-> {r['final_collected_over_rlock']:.3f} r_lock (fold predicts {r['predicted_fold_over_rlock']:.3f}), "
                          f"others {r['final_others_over_rlock']:.3f}", flush=True)
    release_runs_plot(a, rows)
    for r in rows:
        del r["_pairs"]
    with open(os.path.join(a.out, "stop_depth_release.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    lines = [f"# Aimed release: dwell at f_1, fast step(s) to the hold speed ({a.runs} random starts, seed {a.seed}, "
             f"contact hard, last dwell {a.dwell2:g} s)", "",
             "collected: runs with |U| >= 0.9 r_in(f_1) at the end of the dwell at f_1 (same starts, profile cut there); "
             "fold: the 1-D Coulomb oscillator's stop of a run released at rest on that boundary.", ""]
    for mu in a.mu:
        sub = sorted((r for r in rows if r["mu"] == mu), key=lambda r: r["mean_over_rlock"])
        lines += [f"mu {mu:g} (r_lock {r_lock(mu):.2f}): {len(sub)} cases, mean / r_lock from {sub[0]['mean_over_rlock']:.3f} "
                  f"to {sub[-1]['mean_over_rlock']:.3f}", "",
                  "| speeds [Hz] | approach [s] | t_1 [s] | step [s] | r_in(f_1) / r_in(f_h) | mean \|I_r\| [95 %] | mean / r_lock | "
                  "share <= 0.44 r_lock | collected | collected: \|U\| / r_in(f_1) at release | collected: final / r_lock "
                  "(p10, p90) | fold predicts | collected runs that moved | others: final / r_lock |", "|" + "---|" * 14]
        for r in sub:
            lines.append(f"| {r['freqs'].replace('_', ' -> ')} | {r['approach_s']:g} | {r['dwell1_s']:g} | {r['step_s']:.3g} | {r['q']:.2f} | "
                         f"{r['mean']:.2f} +- {r['hw95']:.2f} | {r['mean_over_rlock']:.3f} | "
                         f"{100 * r['share_at_goal_depth']:.1f} % | {100 * r['share_collected']:.1f} % | "
                         f"{r['u1_collected_over_rin1']:.3f} | {r['final_collected_over_rlock']:.3f} "
                         f"({r['final_collected_p10_over_rlock']:.3f}, {r['final_collected_p90_over_rlock']:.3f}) | "
                         f"{r['predicted_fold_over_rlock']:.3f} | {100 * r['share_collected_moved']:.0f} % | "
                         f"{r['final_others_over_rlock']:.3f} |")
        lines.append("")
    def release_row(r):
        if r["steps"] != 1:
            return None
        rl_over_rin = r_lock(r["mu"]) / r["rin_hold"]
        return (f"{r['q']:.4f} {r['final_collected_over_rlock'] * rl_over_rin:.4f} {abs(2 - r['q']):.4f} "
                f"{r['mean_over_rlock'] * rl_over_rin:.4f}\n")

    write_md_and_dat(a, "stop_depth_release", lines, rows,
                     lambda mu: f"# mu {mu}: r_in(f_1) / r_in(f_h), collected runs' final / r_in(f_h), fold |2 - q|, all runs\n",
                     release_row)
    plots = ", ".join(f"'stop_depth_release.dat' index {k} using 1:2 with points pt {7 + k} ps 1.0 title 'collected runs, mu {mu:g}', "
                      f"'' index {k} using 1:4 with points pt {4 + k} ps 0.8 title 'all runs, mu {mu:g}'"
                      for k, mu in enumerate(a.mu))
    qs = [r["q"] for r in rows if r["steps"] == 1]
    write_plot(a.out, "stop_depth_release",
               f"set title 'aimed release: mean final |I_r| / r_in(f_h) against r_in(f_1) / r_in(f_h) ({a.runs} starts, "
               "contact hard)'\nset xlabel 'r_in(f_1) / r_in(f_h) (the fold aims at 2)'\n"
               f"set xrange [{min(qs) - 0.1:.3f}:{max(qs) + 0.1:.3f}]\nset samples 200\n"
               "set ylabel 'mean final |I_r| / r_in(f_h)'\nset yrange [0:*]\nset key top left\n"
               f"plot {plots}, abs(2 - x) with lines lw 2 lc rgb 'black' title '1-D fold |2 - q| (Coulomb oscillator)'\n")


def release_runs_plot(a, rows):
    """Per run, final |U| against |U| at the end of the dwell at f_1, for the case per friction whose fold aims
    nearest to a balancing point (one step, f_1 above resonance, the most runs collected among |q - 2| <= 0.3), beside
    the 1-D fold: a run at |U| > r_in(f_2) stops at |2 r_in(f_2) - |U||, one inside stays."""
    fn = OMEGA_N / (2 * math.pi)
    picks = []
    for mu in a.mu:
        cand = [r for r in rows if r["mu"] == mu and r["steps"] == 1 and r["f1_hz"] > fn and abs(r["q"] - 2) <= 0.3]
        if cand:
            picks.append(max(cand, key=lambda r: (r["share_collected"], -abs(r["q"] - 2))))
    if not picks:
        return
    lines = []
    with open(os.path.join(a.out, "stop_depth_release_runs.dat"), "w") as f:
        for k, r in enumerate(picks):
            rl, rin2 = r_lock(r["mu"]), r["rin_hold"]
            f.write(f"# {r['freqs']} approach {r['approach_s']:g} s step {r['step_s']:.3g} s mu {r['mu']}: "
                    "|U| at release / r_in(f_1), final / r_lock, 1-D fold / r_lock\n")
            for u1, uf in r["_pairs"]:
                fold = abs(2 * rin2 - u1) if u1 > rin2 else u1
                f.write(f"{u1 / r['rin1']:.4f} {uf / rl:.4f} {fold / rl:.4f}\n")
            f.write("\n\n")
            lines.append(f"'stop_depth_release_runs.dat' index {k} using 1:2 with points pt {7 + k} ps 0.6 title "
                         f"'{r['freqs'].replace('_', ' -> ')} Hz, mu {r['mu']:g}: final', "
                         f"'' index {k} using 1:3 with points pt 1 ps 0.4 lc rgb '{'black' if k == 0 else 'gray40'}' "
                         f"title '1-D fold, mu {r['mu']:g}'")
    write_plot(a.out, "stop_depth_release_runs",
               f"set title 'aimed release, per run ({a.runs} starts): final |I_r| against |I_r| at the end of the dwell "
               "at f_1'\nset xlabel '|I_r| at the end of the dwell at f_1 / r_in(f_1)  (>= 0.9: collected on the "
               "boundary)'\nset ylabel 'final |I_r| / r_lock(mu)'\nset yrange [0:*]\nset xrange [0:*]\n"
               "set key top left\nset arrow from 0.9, graph 0 to 0.9, graph 1 nohead dt 2\n"
               f"plot {', '.join(lines)}, {GOAL_FRACTION} with lines lw 2 lc rgb 'black' title 'goal 0.44 r_lock'\n")


def write_md_and_dat(a, stem, lines, rows, header, row_text):
    """OUT/stem.md (the lines, also printed) and OUT/stem.dat: one gnuplot index per friction of a.mu,
    header(mu) then row_text(r) of each of its rows (None: the row is left out)."""
    with open(os.path.join(a.out, stem + ".md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))
    with open(os.path.join(a.out, stem + ".dat"), "w") as f:
        for mu in a.mu:
            f.write(header(mu))
            for r in rows:
                text = row_text(r) if r["mu"] == mu else None
                if text is not None:
                    f.write(text)
            f.write("\n\n")


def write_plot(out, name, body):
    """Write OUT/NAME.gp (the common preamble: a 1000 x 650 PNG OUT/NAME.png, grid) followed by body, and run
    gnuplot on it in OUT if gnuplot is installed (the data files body names are relative to OUT)."""
    with open(os.path.join(out, name + ".gp"), "w") as f:
        f.write(f"set terminal pngcairo size 1000,650 noenhanced\nset output '{name}.png'\nset grid\n" + body)
    gp = shutil.which("gnuplot")
    if gp:
        subprocess.run([gp, name + ".gp"], cwd=out, capture_output=True)


def parser():
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
    ap.add_argument("--family", choices=["approach", "oscillate", "release"], default="approach")
    ap.add_argument("--f1", type=float, nargs="+", default=[28.2, 28.3, 28.4, 29.4, 29.45, 29.5, 29.6],
                    help="release: the collecting speed f_1 [Hz]")
    ap.add_argument("--f2", type=float, nargs="+", default=[28.85, 28.9, 29.0], help="release: the hold speed f_2 [Hz]")
    ap.add_argument("--stairs", nargs="*", default=[], help="release: staircases f_1:f_2:...:f_h [Hz] (dwell t_1 at each but the last)")
    ap.add_argument("--dwell1", type=float, nargs="+", default=[3.0, 8.0], help="release: dwell t_1 at f_1 [s]")
    ap.add_argument("--dwell2", type=float, default=HOLD_S, help="release: dwell at the hold speed [s]")
    ap.add_argument("--step", type=float, nargs="+", default=[0.0, 0.5],
                    help="release: step duration [s] (0: the acceleration limit, peak rate %g Hz/s)" % MAX_RATE_HZ_S)
    ap.add_argument("--approach-s", type=float, nargs="+", default=[3.0, 0.25],
                    help="release: 25 Hz -> f_1 in this time [s] (fast: the balls cross resonance without stopping)")
    ap.add_argument("--center", type=float, nargs="+", default=[28.9, 29.2, 29.5], help="oscillate: f_c [Hz]")
    ap.add_argument("--amplitude", type=float, nargs="+", default=[0.2, 0.5, 1.0, 1.5], help="oscillate: A [Hz]")
    ap.add_argument("--period", type=float, nargs="+", default=[0.5, 1, 2, 4], help="oscillate: P [s]")
    ap.add_argument("--cycles", type=int, nargs="+", default=[1, 2, 4], help="oscillate: n")
    ap.add_argument("--dwell", type=float, nargs="+", default=[28.93, 29.0], help="oscillate: f_d [Hz]")
    return ap


def main():
    a = parser().parse_args()
    if a.runs < 2:
        sys.exit(f"--runs {a.runs}: must be >= 2")
    if not os.access(a.abuopt, os.X_OK):
        sys.exit(f"--abuopt {a.abuopt}: not an executable")
    os.makedirs(a.out, exist_ok=True)
    if a.family == "oscillate":
        return oscillate(a)
    if a.family == "release":
        return release(a)
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
    # colour: the approach and hold (the same for every friction), line: up solid / down dashed, points: open for the
    # first friction, filled for the second
    colours = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b"]
    per_mu = 2 * len(a.hold)
    plots = ", ".join(f"'stop_depth.dat' index {k} using 1:2 with linespoints lw 1.5 dt {1 if 'up' in s else 2} "
                      f"lc rgb '{colours[(k % per_mu) % len(colours)]}' pt {(6, 7, 4, 5)[min(k // per_mu, 3)]} "
                      f"title '{s}'" for k, s in enumerate(series))
    write_plot(a.out, "stop_depth",
               f"set title 'mean |I_r| / r_lock(mu) against the approach duration ({a.runs} starts, contact hard)'\n"
               "set xrange [0.2:40]\nset xlabel 'approach duration D to the hold frequency [s] (log)'\nset logscale x\n"
               "set ylabel 'mean |I_r| / r_lock(mu)'\nset yrange [0:*]\nset key outside right\n"
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
    write_md_and_dat(a, "stop_depth_osc", lines, rows, lambda mu: f"# mu {mu}: peak rate, mean / r_lock, cycles\n",
                     lambda r: f"{r['peak_rate_hz_s']:.4f} {r['mean_over_rlock']:.4f} {r['cycles']}\n")
    plots = ", ".join(f"'stop_depth_osc.dat' index {k} using 1:2 with points pt {7 + k} ps 0.8 title 'mu {mu:g}'"
                      for k, mu in enumerate(a.mu))
    write_plot(a.out, "stop_depth_osc",
               f"set title 'oscillations through the band: mean |I_r| / r_lock(mu) per case ({a.runs} starts, "
               "contact hard)'\nset logscale x\nset xlabel 'peak rate of the profile after 25 Hz [Hz/s] (log)'\n"
               "set ylabel 'mean |I_r| / r_lock(mu)'\nset yrange [0:*]\nset key bottom right\n"
               f"plot {plots}, {GOAL_FRACTION} with lines lw 2 lc rgb 'black' title 'goal 7.0e-7 = 0.44 r_lock'\n")


if __name__ == "__main__":
    main()
