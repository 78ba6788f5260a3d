#!/usr/bin/env python3
"""Tests of scripts/g6_validate.py and the cheap parts of scripts/g6_checks.py.

    g6_validate_test.py ABUOPT

g6_validate: ref_config() is the report's 2003 profile (25 Hz / 1 s, 29.5 Hz / 10 s, 100 Hz / 8 s) with the asked
balls; unpaired() against hand numbers; the whole script on a tiny case (the incumbent of g6_multistart as the
design, seed 9001, 8 starts, six balls and the two-ball reference): its report's paired difference is the run-by-run
mean of design minus 2003 (from the runs.csv files, 1e-9), the ratio is the means' ratio, the unpaired interval the
two half-widths added in quadrature, and the goal line is 18.47 / 1.5. g6_checks: with_imbalance() (x 1 unchanged;
x 0.8 adds imbalance_mass_kg 0.000448 under abu:; an existing 0.00056 line replaced), with_pi(); and abuopt accepts
the -20 % imbalance and PI-motor variants of the 2003 config (2 starts).
"""
import csv
import json
import math
import os
import subprocess
import sys
import tempfile

from script_check import ROOT, check, failures, load_script

sys.path.insert(0, os.path.join(ROOT, "scripts"))  # g6_validate imports startup_study, g6_checks g6_validate
gv = load_script("g6_validate")
gc = load_script("g6_checks")
g6 = load_script("g6_multistart")


def unit():
    ref = gv.ref_config(6)
    segs = [l.strip() for l in ref.splitlines() if "end_frequency_hz" in l]
    check(segs == ["- {end_frequency_hz: 25.0, duration_s: 1.0}", "- {end_frequency_hz: 29.5, duration_s: 10.0}",
                   "- {end_frequency_hz: 100.0, duration_s: 8.0}"] and "ball_count: 6\n" in ref
          and "ball_mass_kg: 4.66667e-05\n" in ref and "friction_mu: 0.03\n" in ref,
          "ref_config(6): the 2003 profile 25 Hz / 1 s, 29.5 Hz / 10 s, 100 Hz / 8 s with six balls of 4.66667e-05 kg")
    check("ball_count: 2\n" in gv.ref_config(2) and "ball_mass_kg: 0.00014\n" in gv.ref_config(2),
          "ref_config(2): the report's two balls of 1.4e-4 kg")
    u = gv.unpaired({"mean": 10.0, "lo": 8.0, "hi": 12.0}, {"mean": 7.0, "lo": 6.0, "hi": 8.0})
    h = math.sqrt(2 ** 2 + 1 ** 2)
    check(abs(u["mean"] - 3) < 1e-12 and abs(u["lo"] - (3 - h)) < 1e-12 and abs(u["hi"] - (3 + h)) < 1e-12,
          f"unpaired(10 [8, 12], 7 [6, 8]) = {u['mean']:.3f} [{u['lo']:.4f}, {u['hi']:.4f}] (hand: 3 -+ sqrt 5)")

    check(gc.with_imbalance(ref, 1.0) == ref, "with_imbalance(x 1.0) leaves the config alone")
    r08 = gc.with_imbalance(ref, 0.8)
    check(r08 == ref.replace("abu:\n", "abu:\n  imbalance_mass_kg: 0.000448\n", 1),
          "with_imbalance(x 0.8) adds imbalance_mass_kg: 0.000448 (0.8 x 5.6e-4) as the first line under abu:")
    withline = ref.replace("abu:\n", "abu:\n  imbalance_mass_kg: 0.00056\n", 1)
    r12 = gc.with_imbalance(withline, 1.2)
    check(r12.count("imbalance_mass_kg") == 1 and "  imbalance_mass_kg: 0.000672\n" in r12,
          "with_imbalance(x 1.2) replaces an existing 0.00056 line by 0.000672")
    pi = gc.with_pi(ref)
    check("kind: pi\n" in pi and "kind: ideal" not in pi and len(pi) == len(ref) - 3,
          "with_pi(): the ideal motor becomes the PI motor, nothing else changes")
    return ref


