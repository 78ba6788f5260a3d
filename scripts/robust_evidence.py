#!/usr/bin/env python3
"""Paired evidence for issue 30's robust designs from `abuopt montecarlo --out` folders.

  robust_evidence.py pair BASE DESIGN            one design against the baseline on the SAME draws
  robust_evidence.py corners BASE_PREFIX DESIGN_PREFIX
        the 16 corners: folders PREFIX_<mu>_<imbalance factor>_<stiffness factor>_<restitution>
  robust_evidence.py depth FOLDER [FOLDER...]
        the stop depth: mean |I_r| / r_lock(mu, k) of each run, by friction quarter, and the share of
        runs stopped at or below 0.44 r_lock (docs/equilibrium_sets.md section 4:
        r_lock = 2 bbar sqrt(1 - bbar^2) M L mu / (1 + mu), bbar = b / (2 sqrt(k M)))

Both folders must hold the same draws (same seed, runs and envelope): runs are paired by index.
Means and differences: +-1.96 standard errors; the ratio base/design from the paired difference's
interval (base mean / (base mean - difference bound)); %MI: Wilson (a run is MI when |I| >= m_I e
of the run, e = 3.7e-3 m). Units: 1e-7 kg m. Only the standard library.
"""
import csv
import math
import os
import sys

E_M = 3.7e-3  # the report ABU's eccentricity (abu.eccentricity_m)


def load(folder):
    with open(os.path.join(folder, "runs.csv"), newline="") as f:
        return {int(r["index"]): r for r in csv.DictReader(f) if r["status"] == "ok"}


def mean_ci(v):
    n = len(v)
    m = sum(v) / n
    s = math.sqrt(sum((x - m) ** 2 for x in v) / (n - 1)) if n > 1 else 0.0
    return m, 1.96 * s / math.sqrt(n)


def wilson(k, n, z=1.96):
    p = k / n
    d = 1 + z * z / n
    c = (p + z * z / (2 * n)) / d
    h = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / d
    return 100 * p, 100 * (c - h), 100 * (c + h)


def stats(base, design, keys):
    out = {}
    for col, name in (("ir_magnitude_kgm", "mag"), ("ir_x_kgm", "x")):
        b = [abs(float(base[k][col])) * 1e7 for k in keys]
        d = [abs(float(design[k][col])) * 1e7 for k in keys]
        mb, hb = mean_ci(b)
        md, hd = mean_ci(d)
        diff, hdiff = mean_ci([y - x for x, y in zip(b, d)])
        lo_d, hi_d = diff - hdiff, diff + hdiff
        ratio = mb / md
        r_lo, r_hi = mb / (mb + hi_d), mb / (mb + lo_d)
        thr = [float(base[k]["imbalance_mass_kg"]) * E_M * 1e7 for k in keys]
        mi_b = wilson(sum(x >= t for x, t in zip(b, thr)), len(keys))
        mi_d = wilson(sum(y >= t for y, t in zip(d, thr)), len(keys))
        out[name] = dict(mb=mb, hb=hb, md=md, hd=hd, diff=diff, hdiff=hdiff, ratio=ratio, r_lo=r_lo, r_hi=r_hi,
                         mi_b=mi_b, mi_d=mi_d)
    out["n"] = len(keys)
    out["amp_b"] = max(float(base[k]["max_amplitude_mm"]) for k in keys)
    out["amp_d"] = max(float(design[k]["max_amplitude_mm"]) for k in keys)
    return out


def pair(base_dir, design_dir):
    base, design = load(base_dir), load(design_dir)
    keys = sorted(set(base) & set(design))
    s = stats(base, design, keys)
    print(f"paired runs: {s['n']} (of {len(base)} / {len(design)})")
    for name, label in (("mag", "|I_r|"), ("x", "I_r,x")):
        t = s[name]
        print(f"{label}: base {t['mb']:.2f} +-{t['hb']:.2f}  design {t['md']:.2f} +-{t['hd']:.2f}  "
              f"difference {t['diff']:+.2f} [{t['diff'] - t['hdiff']:+.2f}, {t['diff'] + t['hdiff']:+.2f}]  "
              f"ratio base/design {t['ratio']:.3f} [{t['r_lo']:.3f}, {t['r_hi']:.3f}]")
        print(f"  %MI({label}) base {t['mi_b'][0]:.2f} [{t['mi_b'][1]:.2f}, {t['mi_b'][2]:.2f}]  "
              f"design {t['mi_d'][0]:.2f} [{t['mi_d'][1]:.2f}, {t['mi_d'][2]:.2f}]  "
              f"ratio design/base {t['mi_d'][0] / t['mi_b'][0]:.2f}")
    print(f"peak amplitude (max over runs) [mm]: base {s['amp_b']:.4f}  design {s['amp_d']:.4f}")


