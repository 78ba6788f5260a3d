#!/usr/bin/env python3
"""Where the runs of a startup profile stop, split into the runs LOCKED BEFORE THE BAND and the runs that stop in
or after it (issue 10's limit analysis; docs/studies/startup-profile.md 8.1, "The floor of the locked runs").

The set at speed f (docs/equilibrium_sets.md): ball i sticks while |Im w_i| <= mu (1 + Re w_i), w_i = G(f) U /
(M L) e^(-i beta_i), U = m_I e + sum_i m L e^(i beta_i) the residual imbalance vector. Its GAUGE at f is
g(f) = max_i |Im w_i| / (mu (1 + Re w_i)) (g <= 1: in the set); a configuration is LOCKED when it is in the set
of every speed of the band and above, g_lock = max over f >= 26 Hz of g(f) <= 1 (the sets below 26 Hz are
wider than 6 r_lock). In a stuck configuration |U| >= g(f) r_in(f) >= g(f) r_lock (section "The lemma" of 8.1),
so a run's depth |U| / r_lock is at least its gauge.

    scripts/stop_distribution.py geometry --mu 0.03 [--grid 256]      # uniform starts inside the lock set
    scripts/stop_distribution.py jacobian                             # the map (beta_1, beta_2) -> U at balance
    scripts/stop_distribution.py runs RUNS_CSV --profile 25:1,29.5:10,100:8 --mu 0.03 [--entry CUT_CSV] [--plot DIR]

`runs` reads the runs.csv of `abuopt montecarlo ... --out DIR` (two balls); a run is EARLY when it settled below
the band (r_in(f_s) > 2 r_lock, f_s below resonance: it never moved again), LATE otherwise. --entry: the runs.csv
of the same starts cut at a time inside the band (`simulation.end_time_s`), for the directions of U there; --plot:
the CDFs of the lock gauge (against t and t^2) and of the depth, early and late runs, as DIR/stop_distribution.png.
A CLOSE PAIR has its balls within 0.04 rad of the contact distance (touching or nearly): it cannot end below the
pair floor |m_I e - 2 m L cos(s/2)| >= 11.11e-7 kg m.
Parameters are the report's (table 3.2), as in scripts/final_states_in_set.py.
"""
import argparse
import cmath
import csv
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from final_states_in_set import MT, B, K, L, MI, E, M_BALL, profile_frequency  # noqa: E402
from stop_depth_study import write_plot  # noqa: E402

M = MT + MI + 2 * M_BALL
OMEGA_N = math.sqrt(K / M)
BBAR = B / (2 * M * OMEGA_N)
F_N = OMEGA_N / (2 * math.pi)
# Speeds where a configuration can still be unlocked: 26 .. 40 Hz (r_in >= 6 r_lock below, >= 8 r_lock above).
LOCK_FREQS = [26.0 + 0.05 * k for k in range(281)]


def gain(f):
    """G(W) = W^2 / (1 - W^2 + 2 i bbar W), W = 2 pi f / omega_n."""
    w = 2 * math.pi * f / OMEGA_N
    return w * w / complex(1 - w * w, 2 * BBAR * w)


def r_in(f, mu):
    """The inscribed disc of the set at f [kg m]: M L mu / ((1 + mu) |G|)."""
    return M * L * mu / ((1 + mu) * abs(gain(f)))


def r_lock(mu):
    """min_f r_in(f) = 2 bbar sqrt(1 - bbar^2) M L mu / (1 + mu) [kg m]."""
    return 2 * BBAR * math.sqrt(1 - BBAR * BBAR) * M * L * mu / (1 + mu)


def imbalance(betas):
    """U = m_I e + sum m L e^(i beta) [kg m], a complex number (the imbalance along the real axis)."""
    return MI * E + sum(M_BALL * L * cmath.exp(1j * b) for b in betas)


def gauge(f, betas, mu):
    """max_i |Im w_i| / (mu (1 + Re w_i)): <= 1 in the set at f, inf where a ball's normal force vanishes."""
    z = gain(f) * imbalance(betas) / (M * L)
    g = 0.0
    for b in betas:
        w = z * cmath.exp(-1j * b)
        d = mu * (1 + w.real)
        g = max(g, abs(w.imag) / d if d > 0 else math.inf)
    return g


def lock_gauge(betas, mu, freqs=LOCK_FREQS):
    """max_f gauge(f): <= 1 when the configuration is in the set of every speed of freqs."""
    return max(gauge(f, betas, mu) for f in freqs)


BALL_DIAMETER = 3.0e-3
CONTACT_SEPARATION = 2 * math.asin(BALL_DIAMETER / (2 * L))  # touching balls: 0.2616 rad apart (docs/model.md 11.1)


