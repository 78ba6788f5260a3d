#!/usr/bin/env python3
"""Where the final ball positions of a Monte Carlo lie relative to the equilibrium set.

Reads the runs.csv of `abuopt montecarlo ... --out DIR` (two balls) and, for every settled run,
the frequency f_s of the profile at its settling time; prints the distribution of f_s, of the
final |I_r| against r_in(f_s) (the inscribed disc of docs/equilibrium_sets.md section 4) and
r_lock, and whether the final configuration is in the set at f_s (closed-form membership test of
section 1). Parameters are the report's (table 3.2), as in configs/eqset.yaml.

    scripts/final_states_in_set.py results/mc/runs.csv --profile 25:1,29.5:10,100:8 [--mu 0.02]
"""
import argparse
import cmath
import csv
import math
import statistics
import sys

MT, B, K, L, MI, E = 0.324, 1.28, 1.07e4, 1.15e-2, 5.6e-4, 3.7e-3
M_BALL = 1.4e-4


def profile_frequency(segments, t, f0=0.0):
    t0 = 0.0
    for f_end, dt in segments:
        if t <= t0 + dt:
            phi = 2 * math.pi * (t - t0) / dt
            return f0 + (f_end - f0) / (2 * math.pi) * (phi - math.sin(phi))
        t0 += dt
        f0 = f_end
    return f0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("runs_csv")
    ap.add_argument("--profile", required=True, help="segments f_end:dt,... starting at 0 Hz")
    ap.add_argument("--mu", type=float, default=0.02)
    a = ap.parse_args()
    segments = [tuple(float(v) for v in s.split(":")) for s in a.profile.split(",")]
    M = MT + MI + 2 * M_BALL
    wn = math.sqrt(K / M)
    bbar = B / (2 * M * wn)
    mu = a.mu

    def gain(f):
        W = 2 * math.pi * f / wn
        return W * W / complex(1 - W * W, 2 * bbar * W)

    def r_in(f):
        return M * L * mu / ((1 + mu) * abs(gain(f)))

    r_lock = M * L * mu * 2 * bbar * math.sqrt(1 - bbar * bbar) / (1 + mu)

    def in_set(f, betas):
        C = (MI * E + sum(M_BALL * L * cmath.exp(1j * b) for b in betas)) / (M * L)
        z = gain(f) * C
        for b in betas:
            w = z * cmath.exp(-1j * b)
            if abs(w.imag) > mu * (1 + w.real) + 1e-12:
                return False
        return True

    rows = [r for r in csv.DictReader(open(a.runs_csv)) if r["status"] == "ok" and r["settled"] == "1"]
    if not rows:
        sys.exit("no settled runs")
    fs, ratio, ir, inside, inside_all = [], [], [], 0, 0
    for r in rows:
        t = float(r["settling_time_s"])
        f = profile_frequency(segments, t)
        betas = [float(r["beta_final_1"]), float(r["beta_final_2"])]
        u = float(r["ir_magnitude_kgm"])
        fs.append(f)
        ir.append(u)
        ratio.append(u / r_in(f))
        inside += in_set(f, betas)
        inside_all += all(in_set(g, betas) for g in [f] + [f + 0.05 * k for k in range(1, 2000) if f + 0.05 * k <= 100])

    def q(v, p):
        v = sorted(v)
        return v[min(len(v) - 1, int(p * (len(v) - 1) + 0.5))]

    n = len(rows)
    print(f"settled runs: {n}; mu = {mu}; r_lock = {r_lock / 1e-7:.2f}e-7 kg m")
    print(f"frequency at settling [Hz]: p10 {q(fs, 0.1):.3f}  median {q(fs, 0.5):.3f}  p90 {q(fs, 0.9):.3f}")
    print(f"final |I_r| [1e-7]: mean {statistics.mean(ir) / 1e-7:.2f}  median {q(ir, 0.5) / 1e-7:.2f}  "
          f"p90 {q(ir, 0.9) / 1e-7:.2f}")
    print(f"final |I_r| / r_in(f at settling): p10 {q(ratio, 0.1):.3f}  median {q(ratio, 0.5):.3f}  "
          f"p90 {q(ratio, 0.9):.3f}")
    print(f"runs with final |I_r| < r_lock (in the set at every speed): {sum(u < r_lock for u in ir) / n * 100:.1f} %")
    # Pair separation: a run whose balls end s apart cannot leave less than |m_I e - 2 m L cos(s/2)|.
    def sep(r):
        d = (float(r["beta_final_1"]) - float(r["beta_final_2"])) % (2 * math.pi)
        return min(d, 2 * math.pi - d)

    seps = [sep(r) for r in rows]
    goal = 7.0e-7
    s_goal = 2 * math.acos((MI * E + goal) / (2 * M_BALL * L))  # smallest separation allowing |I_r| <= goal
    print(f"ball separation at the end [rad]: p10 {q(seps, 0.1):.3f}  median {q(seps, 0.5):.3f}  p90 {q(seps, 0.9):.3f}; "
          f"closer than a ball diameter (0.262): {sum(x < 0.262 for x in seps) / n * 100:.1f} %; "
          f"at least {s_goal:.3f} (needed for |I_r| <= 7e-7): {sum(x >= s_goal for x in seps) / n * 100:.1f} %")
    # Orientation: the pair's resultant against the balancing direction (opposite the imbalance, angle pi).
    # With separation s (b = 2 m L cos(s/2)) and orientation error delta, |I_r|^2 = a^2 + b^2 - 2 a b cos(delta),
    # a = m_I e: |I_r| <= goal needs the separation band above AND |delta| small (at the balancing separation,
    # b = a: |delta| <= 2 asin(goal / 2a)).
    def orientation_error(r):
        v = cmath.exp(1j * float(r["beta_final_1"])) + cmath.exp(1j * float(r["beta_final_2"]))
        return abs(cmath.phase(-v))

    a_ = MI * E
    d_max = 2 * math.asin(goal / (2 * a_))
    band = [r for r, x in zip(rows, seps) if x >= s_goal and x <= 2 * math.acos((a_ - goal) / (2 * M_BALL * L))]
    errs = [orientation_error(r) for r in rows]
    band_errs = [orientation_error(r) for r in band]
    print(f"pair orientation error (resultant against the balancing direction) [deg]: median "
          f"{math.degrees(q(errs, 0.5)):.1f}; of the {len(band) / n * 100:.1f} % of runs in the separation band "
          f"for |I_r| <= {goal / 1e-7:.1f}: median {math.degrees(q(band_errs, 0.5)) if band else float('nan'):.1f}, "
          f"within {math.degrees(d_max):.1f} (the balancing separation's bound): "
          f"{sum(x <= d_max for x in band_errs) / n * 100:.1f} % of all runs")
    # Reference: uniformly random angles (the fraction of the torus with |I_r| <= goal), 512 x 512 grid.
    g = 512
    hits = sum(1 for i in range(g) for j in range(g)
               if abs(a_ + M_BALL * L * (cmath.exp(2j * math.pi * i / g) + cmath.exp(2j * math.pi * j / g))) <= goal)
    print(f"runs with final |I_r| <= {goal / 1e-7:.1f}: {sum(u <= goal for u in ir) / n * 100:.1f} % "
          f"(uniformly random angles: {hits / g / g * 100:.1f} % of the torus)")
    print(f"runs whose final state is in the set at f(settling): {inside / n * 100:.1f} %; "
          f"at every frequency from there to 100 Hz (0.05 Hz steps): {inside_all / n * 100:.1f} %")


if __name__ == "__main__":
    main()
