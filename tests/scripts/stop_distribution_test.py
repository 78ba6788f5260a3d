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
N balls (six of the two balls' total mass): U = 0 at a hand-made balancing configuration (three pairs at pi -+ theta_k,
sum cos theta_k = m_I e / (2 m L)), where the gauge is 0; six touching balls have the cluster floor |m_I e - m L
sin(3 s_c) / sin(s_c / 2)| = 9.96e-7 kg m; two balls through the N-ball code give the two-ball numbers (M, r_lock,
gauge; the cluster floor is the pair floor of a close pair, 0 apart); the lemma for six balls; a hand-made six-ball
runs.csv through the command line (early / late shares, depths, the passage split); and abuopt's |I_r| of six balls
is |U| of their final angles.
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


def n_balls():
    """The N-ball extension, checked by hand (docs: stop_distribution.py's docstring, the cluster floor)."""
    six = sd.Abu.equal_mass(6)
    m, d = six.masses[0], six.diameters[0]
    check(abs(six.M - sd.M) < 1e-15 and abs(sd.r_lock(0.03, six) - sd.r_lock(0.03)) < 1e-20
          and abs(m - 4.6667e-5) < 1e-9 and abs(d - 2.0801e-3) < 1e-7,
          f"six balls of the two balls' total mass: m {m:.4e} kg, d {d * 1e3:.4f} mm, the same M and r_lock")
    # A balancing configuration: pairs at pi -+ theta_k with sum cos theta_k = m_I e / (2 m L) = 1.9304.
    c = sd.MI * sd.E / (2 * m * sd.L)
    cos3 = [0.9, 0.65, c - 1.55]
    b = []
    for ck in cos3:
        t = math.acos(ck)
        b += [math.pi - t, math.pi + t]
    check(abs(c - 1.9304) < 1e-4 and abs(sd.imbalance(b, six)) < 1e-12 * sd.MI * sd.E,
          f"U = 0 at pairs pi -+ acos({cos3[0]}, {cos3[1]}, {cos3[2]:.4f}) (sum of cosines {c:.4f})")
    check(sd.gauge(28.9, b, 0.03, six) < 1e-9 and sd.lock_gauge(b, 0.03, abu=six) < 1e-9
          and sd.cluster_floor(b, six) == 0.0 and len(sd.clusters(b, six)) == 6,
          "there the gauge and the lock gauge are 0 (<= 1: locked), the six balls are apart, the cluster floor 0")
    s = sd.contact_separation(d, d)
    chain = [math.pi + (k - 2.5) * s for k in range(6)]  # six touching balls centred opposite the imbalance
    closed = abs(sd.MI * sd.E - m * sd.L * math.sin(3 * s) / math.sin(s / 2))
    check(abs(s - 0.18112) < 5e-5 and abs(closed - 9.96e-7) < 0.005e-7 and len(sd.clusters(chain, six)) == 1
          and abs(abs(sd.imbalance(chain, six)) - closed) < 1e-15 and abs(sd.cluster_floor(chain, six) - closed) < 1e-15
          and abs(sd.one_cluster_floor(six) - closed) < 1e-15,
          f"six touching balls (s_c {s:.5f} rad): one cluster, |U| = its floor = {closed / 1e-7:.3f}e-7 (closed form)")
    five = chain[:5] + [chain[5] + 0.5]  # one ball off the chain: the floor max(0, 2 max a - sum a) = 0
    check(len(sd.clusters(five, six)) == 2 and sd.cluster_floor(five, six) == 0.0,
          "five touching and one apart: two clusters, no floor (2 max a < sum a)")
    two = sd.Abu.equal_mass(2)
    rng = random.Random(11)
    worst_g, worst_floor, n_close, n_in, least = 0.0, 0.0, 0, 0, math.inf
    for _ in range(3000):
        bb = (rng.uniform(0, 2 * math.pi), rng.uniform(0, 2 * math.pi))
        if rng.random() < 0.3:
            bb = (bb[0], bb[0] + rng.choice((1, -1)) * (sd.CONTACT_SEPARATION + rng.uniform(-0.03, 0.04)))
        worst_g = max(worst_g, abs(sd.gauge(29.0, bb, 0.03, two) - sd.gauge(29.0, bb, 0.03)))
        pair = abs(sd.MI * sd.E - 2 * sd.M_BALL * sd.L * math.cos(sd.separation(bb) / 2)) if sd.is_touching(bb) else 0.0
        n_close += sd.is_touching(bb)
        worst_floor = max(worst_floor, abs(sd.cluster_floor(bb) - pair))
        b6 = [rng.uniform(0, 2 * math.pi) for _ in range(6)]
        f, mu = rng.uniform(20, 40), rng.choice((0.02, 0.03, 0.04))
        g6 = sd.gauge(f, b6, mu, six)
        if g6 <= 1:
            n_in += 1
            least = min(least, abs(sd.imbalance(b6, six)) / (g6 * sd.r_in(f, mu, six)) if g6 > 0 else math.inf)
    check(worst_g < 1e-12 and worst_floor < 1e-18 and n_close > 500,
          f"two balls through the N-ball code: the same gauge, the cluster floor = the pair floor ({n_close} close pairs) "
          "or 0")
    check(n_in > 300 and least >= 1 - 1e-12, f"six balls: |U| >= g(f) r_in(f) in all {n_in} random configurations in "
          f"the set (least ratio {least:.4f})")
    # A hand-made runs.csv: two runs settled in the first ramp (0 -> 25 Hz in 1 s), one at the balancing configuration
    # (depth 0), one touching chain (depth 9.96e-7 / r_lock); two in the last ramp (after 11 s), the chain and a
    # balancing configuration; one not settled (left out).
    rl = sd.r_lock(0.03, six)
    runs = [(0.8, b, 1), (0.9, chain, 1), (12.0, chain, 1), (13.0, b, 1), (38.0, chain, 0)]
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "runs.csv")
        with open(path, "w") as fh:
            fh.write("index," + ",".join(f"beta0_{k}" for k in range(1, 7)) + ",mu,imbalance_mass_kg,imbalance_angle_rad,"
                     + ",".join(f"beta_final_{k}" for k in range(1, 7))
                     + ",ir_magnitude_kgm,ir_x_kgm,settled,settling_time_s,max_amplitude_mm,events,rhs_evaluations,status\n")
            for i, (t, bb, settled) in enumerate(runs):
                fh.write(f"{i}," + ",".join("0" for _ in range(6)) + ",0.03,,0," + ",".join(f"{x:.17g}" for x in bb)
                         + f",{abs(sd.imbalance(bb, six)):.17g},0,{settled},{t},0.1,1,1,ok\n")
        script = os.path.join(ROOT, "scripts", "stop_distribution.py")
        prof = "25:1,29.5:10,100:8"
        r = subprocess.run([sys.executable, script, "runs", path, "--profile", prof, "--mu", "0.03", "--balls", "6",
                            "--ci"], capture_output=True, text=True)
        depth = closed / rl
        check(r.returncode == 0 and "4 settled runs" in r.stdout and f"mean depth {depth / 2:.3f} r_lock" in r.stdout
              and f"early  50.0 %: mean depth {depth / 2:.3f}" in r.stdout and f"late   50.0 %: mean depth {depth / 2:.3f}"
              in r.stdout and "held by a cluster 50.0 %" in r.stdout,
              f"CLI, six balls: 4 settled runs, early 50 % and late 50 % both at {depth / 2:.3f} r_lock (half at 0, half "
              f"at the chain's {depth:.3f}), half of each held by a cluster")
        r2 = subprocess.run([sys.executable, script, "runs", path, "--profile", prof, "--mu", "0.03"],
                            capture_output=True, text=True)
        check(r2.returncode != 0 and "give --config or --balls" in r2.stderr, "six-ball runs.csv without the balls: refused")
        rows = sd.read_runs(path)
        out = sd.analyse_runs(rows, [(25, 1), (29.5, 10), (100, 8)], 0.03, abu=six, split="passage", edge=25.0)
        check(out["early"]["count"] == 2 and abs(out["t_edge"] - 1.0) < 1e-4 and out["late"]["count"] == 2,
              f"passage split at 25 Hz: the first passage at t = {out['t_edge']:.6f} s (the end of the first ramp), two early")


