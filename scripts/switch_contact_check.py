#!/usr/bin/env python3
"""The switch-model check of issue 10 with hard ball contact (docs/studies/startup-profile.md 8.11).

Runs every design with the event-driven model (as shipped) and with the switch model
(`simulation.method: switch_model`, everything else the same) on the same random starts
(`abuopt montecarlo CONFIG --runs N --seed S`), and prints a Markdown table: mean |I_r| and mean
I_r,x with 95 % intervals (mean +- 1.96 s / sqrt(n)), %MI of both with the Wilson intervals the
command reports, the paired difference switch - event-driven of the mean |I_r| with its 95 %
interval, how many runs end within 0.05 rad (every ball) of each other, and the CPU time per run
of each method (the two commands alternate design by design in one run of this script).

  python3 scripts/switch_contact_check.py --abuopt build/app/abuopt --out results/switch_check
"""
import argparse
import csv
import json
import math
import os
import resource
import subprocess
import sys

BEST = "configs/studies/best"
# (name, config, extra montecarlo arguments)
DESIGNS = [
    ("report_2003", "configs/report_final_profile.yaml", []),
    ("contact_best_19s", "configs/designs/two_balls_19s.yaml", []),
    ("contact_best_8s", BEST + "/contact_best_8s.yaml", []),
    ("contact_f2_min_T", "configs/designs/fast_2balls_8s.yaml", []),
    ("contact_best_mu03 (mu 0.03)", BEST + "/contact_best_mu03.yaml", ["--mu", "0.03"]),
    ("contact_best_robust", BEST + "/contact_best_robust.yaml", []),
    ("contact_f2_min_T_pi (PI motor)", "configs/designs/fast_2balls_8s_pi.yaml", []),
    ("contact_best_mu03_k4 (mu 0.03)", BEST + "/contact_best_mu03_k4.yaml", ["--mu", "0.03"]),
]


def variant(text, method, band):
    """The config text with hard contact and the given friction method."""
    lines = text.splitlines()
    out = []
    has_contact = any(l.strip().startswith("ball_contact:") for l in lines)
    for l in lines:
        s = l.strip()
        if s.startswith("method:"):
            l = l[: len(l) - len(l.lstrip())] + "method: " + method
            if method == "switch_model" and band:
                out.append(l)
                l = l[: len(l) - len(l.lstrip())] + "switch_band: " + band
        out.append(l)
        if s == "abu:" and not has_contact:
            out.append("  ball_contact: hard")
    if not any(l.strip() == "method: " + method for l in out):
        raise ValueError("the config has no simulation.method line to set to " + method)
    return "\n".join(out) + "\n"


def run(abuopt, cfg, outdir, runs, seed, threads, extra):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    res = subprocess.run([abuopt, "montecarlo", cfg, "--design", "random", "--runs", str(runs), "--seed", str(seed), "--threads",
                          str(threads), "--json", "--out", outdir] + extra, capture_output=True, text=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if res.returncode != 0:
        sys.exit("montecarlo failed for %s: %s" % (cfg, res.stderr))
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    with open(os.path.join(outdir, "runs.csv")) as f:
        rows = list(csv.DictReader(f))
    return json.loads(res.stdout), rows, cpu


def mean_ci(xs):
    n = len(xs)
    m = sum(xs) / n
    sd = math.sqrt(sum((x - m) ** 2 for x in xs) / (n - 1))
    h = 1.96 * sd / math.sqrt(n)
    return m, m - h, m + h


def angle_distance(a, b):
    d = math.fmod(abs(a - b), 2 * math.pi)
    return min(d, 2 * math.pi - d)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--abuopt", default="build/app/abuopt")
    ap.add_argument("--out", required=True)
    ap.add_argument("--runs", type=int, default=256)
    ap.add_argument("--seed", type=int, default=9001)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--band", default="", help="simulation.switch_band (default: the config's, 1e-4)")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    e7 = 1e7
    print("| design | method | mean \\|I_r\\| [95 %] | %MI(\\|I_r\\|) [95 %] | mean I_r,x [95 %] | %MI(I_r,x) [95 %] "
          "| failed | CPU ms/run |")
    print("|---|---|---|---|---|---|---|---|")
    paired = []
    for name, cfg, extra in DESIGNS:
        with open(cfg) as f:
            text = f.read()
        results = {}
        for method in ("event_driven", "switch_model"):
            tag = name.split(" ")[0] + "_" + method
            path = os.path.join(a.out, tag + ".yaml")
            with open(path, "w") as f:
                f.write(variant(text, method, a.band))
            summ, rows, cpu = run(a.abuopt, path, os.path.join(a.out, tag), a.runs, a.seed, a.threads, extra)
            results[method] = (summ, rows, cpu)
            ok = [r for r in rows if r["status"] == "ok"]
            m = mean_ci([float(r["ir_magnitude_kgm"]) * e7 for r in ok])
            mx = mean_ci([float(r["ir_x_kgm"]) * e7 for r in ok])
            mi, mix = summ["magnitude"], summ["report_x"]
            print("| %s | %s | %.2f [%.2f, %.2f] | %.1f [%.1f, %.1f] | %.2f [%.2f, %.2f] | %.1f [%.1f, %.1f] | %d | %.2f |" % (
                name, method, m[0], m[1], m[2], mi["pct_mi"], mi["pct_mi_ci95"][0], mi["pct_mi_ci95"][1],
                mx[0], mx[1], mx[2], mix["pct_mi"], mix["pct_mi_ci95"][0], mix["pct_mi_ci95"][1],
                summ["failed"], 1e3 * cpu / a.runs))
        ev, sw = results["event_driven"][1], results["switch_model"][1]
        diffs, diffx, agree, both = [], [], 0, 0
        for r, s in zip(ev, sw):
            assert r["index"] == s["index"] and r["beta0_1"] == s["beta0_1"], "not the same starts"
            if r["status"] != "ok" or s["status"] != "ok":
                continue
            both += 1
            diffs.append((float(s["ir_magnitude_kgm"]) - float(r["ir_magnitude_kgm"])) * e7)
            diffx.append((float(s["ir_x_kgm"]) - float(r["ir_x_kgm"])) * e7)
            nb = sum(1 for k in r if k.startswith("beta_final_"))
            d = max(angle_distance(float(r["beta_final_%d" % (i + 1)]), float(s["beta_final_%d" % (i + 1)]))
                    for i in range(nb))
            agree += d < 0.05
        ratio = results["switch_model"][2] / max(results["event_driven"][2], 1e-9)
        paired.append((name, mean_ci(diffs), mean_ci(diffx), agree, both, ratio))
    print()
    print("| design | paired switch - event-driven, mean \\|I_r\\| [95 %] | same, I_r,x [95 %] "
          "| runs within 0.05 rad | CPU switch / event-driven |")
    print("|---|---|---|---|---|")
    for name, d, dx, agree, both, ratio in paired:
        print("| %s | %+.2f [%+.2f, %+.2f] | %+.2f [%+.2f, %+.2f] | %d of %d | %.2f |" % (
            name, d[0], d[1], d[2], dx[0], dx[1], dx[2], agree, both, ratio))


if __name__ == "__main__":
    main()