def touching_floor():
    """The least |U| of two touching balls (separation s_c): |m_I e - 2 m L cos(s_c / 2)| = 11.20e-7 kg m."""
    return abs(MI * E - 2 * M_BALL * L * math.cos(CONTACT_SEPARATION / 2))


CLOSE_TOL = 0.04  # rad: a "close pair" (touching or nearly: gap below 0.46 mm); its pair floor is >= 11.11e-7 kg m


def separation(betas):
    """The wrapped angle between the two balls, in [0, pi]."""
    d = (betas[0] - betas[1]) % (2 * math.pi)
    return min(d, 2 * math.pi - d)


def is_touching(betas, tol=CLOSE_TOL):
    """Ball separation within tol [rad] of the contact distance: a close pair."""
    return abs(separation(betas) - CONTACT_SEPARATION) <= tol


def balancing_separation():
    """s* with 2 m L cos(s*/2) = m_I e: the two balancing points are beta = pi -+ s*/2 (U = 0)."""
    return 2 * math.acos(MI * E / (2 * M_BALL * L))


def jacobian_singular_values(s):
    """Of dU / d(beta_1, beta_2) (columns m L i e^(i beta_k) as real 2-vectors) at separation s:
    m L sqrt(1 +- cos s) = sqrt(2) m L (cos(s/2), sin(s/2)), largest first."""
    a, b = math.sqrt(2) * M_BALL * L * abs(math.cos(s / 2)), math.sqrt(2) * M_BALL * L * abs(math.sin(s / 2))
    return max(a, b), min(a, b)


def mean(v):
    return sum(v) / len(v) if v else float("nan")


def quantile(v, p):
    s = sorted(v)
    return s[min(len(s) - 1, int(p * (len(s) - 1) + 0.5))] if s else float("nan")


def ks_power(v, k):
    """Kolmogorov-Smirnov distance of the sample v (values in [0, 1]) from the CDF t^k (k = 1: uniform along a
    path, k = 2: uniform over a plane region measured by its gauge)."""
    s = sorted(min(max(x, 0.0), 1.0) for x in v)
    n = len(s)
    return max(max(abs((i + 1) / n - t ** k), abs(i / n - t ** k)) for i, t in enumerate(s)) if n else float("nan")


def circular_resultant(angles):
    """|mean of e^(i angle)|: 1 all in one direction, ~1/sqrt(n) spread uniformly."""
    return abs(sum(cmath.exp(1j * a) for a in angles)) / len(angles) if angles else float("nan")


def mirrored_direction(betas):
    """The direction of U, reflected for the mirror balancing point (beta_1 - beta_2 of the other sign) so that
    the runs near either point share one frame."""
    a = cmath.phase(imbalance(betas))
    return a if math.sin(betas[0] - betas[1]) >= 0 else -a


def torus_lock_stats(mu, grid, freqs=LOCK_FREQS, reach=0.0):
    """Uniform starts (a grid x grid lattice of the torus, offset half a cell): the share in the lock set, the mean
    |U| / r_lock and the mean lock gauge of those (what the runs locked before the band keep when the first ramp
    leaves the torus uniform); and the share and mean depth of the locked starts with lock gauge <= 1 - reach (out
    of reach of a ramp whose Euler term uses the fraction `reach` of the friction)."""
    rl = r_lock(mu)
    locked = []
    for i in range(grid):
        for j in range(grid):
            b = (2 * math.pi * (i + 0.5) / grid, 2 * math.pi * (j + 0.5) / grid)
            if abs(imbalance(b)) > 2 * rl:  # outside the set at resonance for sure (|U| > the corner radius)
                continue
            g = lock_gauge(b, mu, freqs)
            if g <= 1:
                locked.append((g, abs(imbalance(b)) / rl))
    deep = [d for g, d in locked if g <= 1 - reach]
    n = grid * grid
    return {"share": len(locked) / n, "depth_mean": mean([d for _, d in locked]), "g_mean": mean([g for g, _ in locked]),
            "unreached_share": len(deep) / n, "unreached_depth_mean": mean(deep)}


def euler_reach(mu, alpha_max, f=F_N):
    """The fraction of the friction margin that the Euler term of a ramp at alpha_max [rad/s^2] uses at speed f:
    alpha_max / (mu Omega^2) (a stuck ball slips when |Im w - alpha / Omega^2| > mu (1 + Re w))."""
    return alpha_max / (mu * (2 * math.pi * f) ** 2)


def read_runs(path):
    return [r for r in csv.DictReader(open(path)) if r["status"] == "ok"]