def six_ball_runs(abuopt):
    """abuopt's |I_r| of six balls is |U| of its final angles (64 starts of the six-ball design at mu 0.03)."""
    cfg = os.path.join(ROOT, "configs", "studies", "best", "contact_best_mu03_shake_6balls.yaml")
    six = sd.Abu.from_config(cfg)
    with tempfile.TemporaryDirectory() as tmp:
        r = subprocess.run([abuopt, "montecarlo", cfg, "--mu", "0.03", "--runs", "64", "--seed", "9001", "--threads", "1",
                            "--out", tmp], capture_output=True, text=True)
        check(r.returncode == 0, "abuopt montecarlo of contact_best_mu03_shake_6balls (64 starts) runs")
        if r.returncode != 0:
            return
        rows = sd.read_runs(os.path.join(tmp, "runs.csv"))
        n = sd.ball_count(os.path.join(tmp, "runs.csv"))
    worst = max(abs(abs(sd.imbalance([float(x[f"beta_final_{k}"]) for k in range(1, 7)], six))
                    - float(x["ir_magnitude_kgm"])) for x in rows)
    check(n == 6 and len(rows) == 64 and worst < 1e-6 * sd.MI * sd.E,
          f"six balls: |U| of the final angles = abuopt's |I_r| in all {len(rows)} runs (largest difference "
          f"{worst:.2e} kg m)")


def main(abuopt):
    closed_forms()
    lemma()
    lock_set()
    n_balls()
    six_ball_runs(abuopt)
    monte_carlo(abuopt)
    print(f"{len(failures)} failure(s)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
