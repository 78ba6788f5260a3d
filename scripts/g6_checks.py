#!/usr/bin/env python3
"""The checks of a shipped mu-0.03 design (seed 9001 unless told): the robust grid mu {0.02, 0.03, 0.04} x imbalance
{-20, 0, +20 %} (1024 random starts each), the PI motor at mu 0.03, and the switch model (256 starts), each beside
the 2003 profile with the same balls on the same starts (paired).

  g6_checks.py --design CFG --out DIR [--what grid,pi,switch] [--seed 9001]

CFG must be a montecarlo config with `abu:` (no imbalance_mass_kg line), `motor:\n  kind: ideal` and
`simulation:\n  method: event_driven`.
"""
import argparse
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from startup_study import statistics_of, paired_of  # noqa: E402
from g6_validate import ref_config, ABUOPT  # noqa: E402
from switch_contact_check import variant, angle_distance, mean_ci  # noqa: E402
import csv  # noqa: E402

M_I = 5.6e-4


def with_imbalance(text, factor):
    if factor == 1.0:
        return text
    import re
    line = f"  imbalance_mass_kg: {M_I * factor:.6g}"
    if re.search(r"^  imbalance_mass_kg:.*$", text, flags=re.M):
        assert "imbalance_mass_kg: 0.00056\n" in text
        return re.sub(r"^  imbalance_mass_kg:.*$", line, text, count=1, flags=re.M)
    return text.replace("abu:\n", "abu:\n" + line + "\n", 1)


def with_pi(text):
    assert "kind: ideal" in text
    return text.replace("kind: ideal", "kind: pi", 1)


def mc(text, d, runs, seed, mu):
    if os.path.exists(os.path.join(d, "summary.json")):
        return
    os.makedirs(d, exist_ok=True)
    cfg = os.path.join(d, "config.yaml")
    with open(cfg, "w") as f:
        f.write(text)
    r = subprocess.run(["nice", "-n", "5", ABUOPT, "montecarlo", cfg, "--mu", str(mu), "--design", "random",
                        "--runs", str(runs), "--seed", str(seed), "--threads", "1", "--out", d],
                       capture_output=True, text=True)
    if r.returncode not in (0, 3):
        sys.exit(f"montecarlo failed in {d}: {r.stderr[-1500:]}")


def pair_line(label, dd, dr):
    s, r = statistics_of(dd), statistics_of(dr)
    p = paired_of(dd, dr)
    return (f"{label}: design {s['ir']['mean']:.2f} [{s['ir']['lo']:.2f}, {s['ir']['hi']:.2f}] ok {s['ok']}/{s['runs']} "
            f"%MI {s['ir']['pct_mi']:.1f}; 2003 same balls {r['ir']['mean']:.2f} ok {r['ok']}/{r['runs']}; paired "
            f"{p['mean']:+.2f} [{p['lo']:+.2f}, {p['hi']:+.2f}] ({p['relative_pct']:+.1f} %)")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--design", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--what", default="grid,pi,switch")
    ap.add_argument("--seed", type=int, default=9001)
    ap.add_argument("--balls", type=int, default=6)
    a = ap.parse_args()
    design = open(a.design).read()
    ref = ref_config(a.balls)
    what = a.what.split(",")
    if "grid" in what:
        for mu in (0.02, 0.03, 0.04):
            for fac in (0.8, 1.0, 1.2):
                tag = f"mu{mu:g}_im{fac:g}_{a.seed}"
                dd, dr = os.path.join(a.out, "design", tag), os.path.join(a.out, "ref2003", tag)
                mc(with_imbalance(design, fac), dd, 1024, a.seed, mu)
                mc(with_imbalance(ref, fac), dr, 1024, a.seed, mu)
                print(pair_line(f"grid mu {mu:g} imbalance {100 * (fac - 1):+.0f} %", dd, dr), flush=True)
    if "pi" in what:
        tag = f"pi_mu0.03_{a.seed}"
        dd, dr = os.path.join(a.out, "design", tag), os.path.join(a.out, "ref2003", tag)
        mc(with_pi(design), dd, 1024, a.seed, 0.03)
        mc(with_pi(ref), dr, 1024, a.seed, 0.03)
        print(pair_line("PI motor, mu 0.03", dd, dr), flush=True)
    if "switch" in what:
        out = {}
        for method in ("event_driven", "switch_model"):
            d = os.path.join(a.out, "design", f"{method}_256_{a.seed}")
            mc(variant(design, method, ""), d, 256, a.seed, 0.03)
            out[method] = d
        s_ev, s_sw = statistics_of(out["event_driven"]), statistics_of(out["switch_model"])
        ev = list(csv.DictReader(open(os.path.join(out["event_driven"], "runs.csv"))))
        sw = list(csv.DictReader(open(os.path.join(out["switch_model"], "runs.csv"))))
        diffs, agree, both = [], 0, 0
        for r, s in zip(ev, sw):
            assert r["index"] == s["index"] and r["beta0_1"] == s["beta0_1"]
            if r["status"] != "ok" or s["status"] != "ok":
                continue
            both += 1
            diffs.append((float(s["ir_magnitude_kgm"]) - float(r["ir_magnitude_kgm"])) * 1e7)
            nb = sum(1 for k in r if k.startswith("beta_final_"))
            agree += max(angle_distance(float(r[f"beta_final_{i + 1}"]), float(s[f"beta_final_{i + 1}"]))
                         for i in range(nb)) < 0.05
        m = mean_ci(diffs)
        print(f"switch model (256 starts, mu 0.03): {s_sw['ir']['mean']:.2f} [{s_sw['ir']['lo']:.2f}, "
              f"{s_sw['ir']['hi']:.2f}] against {s_ev['ir']['mean']:.2f} [{s_ev['ir']['lo']:.2f}, {s_ev['ir']['hi']:.2f}]"
              f" event-driven; paired {m[0]:+.2f} [{m[1]:+.2f}, {m[2]:+.2f}]; {agree} of {both} runs within 0.05 rad",
              flush=True)


if __name__ == "__main__":
    main()