def analyse_runs(rows, segments, mu, entry=None):
    """Split the settled runs into early (locked below the band) and late; per group the share, the mean depth
    |U| / r_lock and, for the late runs, where they stopped and how deep their lock gauge is. entry: {index:
    row} of the same starts cut inside the band (optional)."""
    rl = r_lock(mu)
    early, late = [], []
    for r in rows:
        if r["settled"] != "1":
            continue
        f = profile_frequency(segments, float(r["settling_time_s"]))
        b = (float(r["beta_final_1"]), float(r["beta_final_2"]))
        rec = {"f_s": f, "depth": abs(imbalance(b)) / rl, "g_s": gauge(f, b, mu), "g_lock": lock_gauge(b, mu),
               "dir": mirrored_direction(b), "index": r["index"], "touching": is_touching(b),
               "separation": separation(b)}
        (early if r_in(f, mu) > 2 * rl and f < F_N else late).append(rec)
    n = len(early) + len(late)
    out = {"runs": n, "r_lock": rl}
    for name, grp in (("early", early), ("late", late)):
        out[name] = {"share": len(grp) / n, "depth_mean": mean([x["depth"] for x in grp]),
                     "g_lock_mean": mean([x["g_lock"] for x in grp]),
                     "ks_path": ks_power([x["g_lock"] for x in grp], 1), "ks_disc": ks_power([x["g_lock"] for x in grp], 2),
                     "dir_resultant": circular_resultant([x["dir"] for x in grp]),
                     "f_s_p10": quantile([x["f_s"] for x in grp], 0.1), "f_s_median": quantile([x["f_s"] for x in grp], 0.5),
                     "f_s_p90": quantile([x["f_s"] for x in grp], 0.9), "g_s_mean": mean([x["g_s"] for x in grp]),
                     "touching_share": mean([1.0 if x["touching"] else 0.0 for x in grp]),
                     "touching_depth": mean([x["depth"] for x in grp if x["touching"]]),
                     "apart_depth": mean([x["depth"] for x in grp if not x["touching"]])}
    out["depth_mean"] = (len(early) * out["early"]["depth_mean"] + len(late) * out["late"]["depth_mean"]) / n
    out["records"] = {"early": early, "late": late}
    if entry is not None:
        dirs, finals = [], []
        for x in late:
            e = entry.get(x["index"])
            if e is None:
                continue
            b = (float(e["beta_final_1"]), float(e["beta_final_2"]))
            dirs.append(mirrored_direction(b))
            finals.append(x["dir"])
        # the entry directions' spread, and how much of the final direction they fix (resultant of the difference)
        out["entry"] = {"runs": len(dirs), "dir_resultant": circular_resultant(dirs),
                        "final_minus_entry_resultant": circular_resultant([f - d for f, d in zip(finals, dirs)])}
    return out


def write_cdf_plot(out, directory, title):
    """DIRECTORY/stop_distribution.dat (the empirical CDFs of the lock gauge and of the depth, early and late runs,
    as four gnuplot index blocks) and stop_distribution.gp / .png: the lock gauge against t (stops along a path)
    and t^2 (uniform over a region), and the depth. Raises OSError if a file cannot be written."""
    os.makedirs(directory, exist_ok=True)
    with open(os.path.join(directory, "stop_distribution.dat"), "w") as f:
        for key in ("g_lock", "depth"):
            for name in ("early", "late"):
                v = sorted(x[key] for x in out["records"][name])
                f.write(f"# {key} of the {name} runs: value, empirical CDF\n")
                f.write("".join(f"{x:.6g} {(i + 1) / len(v):.6g}\n" for i, x in enumerate(v)) + "\n\n")
    share = {k: out[k]["share"] * 100 for k in ("early", "late")}
    write_plot(directory, "stop_distribution",
               f"set multiplot layout 1,2 title '{title}'\nset key left top\nset xrange [0:1.6]\nset yrange [0:1]\n"
               "set xlabel 'lock gauge g_lock (max over 26 .. 40 Hz)'\nset ylabel 'empirical CDF'\n"
               f"plot 'stop_distribution.dat' index 0 with lines lw 2 title 'early runs ({share['early']:.1f} %)', "
               f"'' index 1 with lines lw 2 title 'late runs ({share['late']:.1f} %)', "
               "(x <= 1 ? x : 1) with lines dt 2 title 't (along a path)', (x <= 1 ? x * x : 1) with lines dt 3 "
               "title 't^2 (uniform over the set)'\n"
               "set xrange [0:2]\nset xlabel '|I_r| / r_lock'\n"
               f"set arrow from {touching_floor() / out['r_lock']:.4f},0 to {touching_floor() / out['r_lock']:.4f},1 nohead dt 2\n"
               "plot 'stop_distribution.dat' index 2 with lines lw 2 title 'early runs', '' index 3 with lines lw 2 "
               "title 'late runs (dashed: floor of touching balls)'\nunset multiplot\n")


