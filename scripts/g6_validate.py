#!/usr/bin/env python3
"""Out-of-sample check of a design at mu 0.03 (1024 fresh random starts per seed), paired with the 2003 profile with
the same balls on the same starts, and unpaired against the 2003 profile with the report's two balls.

  g6_validate.py --design CFG --name NAME --out DIR [--seeds 9001,9002,9003] [--runs 1024] [--balls 6]

CFG: a montecarlo config of the design (abu with the balls, profile, motor, simulation). The reference runs
(2003 profile, same balls / two balls) are made once per seed under DIR/ref_*. Prints one line per seed and
writes DIR/NAME/report.json.
"""
import argparse
import json
import math
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from startup_study import statistics_of, paired_of  # noqa: E402

ABUOPT = os.environ.get("ABUOPT", "/work/main/build/app/abuopt")
BALLS = {6: (4.66667e-05, 0.00208008), 5: (5.6e-05, 0.00221042), 2: (1.4e-04, 0.003)}
GOAL = {9001: 18.47 / 1.5, 9002: 18.27 / 1.5, 9003: 18.14 / 1.5}


def ref_config(balls):
    m, d = BALLS[balls]
    return (f"abu:\n  friction_mu: 0.03\n  ball_contact: hard\n  ball_count: {balls}\n  ball_mass_kg: {m}\n"
            f"  ball_diameter_m: {d}\n"
            "profile:                        # the report's 2003 profile\n  start_frequency_hz: 0\n  segments:\n"
            "    - {end_frequency_hz: 25.0, duration_s: 1.0}\n    - {end_frequency_hz: 29.5, duration_s: 10.0}\n"
            "    - {end_frequency_hz: 100.0, duration_s: 8.0}\n"
            "motor:\n  kind: ideal\nsimulation:\n  method: event_driven\n  rtol: 1.0e-6\n")


def mc(cfg, d, runs, seed, mu=0.03, extra=()):
    if os.path.exists(os.path.join(d, "summary.json")):
        return
    os.makedirs(d, exist_ok=True)
    cmd = ["nice", "-n", "5", ABUOPT, "montecarlo", cfg, "--mu", str(mu), "--design", "random", "--runs", str(runs),
           "--seed", str(seed), "--threads", "1", "--out", d] + list(extra)
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode not in (0, 3):
        sys.exit(f"montecarlo failed on {cfg}: {r.stderr[-2000:]}")


def unpaired(a, b):
    """Difference of two means with their own intervals (normal): a, b from statistics_of()['ir']."""
    ha, hb = (a["hi"] - a["lo"]) / 2, (b["hi"] - b["lo"]) / 2
    diff = a["mean"] - b["mean"]
    h = math.sqrt(ha * ha + hb * hb)
    return {"mean": diff, "lo": diff - h, "hi": diff + h}


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--design", required=True)
    p.add_argument("--name", required=True)
    p.add_argument("--out", required=True)
    p.add_argument("--seeds", default="9001,9002,9003")
    p.add_argument("--runs", type=int, default=1024)
    p.add_argument("--balls", type=int, default=6)
    p.add_argument("--mu", type=float, default=0.03)
    p.add_argument("--no-two-ball", action="store_true")
    p.add_argument("--extra", default="", help="extra montecarlo options for the design and the same-ball 2003 runs")
    a = p.parse_args()
    extra = a.extra.split() if a.extra else []
    tag = f"mu{a.mu:g}" + ("_" + "_".join(x.strip("-") for x in extra) if extra else "")
    os.makedirs(a.out, exist_ok=True)
    report = {"design": a.design, "runs": a.runs, "mu": a.mu, "extra": extra, "seeds": {}}
    for seed in (int(s) for s in a.seeds.split(",")):
        refs = {}
        for balls in ([a.balls] if a.no_two_ball else sorted({a.balls, 2})):
            cfg = os.path.join(a.out, f"ref2003_{balls}balls.yaml")
            with open(cfg, "w") as f:
                f.write(ref_config(balls))
            d = os.path.join(a.out, f"ref2003_{balls}balls_{tag}_{seed}_{a.runs}")
            mc(cfg, d, a.runs, seed, a.mu, extra if balls == a.balls else ())
            refs[balls] = d
        d = os.path.join(a.out, a.name, f"{tag}_{seed}_{a.runs}")
        mc(a.design, d, a.runs, seed, a.mu, extra)
        s = statistics_of(d)
        r_same = statistics_of(refs[a.balls])
        pr = paired_of(d, refs[a.balls])
        prx = paired_of(d, refs[a.balls], "ir_x_kgm")
        row = {"design": s, "ref_same": r_same, "paired_same": pr, "paired_same_irx": prx,
               "ratio_same": r_same["ir"]["mean"] / s["ir"]["mean"]}
        line = (f"seed {seed}: {s['ir']['mean']:.2f} [{s['ir']['lo']:.2f}, {s['ir']['hi']:.2f}] ok {s['ok']}/{s['runs']} "
                f"amp {s['amp_max_mm']:.3f} %MI {s['ir']['pct_mi']:.1f}; 2003 same balls {r_same['ir']['mean']:.2f} "
                f"paired {pr['mean']:+.2f} [{pr['lo']:+.2f}, {pr['hi']:+.2f}] ({row['ratio_same']:.3f} x)")
        if 2 in refs and a.balls != 2:
            r2 = statistics_of(refs[2])
            row["ref_two"] = r2
            row["unpaired_two"] = unpaired(s["ir"], r2["ir"])
            row["ratio_two"] = r2["ir"]["mean"] / s["ir"]["mean"]
            u = row["unpaired_two"]
            line += (f"; 2003 two balls {r2['ir']['mean']:.2f} unpaired {u['mean']:+.2f} [{u['lo']:+.2f}, {u['hi']:+.2f}]"
                     f" ({row['ratio_two']:.3f} x)")
        if a.mu == 0.03 and not extra and seed in GOAL:
            row["goal"] = GOAL[seed]
            line += f"; goal <= {GOAL[seed]:.2f}: {'REACHED' if s['ir']['mean'] <= GOAL[seed] else 'not reached'}"
        report["seeds"][seed] = row
        print(line, flush=True)
    with open(os.path.join(a.out, a.name, f"report_{tag}.json"), "w") as f:
        json.dump(report, f, indent=1)


if __name__ == "__main__":
    main()
