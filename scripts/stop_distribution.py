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

`runs` reads the runs.csv of `abuopt montecarlo ... --out DIR` (its beta_final_* columns give the ball count N);
--config CFG (the montecarlo's YAML: abu.balls, or abu.ball_count / ball_mass_kg / ball_diameter_m) or --balls N
(N balls of the two balls' total mass, d = 3 mm x (2 / N)^(1/3)) give the masses and diameters, which set M = MT + MI +
sum m_i, r_lock and U = m_I e + sum m_i L e^(i beta_i); the gauge is per ball as it is. A run is EARLY when it settled below
the band (r_in(f_s) > 2 r_lock, f_s below resonance: it never moved again), LATE otherwise. --entry: the runs.csv
of the same starts cut at a time inside the band (`simulation.end_time_s`), for the directions of U there; --plot:
the CDFs of the lock gauge (against t and t^2) and of the depth, early and late runs, as DIR/stop_distribution.png.
A CLOSE PAIR has its balls within 0.04 rad of the contact distance (touching or nearly): it cannot end below the
pair floor |m_I e - 2 m L cos(s/2)| >= 11.11e-7 kg m. N balls: the pair floor is replaced by the CLUSTER FLOOR. Balls
whose neighbour on the ring is within 0.04 rad of contact form a cluster (a chain of close balls); with the clusters'
shapes kept, each cluster turns as one vector of length a_j = |sum over the cluster of m_i L e^(i beta_i)|, and the
least |U| over their free angles is max(0, 2 max_j a_j - sum_j a_j) with a_0 = m_I e (a polygon closes iff its
longest side is at most the sum of the others). For two balls it is the pair floor (close pair) or 0 (apart); with
six balls of 2.08 mm it is positive only when all six form one cluster (9.96e-7 kg m touching) -- the runs "held up
by a cluster" replace the close pairs in the output for N != 2.
--split passage: EARLY when the run settled for good before the profile first reached the band edge (--edge, default
the speed below resonance where r_in = 2 r_lock, 28.36 Hz at every mu), not by its settling speed (an excursion below
the edge after the first passage counts as late). --ci: 95 % intervals (shares: Wilson; means: normal; medians:
order statistics).
    scripts/stop_distribution.py runs RUNS_CSV --config CFG --profile ... --mu 0.03 --ci [--split passage]
    scripts/stop_distribution.py geometry --mu 0.03 --starts RUNS_CSV --config CFG   # the lock set of N-ball starts
Parameters are the report's (table 3.2), as in scripts/final_states_in_set.py.
"""
import argparse
import cmath
import csv
import math
import os
import random
import sys

import yaml

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from final_states_in_set import MT, B, K, L, MI, E, M_BALL, profile_frequency  # noqa: E402
from stop_depth_study import write_plot  # noqa: E402

M = MT + MI + 2 * M_BALL
OMEGA_N = math.sqrt(K / M)
BBAR = B / (2 * M * OMEGA_N)
F_N = OMEGA_N / (2 * math.pi)
# Speeds where a configuration can still be unlocked: 26 .. 40 Hz (r_in >= 6 r_lock below, >= 8 r_lock above).
LOCK_FREQS = [26.0 + 0.05 * k for k in range(281)]
BALL_DIAMETER = 3.0e-3


class Abu:
    """The balls of an ABU (masses [kg], diameters [m]; the rest is table 3.2) and what they set: the moving mass
    M = MT + MI + sum m_i, omega_n, bbar and f_n. Abu() is the report's two balls (the module's constants)."""

    def __init__(self, masses=(M_BALL, M_BALL), diameters=None):
        self.masses = list(masses)
        self.diameters = list(diameters) if diameters is not None else [BALL_DIAMETER] * len(self.masses)
        if len(self.diameters) != len(self.masses):
            raise ValueError("one diameter per ball")
        self.n = len(self.masses)
        self.mi_e = MI * E
        self.M = MT + MI + sum(self.masses)
        self.omega_n = math.sqrt(K / self.M)
        self.bbar = B / (2 * self.M * self.omega_n)
        self.f_n = self.omega_n / (2 * math.pi)

    @classmethod
    def equal_mass(cls, n):
        """n balls of the report's two balls' total mass, same material: m = 2 M_BALL / n, d = 3 mm x (2 / n)^(1/3)
        (formulation 4)."""
        return cls([2 * M_BALL / n] * n, [BALL_DIAMETER * (2.0 / n) ** (1.0 / 3.0)] * n)

    @classmethod
    def from_config(cls, path):
        """abu.balls ({mass_kg, diameter_m} each) or abu.ball_count with ball_mass_kg / ball_diameter_m of an abuopt
        YAML config; the report's two balls where the config names none."""
        abu = (yaml.safe_load(open(path)) or {}).get("abu", {}) or {}
        if abu.get("balls"):
            return cls([float(b["mass_kg"]) for b in abu["balls"]],
                       [float(b.get("diameter_m", BALL_DIAMETER)) for b in abu["balls"]])
        n = int(abu.get("ball_count", 2))
        return cls([float(abu.get("ball_mass_kg", M_BALL))] * n, [float(abu.get("ball_diameter_m", BALL_DIAMETER))] * n)


TWO = Abu()


def gain(f, abu=None):
    """G(W) = W^2 / (1 - W^2 + 2 i bbar W), W = 2 pi f / omega_n."""
    a = abu or TWO
    w = 2 * math.pi * f / a.omega_n
    return w * w / complex(1 - w * w, 2 * a.bbar * w)


def r_in(f, mu, abu=None):
    """The inscribed disc of the set at f [kg m]: M L mu / ((1 + mu) |G|)."""
    a = abu or TWO
    return a.M * L * mu / ((1 + mu) * abs(gain(f, a)))


def r_lock(mu, abu=None):
    """min_f r_in(f) = 2 bbar sqrt(1 - bbar^2) M L mu / (1 + mu) [kg m]."""
    a = abu or TWO
    return 2 * a.bbar * math.sqrt(1 - a.bbar * a.bbar) * a.M * L * mu / (1 + mu)


def imbalance(betas, abu=None):
    """U = m_I e + sum m_i L e^(i beta_i) [kg m], a complex number (the imbalance along the real axis)."""
    a = abu or TWO
    if len(betas) != a.n:
        raise ValueError(f"{len(betas)} angles for {a.n} balls")
    return a.mi_e + sum(m * L * cmath.exp(1j * b) for m, b in zip(a.masses, betas))


def gauge(f, betas, mu, abu=None):
    """max_i |Im w_i| / (mu (1 + Re w_i)): <= 1 in the set at f, inf where a ball's normal force vanishes."""
    a = abu or TWO
    z = gain(f, a) * imbalance(betas, a) / (a.M * L)
    g = 0.0
    for b in betas:
        w = z * cmath.exp(-1j * b)
        d = mu * (1 + w.real)
        g = max(g, abs(w.imag) / d if d > 0 else math.inf)
    return g


def lock_gauge(betas, mu, freqs=LOCK_FREQS, abu=None):
    """max_f gauge(f): <= 1 when the configuration is in the set of every speed of freqs."""
    return max(gauge(f, betas, mu, abu) for f in freqs)


def contact_separation(d1=BALL_DIAMETER, d2=BALL_DIAMETER):
    """The angle between the centres of two touching balls of diameters d1, d2 on the track: 2 asin((d1 + d2) / 4L)."""
    return 2 * math.asin((d1 + d2) / (4 * L))


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


def clusters(betas, abu=None, tol=CLOSE_TOL):
    """The balls grouped into chains along the ring whose neighbours are within tol [rad] of the contact distance
    (touching or nearly, as a two-ball close pair; a lone ball is a chain of one): a list of lists of ball indices."""
    a = abu or TWO
    n = len(betas)
    order = sorted(range(n), key=lambda i: betas[i] % (2 * math.pi))
    if n == 1:
        return [order]
    close = []  # close[k]: order[k] and order[k + 1] (cyclically) are within tol of contact
    for k in range(n):
        i, j = order[k], order[(k + 1) % n]
        gap = (betas[j] - betas[i]) % (2 * math.pi)
        close.append(abs(gap - contact_separation(a.diameters[i], a.diameters[j])) <= tol)
    if all(close):
        return [order]
    start = close.index(False) + 1  # a chain starts after an open link
    out, cur = [], []
    for k in range(n):
        cur.append(order[(start + k) % n])
        if not close[(start + k) % n]:
            out.append(cur)
            cur = []
    return out


def cluster_floor(betas, abu=None, tol=CLOSE_TOL):
    """The least |U| [kg m] with the clusters of `clusters` kept as they are and turned freely: with the lengths
    a_0 = m_I e and a_j = |sum over cluster j of m_i L e^(i beta_i)|, max(0, 2 max a - sum a). Two balls: the pair
    floor |m_I e - 2 m L cos(s/2)| of a close pair, 0 apart."""
    a = abu or TWO
    lengths = [abs(a.mi_e)] + [abs(sum(a.masses[i] * L * cmath.exp(1j * betas[i]) for i in c))
                               for c in clusters(betas, a, tol)]
    return max(0.0, 2 * max(lengths) - sum(lengths))


def one_cluster_floor(abu=None):
    """The cluster floor of all the balls touching in one chain (equal balls: |m_I e - m L sin(N s_c / 2) /
    sin(s_c / 2)|); 11.20e-7 kg m for the report's two balls, 9.96e-7 for six of 2.08 mm."""
    a = abu or TWO
    beta, betas = 0.0, []
    for i in range(a.n):
        if i:
            beta += contact_separation(a.diameters[i - 1], a.diameters[i])
        betas.append(beta)
    return abs(abs(a.mi_e) - abs(sum(m * L * cmath.exp(1j * b) for m, b in zip(a.masses, betas))))


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


def wilson(k, n, z=1.96):
    """The Wilson 95 % interval of a share k / n."""
    if n == 0:
        return float("nan"), float("nan")
    p = k / n
    c = (p + z * z / (2 * n)) / (1 + z * z / n)
    h = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return c - h, c + h


def mean_interval(v, z=1.96):
    """mean -+ z s / sqrt(n)."""
    if len(v) < 2:
        return float("nan"), float("nan")
    m = mean(v)
    s = math.sqrt(sum((x - m) ** 2 for x in v) / (len(v) - 1))
    return m - z * s / math.sqrt(len(v)), m + z * s / math.sqrt(len(v))


def median_interval(v, z=1.96):
    """The order statistics around the median whose ranks are n/2 -+ z sqrt(n)/2 (distribution-free, ~95 %)."""
    s, n = sorted(v), len(v)
    if n < 2:
        return float("nan"), float("nan")
    lo = max(0, int(math.floor(n / 2 - z * math.sqrt(n) / 2)))
    hi = min(n - 1, int(math.ceil(n / 2 + z * math.sqrt(n) / 2)))
    return s[lo], s[hi]


def ks_power(v, k):
    """Kolmogorov-Smirnov distance of the sample v (values in [0, 1]) from the CDF t^k (k = 1: uniform along a
    path, k = 2: uniform over a plane region measured by its gauge)."""
    s = sorted(min(max(x, 0.0), 1.0) for x in v)
    n = len(s)
    return max(max(abs((i + 1) / n - t ** k), abs(i / n - t ** k)) for i, t in enumerate(s)) if n else float("nan")


def circular_resultant(angles):
    """|mean of e^(i angle)|: 1 all in one direction, ~1/sqrt(n) spread uniformly."""
    return abs(sum(cmath.exp(1j * a) for a in angles)) / len(angles) if angles else float("nan")


def mirrored_direction(betas, abu=None):
    """The direction of U, reflected for the mirror balancing point (beta_1 - beta_2 of the other sign) so that
    the runs near either point share one frame (two balls; N balls: the direction of U as it is)."""
    a = cmath.phase(imbalance(betas, abu))
    if len(betas) != 2:
        return a
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


def starts_lock_stats(starts, mu, abu=None, freqs=LOCK_FREQS, reaches=(0.0,)):
    """torus_lock_stats for a list of N-ball configurations (the starts of a Monte Carlo, or sampled): the share in
    the lock set, their mean depth |U| / r_lock and lock gauge, and per reach u the share and mean depth of those with
    lock gauge <= 1 - u ("unreached": {u: (share, depth)}); "share_interval": the Wilson interval of the share."""
    a = abu or TWO
    rl = r_lock(mu, a)
    locked = []
    for b in starts:
        u = abs(imbalance(b, a))
        if u > 2 * rl:
            continue
        g = lock_gauge(b, mu, freqs, a)
        if g <= 1:
            locked.append((g, u / rl))
    n = len(starts)
    out = {"starts": n, "share": len(locked) / n, "share_interval": wilson(len(locked), n),
           "depth_mean": mean([d for _, d in locked]), "g_mean": mean([g for g, _ in locked]), "unreached": {}}
    for r in reaches:
        deep = [d for g, d in locked if g <= 1 - r]
        out["unreached"][r] = (len(deep) / n, mean(deep))
    return out


def sample_starts(abu, count, seed):
    """`count` configurations uniform on the torus without overlapping balls (rejection). Note: abuopt's designs map
    overlapping starts onto the feasible set instead (touching clusters with a positive probability), so the
    starts of a runs.csv (--starts) are the ones its runs had."""
    rng = random.Random(seed)
    out = []
    while len(out) < count:
        b = [rng.uniform(0, 2 * math.pi) for _ in range(abu.n)]
        ok = True
        for i in range(abu.n):
            for j in range(i + 1, abu.n):
                d = (b[i] - b[j]) % (2 * math.pi)
                if min(d, 2 * math.pi - d) < contact_separation(abu.diameters[i], abu.diameters[j]):
                    ok = False
        if ok:
            out.append(b)
    return out


def euler_reach(mu, alpha_max, f=F_N):
    """The fraction of the friction margin that the Euler term of a ramp at alpha_max [rad/s^2] uses at speed f:
    alpha_max / (mu Omega^2) (a stuck ball slips when |Im w - alpha / Omega^2| > mu (1 + Re w))."""
    return alpha_max / (mu * (2 * math.pi * f) ** 2)


def read_runs(path):
    return [r for r in csv.DictReader(open(path)) if r["status"] == "ok"]


def ball_count(path):
    """The number of beta_final_* columns of a runs.csv."""
    with open(path) as f:
        return sum(1 for c in next(csv.reader(f)) if c.startswith("beta_final_"))


def band_edge(mu, abu=None):
    """The speed below resonance where r_in = 2 r_lock (28.36 Hz; the ratio does not depend on mu)."""
    lo, hi = 10.0, (abu or TWO).f_n
    for _ in range(60):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if r_in(mid, mu, abu) > 2 * r_lock(mu, abu) else (lo, mid)
    return (lo + hi) / 2


def first_passage(segments, f_edge):
    """The first time [s] the profile (inclined sines from 0 Hz) reaches f_edge; inf if it never does."""
    t0, f0 = 0.0, 0.0
    for f_end, dt in segments:
        if f_end >= f_edge > f0:
            lo, hi = t0, t0 + dt
            for _ in range(60):
                mid = (lo + hi) / 2
                lo, hi = (mid, hi) if profile_frequency(segments, mid) < f_edge else (lo, mid)
            return (lo + hi) / 2
        t0 += dt
        f0 = f_end
    return math.inf


def analyse_runs(rows, segments, mu, entry=None, abu=None, split="speed", edge=None):
    """Split the settled runs into early (locked below the band) and late; per group the share, the mean depth
    |U| / r_lock and, for the late runs, where they stopped and how deep their lock gauge is. entry: {index:
    row} of the same starts cut inside the band (optional). split "speed": early when the settling speed f_s is
    below resonance with r_in(f_s) > 2 r_lock; "passage": when the run settled before the profile first reached
    the speed `edge` (default band_edge). The close pairs (two balls) are, for N balls, the runs held up by a
    cluster (cluster_floor > 0)."""
    a = abu or TWO
    rl = r_lock(mu, a)
    t_edge = first_passage(segments, edge if edge is not None else band_edge(mu, a)) if split == "passage" else None
    early, late = [], []
    for r in rows:
        if r["settled"] != "1":
            continue
        t_s = float(r["settling_time_s"])
        f = profile_frequency(segments, t_s)
        b = tuple(float(r[f"beta_final_{k + 1}"]) for k in range(a.n))
        floor = cluster_floor(b, a)
        rec = {"f_s": f, "depth": abs(imbalance(b, a)) / rl, "g_s": gauge(f, b, mu, a), "g_lock": lock_gauge(b, mu, abu=a),
               "dir": mirrored_direction(b, a), "index": r["index"],
               "touching": is_touching(b) if a.n == 2 else floor > 0,
               "separation": separation(b) if a.n == 2 else float("nan"), "t_s": t_s, "floor": floor / rl,
               "largest_cluster": max(len(c) for c in clusters(b, a))}
        if split == "passage":
            is_early = t_s < t_edge
        else:
            is_early = r_in(f, mu, a) > 2 * rl and f < a.f_n
        (early if is_early else late).append(rec)
    n = len(early) + len(late)
    out = {"runs": n, "r_lock": rl, "abu": a, "t_edge": t_edge}
    for name, grp in (("early", early), ("late", late)):
        out[name] = {"share": len(grp) / n, "depth_mean": mean([x["depth"] for x in grp]),
                     "g_lock_mean": mean([x["g_lock"] for x in grp]),
                     "ks_path": ks_power([x["g_lock"] for x in grp], 1), "ks_disc": ks_power([x["g_lock"] for x in grp], 2),
                     "dir_resultant": circular_resultant([x["dir"] for x in grp]),
                     "f_s_p10": quantile([x["f_s"] for x in grp], 0.1), "f_s_median": quantile([x["f_s"] for x in grp], 0.5),
                     "f_s_p90": quantile([x["f_s"] for x in grp], 0.9), "g_s_mean": mean([x["g_s"] for x in grp]),
                     "touching_share": mean([1.0 if x["touching"] else 0.0 for x in grp]),
                     "touching_depth": mean([x["depth"] for x in grp if x["touching"]]),
                     "apart_depth": mean([x["depth"] for x in grp if not x["touching"]]),
                     "count": len(grp), "share_interval": wilson(len(grp), n),
                     "depth_median": quantile([x["depth"] for x in grp], 0.5),
                     "depth_interval": mean_interval([x["depth"] for x in grp]),
                     "median_interval": median_interval([x["depth"] for x in grp])}
    out["depth_mean"] = ((len(early) * out["early"]["depth_mean"] if early else 0.0)
                         + (len(late) * out["late"]["depth_mean"] if late else 0.0)) / n
    out["depth_interval"] = mean_interval([x["depth"] for x in early + late])
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
    abu = out.get("abu") or TWO
    floor = touching_floor() if abu.n == 2 else one_cluster_floor(abu)
    write_plot(directory, "stop_distribution",
               f"set multiplot layout 1,2 title '{title}'\nset key left top\nset xrange [0:1.6]\nset yrange [0:1]\n"
               "set xlabel 'lock gauge g_lock (max over 26 .. 40 Hz)'\nset ylabel 'empirical CDF'\n"
               f"plot 'stop_distribution.dat' index 0 with lines lw 2 title 'early runs ({share['early']:.1f} %)', "
               f"'' index 1 with lines lw 2 title 'late runs ({share['late']:.1f} %)', "
               "(x <= 1 ? x : 1) with lines dt 2 title 't (along a path)', (x <= 1 ? x * x : 1) with lines dt 3 "
               "title 't^2 (uniform over the set)'\n"
               "set xrange [0:2]\nset xlabel '|I_r| / r_lock'\n"
               f"set arrow from {floor / out['r_lock']:.4f},0 to {floor / out['r_lock']:.4f},1 nohead dt 2\n"
               "plot 'stop_distribution.dat' index 2 with lines lw 2 title 'early runs', '' index 3 with lines lw 2 "
               "title 'late runs (dashed: floor of touching balls)'\nunset multiplot\n")


def needed_late_depth(out, goal_depth):
    """The mean depth the late runs would need for the whole mean to reach goal_depth (in r_lock), the early runs
    kept as they are."""
    e = out["early"]
    return (goal_depth - e["share"] * e["depth_mean"]) / (1 - e["share"])


def abu_from_args(a, runs_csv=None):
    """The balls from --config / --balls, checked against the runs.csv's ball count; the report's two balls when
    neither is given and the runs.csv has two."""
    n_csv = ball_count(runs_csv) if runs_csv else None
    if a.config:
        abu = Abu.from_config(a.config)
    elif a.balls:
        abu = Abu.equal_mass(a.balls)
    elif n_csv in (None, 2):
        return TWO
    else:
        sys.exit(f"{runs_csv} has {n_csv} balls: give --config or --balls")
    if n_csv is not None and n_csv != abu.n:
        sys.exit(f"{runs_csv} has {n_csv} balls, the config / --balls {abu.n}")
    return abu


def print_histogram(title, values, edges):
    """A text histogram: count and share per bin [edges[k], edges[k + 1])."""
    n = len(values)
    print(f"  {title} ({n} runs):")
    for lo, hi in zip(edges, edges[1:]):
        c = sum(1 for v in values if lo <= v < hi)
        if c:
            print(f"    [{lo:6.2f}, {hi:6.2f}) {c:5d} {100 * c / n:5.1f} % {'#' * round(60 * c / n)}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    g = sub.add_parser("geometry")
    g.add_argument("--mu", type=float, default=0.03)
    g.add_argument("--grid", type=int, default=256)
    g.add_argument("--alpha-max", type=float, default=314.16, help="peak angular acceleration [rad/s^2]")
    g.add_argument("--starts", help="N balls: the starts (beta0_* columns) of this runs.csv")
    g.add_argument("--samples", type=int, default=0, help="N balls: this many uniform starts without overlap instead")
    g.add_argument("--seed", type=int, default=1)
    for p in (g,):
        p.add_argument("--config", help="abuopt YAML whose abu section gives the balls")
        p.add_argument("--balls", type=int, help="N balls of the two balls' total mass (d = 3 mm x (2/N)^(1/3))")
    sub.add_parser("jacobian")
    r = sub.add_parser("runs")
    r.add_argument("runs_csv")
    r.add_argument("--profile", required=True, help="segments f_end:dt,... starting at 0 Hz")
    r.add_argument("--mu", type=float, required=True)
    r.add_argument("--entry", help="runs.csv of the same starts cut inside the band (two balls)")
    r.add_argument("--goal", type=float, default=0.52, help="goal depth in r_lock (0.52: the robust goal)")
    r.add_argument("--plot", help="write the CDFs and their plot (stop_distribution.png) into this directory")
    r.add_argument("--config", help="abuopt YAML whose abu section gives the balls (N != 2)")
    r.add_argument("--balls", type=int, help="N balls of the two balls' total mass (d = 3 mm x (2/N)^(1/3))")
    r.add_argument("--split", choices=("speed", "passage"), default="speed",
                   help="early by the settling speed (default) or by settling before the first passage of --edge")
    r.add_argument("--edge", type=float, help="the band edge of --split passage [Hz] (default: r_in = 2 r_lock)")
    r.add_argument("--ci", action="store_true", help="print 95 %% intervals of the shares, mean and median depths")
    r.add_argument("--hist", action="store_true", help="print histograms of the early runs' settling time and speed")
    a = ap.parse_args()
    if a.cmd == "geometry":
        reach = euler_reach(a.mu, a.alpha_max)
        if a.starts or a.samples or a.config or a.balls:
            abu = abu_from_args(a, a.starts)
            if a.starts:
                starts = [[float(x[f"beta0_{k + 1}"]) for k in range(abu.n)] for x in csv.DictReader(open(a.starts))]
                src = f"the {len(starts)} starts of {a.starts}"
            else:
                starts = sample_starts(abu, a.samples or 4096, a.seed)
                src = f"{len(starts)} uniform starts without overlap (seed {a.seed})"
            x = starts_lock_stats(starts, a.mu, abu, reaches=(0.0, reach))
            lo, hi = x["share_interval"]
            us, ud = x["unreached"][reach]
            print(f"mu {a.mu}, {abu.n} balls: r_lock {r_lock(a.mu, abu) / 1e-7:.2f}e-7; {src} in the lock set (26 .. 40 "
                  f"Hz): {x['share'] * 100:.1f} % [{lo * 100:.1f}, {hi * 100:.1f}], their mean |U| {x['depth_mean']:.3f} "
                  f"r_lock, mean lock gauge {x['g_mean']:.3f}; floor share x depth {x['share'] * x['depth_mean']:.3f} r_lock")
            print(f"  a ramp at {a.alpha_max:g} rad/s^2 uses {reach:.3f} of the friction at resonance; locked starts with "
                  f"lock gauge <= {1 - reach:.3f}: {us * 100:.1f} %, mean |U| {ud:.3f} r_lock; floor {us * ud:.3f} r_lock")
            return
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
        abu = abu_from_args(a, a.runs_csv)
        if a.entry and abu.n != 2:
            sys.exit("--entry: two balls only")
        segments = [tuple(float(v) for v in s.split(":")) for s in a.profile.split(",")]
        entry = {e["index"]: e for e in read_runs(a.entry)} if a.entry else None
        out = analyse_runs(read_runs(a.runs_csv), segments, a.mu, entry, abu, a.split, a.edge)
        two = abu.n == 2
        balls = "" if two else (f"; {abu.n} balls (m {abu.masses[0] / 1e-5:.3f}e-5 kg, d {abu.diameters[0] * 1e3:.3f} mm"
                                f"{'' if len(set(abu.masses)) == 1 else ', unequal'}; M {abu.M:.6f} kg)")
        print(f"{out['runs']} settled runs, mu {a.mu}, r_lock {out['r_lock'] / 1e-7:.2f}e-7; mean depth "
              f"{out['depth_mean']:.3f} r_lock{balls}")
        if a.split == "passage":
            edge = a.edge if a.edge is not None else band_edge(a.mu, abu)
            print(f"  split by passage: early = settled before the profile first reached {edge:.2f} Hz "
                  f"(t = {out['t_edge']:.3f} s)")
        held = "close pairs" if two else "held by a cluster"
        for name in ("early", "late"):
            x = out[name]
            print(f"  {name:5s} {x['share'] * 100:5.1f} %: mean depth {x['depth_mean']:.3f} r_lock, lock gauge mean "
                  f"{x['g_lock_mean']:.3f} (KS from t {x['ks_path']:.3f}, from t^2 {x['ks_disc']:.3f}), stop speed "
                  f"p10 / median / p90 {x['f_s_p10']:.2f} / {x['f_s_median']:.2f} / {x['f_s_p90']:.2f} Hz, gauge there "
                  f"{x['g_s_mean']:.3f}, direction resultant {x['dir_resultant']:.3f}; {held} {x['touching_share'] * 100:.1f} % "
                  f"at {x['touching_depth']:.3f}, apart at {x['apart_depth']:.3f}")
        if two:
            print(f"  touching-pair floor {touching_floor() / out['r_lock']:.3f} r_lock ({touching_floor() / 1e-7:.2f}e-7)")
        else:
            f1 = one_cluster_floor(abu)
            pair = abs(MI * E - 2 * M_BALL * L * math.cos((CONTACT_SEPARATION + CLOSE_TOL) / 2))
            print(f"  cluster floor of all {abu.n} balls touching {f1 / out['r_lock']:.3f} r_lock ({f1 / 1e-7:.2f}e-7); "
                  f"the two-ball close-pair floor {pair / 1e-7:.2f}e-7 = {pair / out['r_lock']:.3f} r_lock")
            for name in ("early", "late"):
                recs = out["records"][name]
                if not recs:
                    continue
                sizes = " / ".join(f"{100 * sum(1 for x in recs if x['largest_cluster'] == k) / len(recs):.1f}"
                                   for k in range(1, abu.n + 1))
                below = 100 * sum(1 for x in recs if x["depth"] * out["r_lock"] < pair) / len(recs)
                print(f"  {name:5s} largest cluster 1 / ... / {abu.n} balls: {sizes} %; below the two-ball close-pair "
                      f"floor: {below:.1f} %")
        print(f"  the late runs would need a mean depth of {needed_late_depth(out, a.goal):.3f} r_lock for "
              f"{a.goal} r_lock overall")
        if a.ci:
            lo, hi = out["depth_interval"]
            print(f"  95 % intervals: mean depth {out['depth_mean']:.3f} [{lo:.3f}, {hi:.3f}] r_lock "
                  f"({out['depth_mean'] * out['r_lock'] / 1e-7:.2f}e-7)")
            for name in ("early", "late"):
                x = out[name]
                (sl, sh), (dl, dh), (ml, mh) = x["share_interval"], x["depth_interval"], x["median_interval"]
                print(f"  {name:5s} {x['count']} runs, share {x['share'] * 100:.1f} % [{sl * 100:.1f}, {sh * 100:.1f}], "
                      f"depth mean {x['depth_mean']:.3f} [{dl:.3f}, {dh:.3f}], median {x['depth_median']:.3f} "
                      f"[{ml:.3f}, {mh:.3f}] r_lock; share x depth {x['share'] * x['depth_mean']:.3f}")
        if a.hist:
            e = out["records"]["early"]
            t_max = max([x["t_s"] for x in e] + [1.0])
            print_histogram("early runs' settling time [s]", [x["t_s"] for x in e],
                            [0.1 * k for k in range(int(t_max / 0.1) + 2)])
            print_histogram("early runs' settling speed [Hz]", [x["f_s"] for x in e], [1.0 * k for k in range(41)])
        if a.plot:
            write_cdf_plot(out, a.plot, f"{os.path.basename(os.path.dirname(os.path.abspath(a.runs_csv)))}, mu {a.mu}")
            print(f"  plot: {os.path.join(a.plot, 'stop_distribution.png')}")
        if entry is not None:
            e = out["entry"]
            print(f"  entry ({e['runs']} late runs): direction resultant {e['dir_resultant']:.3f}; of final minus "
                  f"entry direction {e['final_minus_entry_resultant']:.3f}")


if __name__ == "__main__":
    main()
