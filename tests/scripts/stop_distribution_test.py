#!/usr/bin/env python3
"""Tests of scripts/stop_distribution.py (the floor of the locked runs, docs/studies/startup-profile.md 8.1 and
docs/equilibrium_sets.md section 6).

    stop_distribution_test.py ABUOPT

Checked against closed forms: the balancing points have U = 0 and the singular values of dU/dbeta there are
sqrt(2) m L (cos(s*/2), sin(s*/2)) (finite differences); near a balancing point uniform starts are uniform in the
U plane with density 1 / ((2 pi)^2 (m L)^2 sin s*) per point (the share of the torus with |U| <= r, small r);
the lemma |U| >= g(f) r_in(f) for every configuration in the set (random configurations and speeds); the
Kolmogorov-Smirnov distance of a disc-uniform sample from t^2 and from t (1/4); the lock set contains the disc
|U| <= r_lock. And one Monte Carlo of the robust design through abuopt (256 starts): the runs locked before the
band are as many and as deep as uniform starts in the lock set, within binomial and sampling tolerances; no
close pair ends below the pair floor of its separation; the CDF plot's data has one line per run.
"""
import cmath
import math
import os
import random
import subprocess
import sys
import tempfile

from script_check import ROOT, check, failures, load_script

sd = load_script("stop_distribution")
ML = sd.M_BALL * sd.L


def closed_forms():
    s = sd.balancing_separation()
    check(abs(s - 1.7435) < 5e-5, f"balancing separation s* = {s:.5f} rad (docs: 1.7435)")
    for sign in (1, -1):
        b = (math.pi - sign * s / 2, math.pi + sign * s / 2)
        check(abs(sd.imbalance(b)) < 1e-12 * sd.MI * sd.E, f"U = 0 at the balancing point {sign:+d}")
        h = 1e-6
        cols = [(sd.imbalance((b[0] + h, b[1])) - sd.imbalance((b[0] - h, b[1]))) / (2 * h),
                (sd.imbalance((b[0], b[1] + h)) - sd.imbalance((b[0], b[1] - h))) / (2 * h)]
        # singular values of the real 2 x 2 matrix [Re c1 Re c2; Im c1 Im c2]
        a11, a12, a21, a22 = cols[0].real, cols[1].real, cols[0].imag, cols[1].imag
        fro2, det = a11 ** 2 + a12 ** 2 + a21 ** 2 + a22 ** 2, abs(a11 * a22 - a12 * a21)
        hi = math.sqrt((fro2 + math.sqrt(fro2 ** 2 - 4 * det ** 2)) / 2)
        lo = det / hi
        chi, clo = sd.jacobian_singular_values(s)
        check(abs(hi - chi) < 1e-7 * chi and abs(lo - clo) < 1e-7 * clo,
              f"singular values of dU/dbeta {hi / ML:.5f}, {lo / ML:.5f} m L = closed form {chi / ML:.5f}, {clo / ML:.5f}")
    check(abs(chi / clo - 1.190) < 1e-3, f"their ratio {chi / clo:.4f} (docs: 1.190)")
    # Uniform starts near the balancing points: P(|U| <= r) = 2 pi r^2 / ((2 pi)^2 (m L)^2 sin s*) for small r.
    r, g = 0.15 * ML, 1200
    hits = sum(1 for i in range(g) for j in range(g)
               if abs(sd.imbalance((2 * math.pi * (i + 0.5) / g, 2 * math.pi * (j + 0.5) / g))) <= r)
    expect = r * r / (2 * math.pi * ML * ML * math.sin(s))
    check(abs(hits / g / g - expect) < 0.05 * expect,
          f"share of the torus with |U| <= 0.15 m L: {hits / g / g:.5f} (uniform in the U plane: {expect:.5f})")


def lemma():
    rng = random.Random(7)
    n_in, worst = 0, math.inf
    for _ in range(20000):
        b = (rng.uniform(0, 2 * math.pi), rng.uniform(0, 2 * math.pi))
        f, mu = rng.uniform(20, 40), rng.choice((0.02, 0.03, 0.04))
        gg = sd.gauge(f, b, mu)
        if gg <= 1:
            n_in += 1
            worst = min(worst, abs(sd.imbalance(b)) / (gg * sd.r_in(f, mu)) if gg > 0 else math.inf)
    check(n_in > 1000 and worst >= 1 - 1e-12,
          f"|U| >= g(f) r_in(f) in every one of {n_in} random configurations in the set (least ratio {worst:.4f})")
    check(all(sd.r_in(20 + 0.01 * k, 0.03) >= sd.r_lock(0.03) * (1 - 1e-12) for k in range(2001)),
          "r_in(f) >= r_lock from 20 to 40 Hz")
    n = 400
    disc = [math.sqrt((k + 0.5) / n) for k in range(n)]  # radii of a disc-uniform sample: CDF t^2
    check(sd.ks_power(disc, 2) <= 1.0 / n + 1e-12 and abs(sd.ks_power(disc, 1) - 0.25) <= 1.0 / n,
          f"KS of a disc-uniform sample: from t^2 {sd.ks_power(disc, 2):.4f} (<= 1/n), from t {sd.ks_power(disc, 1):.4f} "
          "(1/4 = max t - t^2)")