def mc_ok(abuopt, text, tmp, label):
    cfg = os.path.join(tmp, "v.yaml")
    with open(cfg, "w") as f:
        f.write(text)
    r = subprocess.run([abuopt, "montecarlo", cfg, "--mu", "0.03", "--design", "random", "--runs", "2", "--seed",
                        "9001", "--threads", "1", "--json"], capture_output=True, text=True)
    check(r.returncode in (0, 3) and '"runs"' in r.stdout, f"abuopt montecarlo accepts {label} (exit {r.returncode})")
    if r.returncode not in (0, 3):
        print(r.stderr[-1500:])


def ir_by_run(d, col="ir_magnitude_kgm"):
    return {r["index"]: float(r[col]) / 1e-7 for r in csv.DictReader(open(os.path.join(d, "runs.csv")))
            if r["status"] == "ok"}


def end_to_end(abuopt, ref):
    with tempfile.TemporaryDirectory() as tmp:
        mc_ok(abuopt, gc.with_imbalance(ref, 0.8), tmp, "the 2003 config with -20 % imbalance")
        mc_ok(abuopt, gc.with_pi(ref), tmp, "the 2003 config with the PI motor")

        design = os.path.join(tmp, "design.yaml")
        with open(design, "w") as f:
            f.write(g6.montecarlo_config(g6.incumbent()))
        out = os.path.join(tmp, "val")
        env = dict(os.environ, ABUOPT=abuopt)
        r = subprocess.run([sys.executable, os.path.join(ROOT, "scripts", "g6_validate.py"), "--design", design,
                            "--name", "inc", "--out", out, "--seeds", "9001", "--runs", "8"],
                           capture_output=True, text=True, env=env)
        rep_path = os.path.join(out, "inc", "report_mu0.03.json")
        if not (r.returncode == 0 and os.path.exists(rep_path)):
            check(False, f"g6_validate.py on 8 starts exits 0 and writes its report (exit {r.returncode})")
            print(r.stderr[-2000:])
            return
        print("     " + r.stdout.strip())
        row = json.load(open(rep_path))["seeds"]["9001"]
        dd = os.path.join(out, "inc", "mu0.03_9001_8")
        dr = os.path.join(out, "ref2003_6balls_mu0.03_9001_8")
        a, b = ir_by_run(dd), ir_by_run(dr)
        common = [k for k in a if k in b]
        diff = sum(a[k] - b[k] for k in common) / len(common)
        p = row["paired_same"]
        check(len(common) == 8 and p["n"] == 8 and abs(p["mean"] - diff) < 1e-9,
              f"paired difference {p['mean']:+.4f} = run-by-run mean of design - 2003 over the 8 same starts "
              f"({diff:+.4f})")
        ma, mb = sum(a.values()) / len(a), sum(b.values()) / len(b)
        check(abs(row["design"]["ir"]["mean"] - ma) < 1e-9 and abs(row["ratio_same"] - mb / ma) < 1e-9,
              f"design mean {ma:.4f}, ratio 2003 / design {row['ratio_same']:.4f} (hand {mb / ma:.4f})")
        s, r2, u = row["design"]["ir"], row["ref_two"]["ir"], row["unpaired_two"]
        h = math.hypot((s["hi"] - s["lo"]) / 2, (r2["hi"] - r2["lo"]) / 2)
        check(abs(u["mean"] - (s["mean"] - r2["mean"])) < 1e-9 and abs(u["hi"] - u["lo"] - 2 * h) < 1e-9,
              f"unpaired against the two-ball 2003: {u['mean']:+.3f} [{u['lo']:+.3f}, {u['hi']:+.3f}]")
        check(abs(row["goal"] - 18.47 / 1.5) < 1e-12 and ("REACHED" in r.stdout) == (s["mean"] <= 18.47 / 1.5),
              f"goal for seed 9001: {row['goal']:.3f} (18.47 / 1.5), the line says so")


def main():
    abuopt = sys.argv[1] if len(sys.argv) > 1 else os.environ.get("ABUOPT", "/work/main/build/app/abuopt")
    ref = unit()
    end_to_end(abuopt, ref)
    print(f"{len(failures)} failure(s)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