def needed_late_depth(out, goal_depth):
    """The mean depth the late runs would need for the whole mean to reach goal_depth (in r_lock), the early runs
    kept as they are."""
    e = out["early"]
    return (goal_depth - e["share"] * e["depth_mean"]) / (1 - e["share"])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    g = sub.add_parser("geometry")
    g.add_argument("--mu", type=float, default=0.03)
    g.add_argument("--grid", type=int, default=256)
    g.add_argument("--alpha-max", type=float, default=314.16, help="peak angular acceleration [rad/s^2]")
    sub.add_parser("jacobian")
    r = sub.add_parser("runs")
    r.add_argument("runs_csv")
    r.add_argument("--profile", required=True, help="segments f_end:dt,... starting at 0 Hz")
    r.add_argument("--mu", type=float, required=True)
    r.add_argument("--entry", help="runs.csv of the same starts cut inside the band")
    r.add_argument("--goal", type=float, default=0.52, help="goal depth in r_lock (0.52: the robust goal)")
    r.add_argument("--plot", help="write the CDFs and their plot (stop_distribution.png) into this directory")
    a = ap.parse_args()
    if a.cmd == "geometry":
        reach = euler_reach(a.mu, a.alpha_max)
        x = torus_lock_stats(a.mu, a.grid, reach=reach)
        print(f"mu {a.mu}: r_lock {r_lock(a.mu) / 1e-7:.2f}e-7; uniform starts ({a.grid}^2 grid) in the lock set "
              f"(26 .. 40 Hz): {x['share'] * 100:.1f} %, their mean |U| {x['depth_mean']:.3f} r_lock, mean lock gauge "
              f"{x['g_mean']:.3f}; floor share x depth {x['share'] * x['depth_mean']:.3f} r_lock")
        print(f"  a ramp at {a.alpha_max:g} rad/s^2 uses {reach:.3f} of the friction at resonance; locked starts with "
              f"lock gauge <= {1 - reach:.3f}: {x['unreached_share'] * 100:.1f} %, mean |U| "
              f"{x['unreached_depth_mean']:.3f} r_lock; floor {x['unreached_share'] * x['unreached_depth_mean']:.3f} r_lock")
    elif a.cmd == "jacobian":
        s = balancing_separation()
        hi, lo = jacobian_singular_values(s)
        print(f"balancing separation s* = {s:.4f} rad; singular values of dU/dbeta there: {hi / (M_BALL * L):.4f}, "
              f"{lo / (M_BALL * L):.4f} m L (ratio {hi / lo:.3f}; of J J^T {(hi / lo) ** 2:.3f})")
    else:
        segments = [tuple(float(v) for v in s.split(":")) for s in a.profile.split(",")]
        entry = {e["index"]: e for e in read_runs(a.entry)} if a.entry else None
        out = analyse_runs(read_runs(a.runs_csv), segments, a.mu, entry)
        print(f"{out['runs']} settled runs, mu {a.mu}, r_lock {out['r_lock'] / 1e-7:.2f}e-7; mean depth "
              f"{out['depth_mean']:.3f} r_lock")
        for name in ("early", "late"):
            x = out[name]
            print(f"  {name:5s} {x['share'] * 100:5.1f} %: mean depth {x['depth_mean']:.3f} r_lock, lock gauge mean "
                  f"{x['g_lock_mean']:.3f} (KS from t {x['ks_path']:.3f}, from t^2 {x['ks_disc']:.3f}), stop speed "
                  f"p10 / median / p90 {x['f_s_p10']:.2f} / {x['f_s_median']:.2f} / {x['f_s_p90']:.2f} Hz, gauge there "
                  f"{x['g_s_mean']:.3f}, direction resultant {x['dir_resultant']:.3f}; close pairs {x['touching_share'] * 100:.1f} % "
                  f"at {x['touching_depth']:.3f}, apart at {x['apart_depth']:.3f}")
        print(f"  touching-pair floor {touching_floor() / out['r_lock']:.3f} r_lock ({touching_floor() / 1e-7:.2f}e-7)")
        print(f"  the late runs would need a mean depth of {needed_late_depth(out, a.goal):.3f} r_lock for "
              f"{a.goal} r_lock overall")
        if a.plot:
            write_cdf_plot(out, a.plot, f"{os.path.basename(os.path.dirname(os.path.abspath(a.runs_csv)))}, mu {a.mu}")
            print(f"  plot: {os.path.join(a.plot, 'stop_distribution.png')}")
        if entry is not None:
            e = out["entry"]
            print(f"  entry ({e['runs']} late runs): direction resultant {e['dir_resultant']:.3f}; of final minus "
                  f"entry direction {e['final_minus_entry_resultant']:.3f}")


if __name__ == "__main__":
    main()