def corners(base_prefix, design_prefix):
    print("| mu | m_I | k | e | 2003 mean [95 %] | design mean [95 %] | ratio [95 %] | %MI 2003 / design "
          "| I_r,x 2003 / design | verdict |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    worse = better = p_worse = 0
    for mu in ("0.02", "0.04"):
        for fi in ("0.5", "1.5"):
            for fk in ("0.95", "1.05"):
                for e in ("0.5", "0.95"):
                    tail = f"_{mu}_{fi}_{fk}_{e}"
                    base, design = load(base_prefix + tail), load(design_prefix + tail)
                    s = stats(base, design, sorted(set(base) & set(design)))
                    m, x = s["mag"], s["x"]
                    # issue 30's rule: WORSE when the design's 95 % interval lies wholly above the baseline's
                    # (and better when wholly below); the paired difference's interval is stricter
                    if m["md"] - m["hd"] > m["mb"] + m["hb"]:
                        verdict = "WORSE"
                    elif m["md"] + m["hd"] < m["mb"] - m["hb"]:
                        verdict = "better"
                    else:
                        verdict = "overlap"
                    worse += verdict == "WORSE"
                    better += verdict == "better"
                    p_worse += m["diff"] - m["hdiff"] > 0
                    print(f"| {mu} | {fi}x | {fk}x | {e} | {m['mb']:.2f} [{m['mb'] - m['hb']:.2f}, {m['mb'] + m['hb']:.2f}] | "
                          f"{m['md']:.2f} [{m['md'] - m['hd']:.2f}, {m['md'] + m['hd']:.2f}] | "
                          f"{m['ratio']:.2f} [{m['r_lo']:.2f}, {m['r_hi']:.2f}] | {m['mi_b'][0]:.1f} / {m['mi_d'][0]:.1f} | "
                          f"{x['mb']:.2f} / {x['md']:.2f} | {verdict} |")
    print(f"worse at {worse} of 16 (the two intervals apart), better at {better}, overlapping at {16 - worse - better}; "
          f"the paired difference's interval wholly above 0 at {p_worse}")


def r_lock(mu, k, m_imb, m_balls=2.8e-4, m_table=0.324, b=1.28, L=1.15e-2):
    M = m_table + m_imb + m_balls
    bb = b / (2 * math.sqrt(k * M))
    return 2 * bb * math.sqrt(1 - bb * bb) * M * L * mu / (1 + mu)


def depth(*folders):
    print("| runs | all | mu 0.020-0.025 | 0.025-0.030 | 0.030-0.035 | 0.035-0.040 | share <= 0.44 r_lock |")
    for folder in folders:
        runs = load(folder).values()
        rows = [(float(r["mu"]), abs(float(r["ir_magnitude_kgm"])) /
                 r_lock(float(r["mu"]), float(r["stiffness_N_per_m"]), float(r["imbalance_mass_kg"]))) for r in runs]
        q = [[d for mu, d in rows if 0.02 + 0.005 * i <= mu < 0.025 + 0.005 * i + (1e-12 if i == 3 else 0)]
             for i in range(4)]
        cells = " | ".join(f"{sum(v) / len(v):.3f}" if v else "-" for v in q)
        share = 100 * sum(d <= 0.44 for _, d in rows) / len(rows)
        print(f"| {folder} ({len(rows)}) | {sum(d for _, d in rows) / len(rows):.3f} | {cells} | {share:.1f} % |")


if __name__ == "__main__":
    if len(sys.argv) >= 3 and sys.argv[1] == "depth":
        depth(*sys.argv[2:])
    elif len(sys.argv) == 4 and sys.argv[1] in ("pair", "corners"):
        {"pair": pair, "corners": corners}[sys.argv[1]](sys.argv[2], sys.argv[3])
    else:
        sys.exit(__doc__)