def lock_set():
    mu, g = 0.03, 40
    x = sd.torus_lock_stats(mu, g, reach=sd.euler_reach(mu, 314.16))
    disc = sum(1 for i in range(g) for j in range(g)
               if abs(sd.imbalance((2 * math.pi * (i + 0.5) / g, 2 * math.pi * (j + 0.5) / g))) <= sd.r_lock(mu)) / g / g
    check(disc <= x["share"] < 1, f"the lock set holds the disc |U| <= r_lock: {x['share']:.3f} >= {disc:.3f}")
    check(abs(sd.CONTACT_SEPARATION - 0.2616) < 5e-5 and abs(sd.touching_floor() - 11.20e-7) < 0.005e-7,
          f"contact distance {sd.CONTACT_SEPARATION:.4f} rad, touching-pair floor {sd.touching_floor() / 1e-7:.3f}e-7 "
          "(docs/equilibrium_sets.md 5: 0.2616, 11.20)")
    s = sd.CONTACT_SEPARATION
    check(sd.is_touching((1.0, 1.0 + s + 0.039)) and sd.is_touching((6.2, 6.2 + s - 2 * math.pi))
          and not sd.is_touching((1.0, 1.0 + s + 0.05)), "a close pair: within 0.04 rad of the contact distance, "
          "across 2 pi too")
    check(x["unreached_share"] < x["share"] and x["unreached_depth_mean"] < x["depth_mean"],
          "the starts out of the Euler term's reach are fewer and deeper")
    check(abs(sd.euler_reach(0.03, 314.16) - 314.16 / (0.03 * (2 * math.pi * sd.F_N) ** 2)) < 1e-15
          and 0.31 < sd.euler_reach(0.03, 314.16) < 0.33, f"Euler reach at mu 0.03: {sd.euler_reach(0.03, 314.16):.3f}")
    return x


def monte_carlo(abuopt):
    """The robust design at mu 0.03 on 256 random starts: its early runs against uniform starts in the lock set
    (grid 160: 50.2 %, mean depth 0.739 r_lock; the test's grid 40 is within 0.01 of it)."""
    x = sd.torus_lock_stats(0.03, 40)
    cfg = os.path.join(ROOT, "configs", "studies", "best", "contact_best_mu03_k4.yaml")
    segs = [(22.6222, 1.55852), (28.9129, 3.4931), (28.9129, 3.71217), (100, 5.08554)]
    with tempfile.TemporaryDirectory() as tmp:
        r = subprocess.run([abuopt, "montecarlo", cfg, "--mu", "0.03", "--runs", "256", "--seed", "9001",
                            "--threads", "1", "--out", tmp], capture_output=True, text=True)
        check(r.returncode == 0, "abuopt montecarlo of contact_best_mu03_k4 at mu 0.03 (256 starts) runs")
        if r.returncode != 0:
            return
        rows = sd.read_runs(os.path.join(tmp, "runs.csv"))
        out = sd.analyse_runs(rows, segs, 0.03)
    n = out["runs"]
    mean_ir = sum(float(r["ir_magnitude_kgm"]) for r in rows) / len(rows)
    check(n == 256 and abs(out["depth_mean"] - mean_ir / sd.r_lock(0.03)) < 1e-9,
          "early + late: all 256 runs, and their mean depth is the Monte Carlo's mean / r_lock")
    p, tol = x["share"], 3 * math.sqrt(x["share"] * (1 - x["share"]) / n)
    e = out["early"]
    check(abs(e["share"] - p) <= tol, f"early runs {e['share'] * 100:.1f} % = uniform starts in the lock set "
          f"{p * 100:.1f} % +- {tol * 100:.1f} (3 binomial sigma)")
    check(abs(e["depth_mean"] - x["depth_mean"]) <= 0.08,
          f"their mean depth {e['depth_mean']:.3f} r_lock = the lock set's {x['depth_mean']:.3f} +- 0.08 "
          "(3 standard errors of about 130 runs)")
    check(e["f_s_p90"] < 23 and out["late"]["f_s_p10"] > 28,
          f"early runs stop in the first ramp (p90 {e['f_s_p90']:.2f} Hz), late ones above 28 Hz")
    close = [x for x in out["records"]["late"] if x["touching"]]
    floor = lambda sep: abs(sd.MI * sd.E - 2 * sd.M_BALL * sd.L * math.cos(sep / 2))  # noqa: E731
    check(len(close) > 20 and all(x["depth"] * sd.r_lock(0.03) >= floor(x["separation"]) * (1 - 1e-12) for x in close),
          f"no close pair of the late runs ({len(close)}) ends below the pair floor |m_I e - 2 m L cos(s/2)| of its "
          "separation")
    with tempfile.TemporaryDirectory() as tmp:
        sd.write_cdf_plot(out, tmp, "test")
        blocks = open(os.path.join(tmp, "stop_distribution.dat")).read().split("\n\n\n")
        sizes = [len([l for l in b.splitlines() if l and not l.startswith("#")]) for b in blocks if b.strip()]
        n_e, n_l = len(out["records"]["early"]), len(out["records"]["late"])
        check(sizes == [n_e, n_l, n_e, n_l], f"the CDF data has one line per run in each of its four blocks {sizes}")
        check(os.path.exists(os.path.join(tmp, "stop_distribution.gp")), "the gnuplot script is written")


def main(abuopt):
    closed_forms()
    lemma()
    lock_set()
    monte_carlo(abuopt)
    print(f"{len(failures)} failure(s)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
