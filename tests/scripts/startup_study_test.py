#!/usr/bin/env python3
"""Tests of scripts/startup_study.py (the issue-10 study runner).

    startup_study_test.py ABUOPT unit          # default suite, a few seconds: the --contact plumbing
    startup_study_test.py ABUOPT end_to_end    # ctest -L long: the whole study at --scale 0.02, then resumed

unit: stage 4c's shake insertion against the profile it edits (shakes()); stage 5c's excursion, acceleration
repair and the deep family's x (mean_goal()); every study config gets exactly one
active `ball_contact: hard` with --contact hard and is left byte-identical with --contact none (so the no-contact
study replays its archives); abuopt accepts the generated configs; the equal-mass ball sets have the closed-form
masses and diameters; the paired difference is the mean of the run-by-run differences; an output folder of one
contact setting is refused with the other.
end_to_end: every stage runs and writes its outputs (stage 4c with --shake-balls 3, stage 5c's chain), every optimised and validated
config carries the contact setting, and a second run replays every evaluation from the archives (nothing computed).
"""
import csv
import json
import os
import re
import subprocess
import sys
import tempfile

from script_check import ROOT, check, failures, load_script

SCRIPT = os.path.join(ROOT, "scripts", "startup_study.py")
study = load_script("startup_study")


def active_contact_lines(text):
    return re.findall(r"^\s*ball_contact:\s*(\S+)", text, re.M)


def unit(abuopt, tmp):
    cdir = os.path.join(ROOT, "configs", "studies")
    for name in sorted(os.listdir(cdir)):
        if not name.endswith(".yaml"):
            continue
        text = study.read(os.path.join(cdir, name))
        if re.search(r"^stages:", text, re.M):
            continue  # an `abuopt study` file (docs/study.md), not a config of this script
        check(study.with_contact(text, "none") == text, f"{name}: --contact none leaves the config unchanged")
        hard = study.with_contact(text, "hard")
        check(active_contact_lines(hard) == ["hard"], f"{name}: --contact hard sets exactly one ball_contact: hard")
        check(active_contact_lines(text) == [], f"{name}: the committed config decides no contact model itself")
    try:
        study.with_contact("abu:\n  ball_contact: none\n", "hard")
        check(False, "a config that sets ball_contact itself is refused")
    except ValueError:
        check(True, "a config that sets ball_contact itself is refused")
    check(study.with_contact("abu:\n  friction_mu: 0.02\n", "hard") == "abu:\n" + study.CONTACT_LINE + "  friction_mu: 0.02\n",
          "ball_contact is added to an abu section without the commented line")

    # Equal total mass 2.8e-4 kg, same material: d = 3 mm (2 / nb)^(1/3).
    for nb in range(2, 7):
        balls = study.equal_mass_balls(nb)
        mass = sum(m for m, _ in balls)
        d = balls[0][1]
        check(len(balls) == nb and abs(mass - 2.8e-4) < 1e-15 and abs(d - 3e-3 * (2.0 / nb) ** (1 / 3)) < 1e-15,
              f"{nb} balls: total mass {mass:.4g} kg, diameter {d * 1e3:.5f} mm")

    # The generated run configs parse and run with either contact setting (4 runs each).
    k4 = study.with_balls(study.with_contact(study.read(os.path.join(cdir, "f1_k4_hold.yaml")), "hard"),
                          study.equal_mass_balls(3))
    cfg = os.path.join(tmp, "k4_3balls.yaml")
    with open(cfg, "w") as f:
        f.write(study.set_section_value(k4, "runs", 4))
    r = subprocess.run([abuopt, "optimize", cfg, "--out", os.path.join(tmp, "k4"), "--max-evaluations", "1",
                        "--threads", "1"], capture_output=True, text=True)
    res = json.load(open(os.path.join(tmp, "k4", "result.json"))) if r.returncode in (0, 3) else {}
    check(r.returncode in (0, 3) and res.get("best", {}).get("metrics", {}).get("runs") == 4,
          "abuopt optimize accepts a study config with 3 balls and hard contact")
    for contact in ("none", "hard"):
        text = study.run_config(study.report_profile(), "test", contact=contact, balls=study.equal_mass_balls(4))
        check(active_contact_lines(text) == ([] if contact == "none" else ["hard"]),
              f"run_config --contact {contact}: ball_contact lines")
        cfg = os.path.join(tmp, f"run_{contact}.yaml")
        with open(cfg, "w") as f:
            f.write(text)
        out = os.path.join(tmp, f"mc_{contact}")
        r = subprocess.run([abuopt, "montecarlo", cfg, "--runs", "4", "--threads", "1", "--out", out],
                           capture_output=True, text=True)
        ok = r.returncode == 0 and json.load(open(os.path.join(out, "summary.json")))["ok"] == 4
        check(ok, f"abuopt montecarlo runs the validation config with contact {contact} (4 balls)")

    shakes(abuopt, tmp, cdir)
    mean_goal(abuopt, tmp, cdir)

    # Paired difference: the mean of the run-by-run differences, over the runs ok in both.
    a, b = os.path.join(tmp, "pa"), os.path.join(tmp, "pb")
    for d, vals in ((a, [3.0, 5.0, 7.0, None]), (b, [1.0, 2.0, 3.0, 9.0])):
        os.makedirs(d, exist_ok=True)
        with open(os.path.join(d, "runs.csv"), "w") as f:
            w = csv.writer(f)
            w.writerow(["index", "ir_magnitude_kgm", "ir_x_kgm", "status"])
            for i, v in enumerate(vals):  # I_r,x: half of |I_r|
                w.writerow([i, (v if v is not None else 0.0) * 1e-7, (v if v is not None else 0.0) * 0.5e-7,
                            "ok" if v is not None else "solver_failure"])
    p = study.paired_of(a, b)
    # differences 2, 3, 4: mean 3, sd 1, half width 1.96 / sqrt(3); reference mean 2 -> +150 %
    check(p["n"] == 3 and abs(p["mean"] - 3.0) < 1e-12 and abs(p["hi"] - 3.0 - 1.96 / 3 ** 0.5) < 1e-12
          and abs(p["relative_pct"] - 150.0) < 1e-9, f"paired difference {p}")
    px = study.paired_of(a, b, "ir_x_kgm")  # differences 1, 1.5, 2: mean 1.5, sd 0.5; reference mean 1 -> +150 %
    check(px["n"] == 3 and abs(px["mean"] - 1.5) < 1e-12 and abs(px["hi"] - 1.5 - 0.98 / 3 ** 0.5) < 1e-12
          and abs(px["relative_pct"] - 150.0) < 1e-9, f"paired difference of I_r,x {px}")

    # Stage 8's case counts (its ETA) against the grids of scripts/stop_depth_study.py: quick 2 x 2 x 3 x 4 approaches,
    # 2 x 8 oscillations, 2 x 2 x 2 x 2 releases; full: the published 96 and 576, and the two release scans.
    counts = {w: [study.stop_depth_cases(f, args) for f, args in study.STOP_DEPTH[w]] for w in ("quick", "full")}
    check(counts == {"quick": [48, 16, 16], "full": [96, 576, 144, 36]}, f"stop-depth case counts {counts}")

    # A folder made with one contact setting is refused with the other, before any work.
    out = os.path.join(tmp, "mixed")
    os.makedirs(out)
    with open(os.path.join(out, "contact.txt"), "w") as f:
        f.write("none\n")
    r = subprocess.run([sys.executable, SCRIPT, "--abuopt", abuopt, "--out", out, "--contact", "hard"],
                       capture_output=True, text=True)
    check(r.returncode != 0 and "refusing" in r.stderr and os.listdir(out) == ["contact.txt"],
          "a --contact none folder is refused by --contact hard, nothing written")


def shakes(abuopt, tmp, cdir):
    """Stage 4c's shake insertion against the inclined-sine profile it edits: f(t) unchanged up to the insertion and
    delayed by the shake's 2 d after it, the lowest point the requested depth below the dwell, the peak |f'| at the
    acceleration limit (within SHAKE_RATE_MARGIN), and abuopt reading the families' x back as the same profile."""
    segs = [(22.6222, 1.55852), (28.9129, 3.4931), (28.9129, 3.71217), (100.0, 5.08554)]  # contact_best_mu03_k4
    new = study.insert_shake(segs, 2, 1.5, 3.0)
    d = study.shake_duration(3.0)
    t_ins, total = 1.55852 + 3.4931 + 1.5, sum(dt for _, dt in segs)
    grid = [total * k / 4000 for k in range(4001)]
    before = max(abs(study.frequency_at(new, t) - study.frequency_at(segs, t)) for t in grid if t <= t_ins)
    after = max(abs(study.frequency_at(new, t + 2 * d) - study.frequency_at(segs, t)) for t in grid if t >= t_ins)
    check(before < 1e-12 and after < 1e-9, f"f(t) unchanged before the shake ({before:.1e}), delayed by 2 d after it "
          f"({after:.1e})")
    fine = [t_ins + 2 * d * k / 2000 for k in range(2001)]  # k = 1000: the end of the way down
    low = min(study.frequency_at(new, t) for t in fine)
    rate = max(abs(study.frequency_at(new, b) - study.frequency_at(new, a)) / (b - a) for a, b in zip(fine, fine[1:]))
    check(abs(low - (28.9129 - 3.0)) < 1e-9, f"the shake reaches 3 Hz below the dwell ({low:.6f} Hz)")
    check(study.MAX_RATE_HZ_S / study.SHAKE_RATE_MARGIN * 0.9999 < rate <= study.MAX_RATE_HZ_S,
          f"the shake's peak f' {rate:.4f} Hz/s at the acceleration limit {study.MAX_RATE_HZ_S:.4f}")
    check(abs(sum(dt for _, dt in new) - (total + 2 * d)) < 1e-12 and abs(d - 0.12 * study.SHAKE_RATE_MARGIN) < 1e-4
          and len(new) == 7 and study.dwells(new) == [2, 5], f"7 segments, total {total:.5f} + 2 x {d:.5f} s")
    for args, what in (((segs, 1, 1.0, 3.0), "a ramp"), ((segs, 2, 0.0, 3.0), "offset 0"),
                       ((segs, 2, 3.71217, 3.0), "offset = the dwell"), ((segs, 2, 1.5, 28.9129), "depth = f"),
                       ((segs, 4, 1.5, 3.0), "index out of range")):
        try:
            study.insert_shake(*args)
            check(False, f"insert_shake refuses {what}")
        except ValueError:
            check(True, f"insert_shake refuses {what}")
    # deepen_first_excursion: the first excursion after the first dwell replaced by a fall to the bottom and a rise
    # back to where it returned, each at the acceleration limit; before it the profile is unchanged, after it delayed.
    deep = study.deepen_first_excursion(new, 22.5)
    k = study.dwells(new)[0]
    t_dwell_end = sum(dt for _, dt in new[:k + 1])
    d_down, d_up = study.shake_duration(28.9129 - 22.5), study.shake_duration(28.9129 - 22.5)
    shift = d_down + d_up - 2 * d
    fine = [t_dwell_end + (d_down + d_up) * j / 4000 for j in range(4001)]
    low = min(study.frequency_at(deep, t) for t in fine)
    rate = max(abs(study.frequency_at(deep, b) - study.frequency_at(deep, a)) / (b - a) for a, b in zip(fine, fine[1:]))
    before = max(abs(study.frequency_at(deep, t) - study.frequency_at(new, t)) for t in grid if t <= t_dwell_end)
    after = max(abs(study.frequency_at(deep, t + shift) - study.frequency_at(new, t))
                for t in grid if t_dwell_end + 2 * d <= t <= total + 2 * d)
    check(len(deep) == len(new) and deep[k + 1][0] == 22.5 and deep[k + 2][0] == new[k + 2][0]
          and abs(low - 22.5) < 1e-9 and study.MAX_RATE_HZ_S / study.SHAKE_RATE_MARGIN * 0.9999 < rate
          <= study.MAX_RATE_HZ_S and before < 1e-12 and after < 1e-9
          and abs(d_down - 2 * 6.4129 / study.MAX_RATE_HZ_S * study.SHAKE_RATE_MARGIN) < 1e-12,
          f"deepen_first_excursion: down to {low:.6f} Hz at peak f' {rate:.4f} Hz/s, unchanged before ({before:.1e}), "
          f"delayed by {shift:.5f} s after ({after:.1e})")
    for args, what in (((new, 28.9129), "bottom = the dwell"), ((new, 0.0), "bottom 0"),
                       ((segs[:1] + [(28.0, 1.0)], 20.0), "no dwell")):
        try:
            study.deepen_first_excursion(*args)
            check(False, f"deepen_first_excursion refuses {what}")
        except ValueError:
            check(True, f"deepen_first_excursion refuses {what}")
    # The two-shake profile in the families' bounds (no clipping), and abuopt reads x back as that profile.
    two = study.insert_shake(new, 5, 1.5, 3.0)
    for name, prof in (("f3_mu03_shake1", new), ("f3_mu03_shake2", two)):
        text = study.set_section_value(study.read(os.path.join(cdir, name + ".yaml")), "runs", 4)
        x, clipped = study.design_x(prof, text)
        bnd = study.bounds_of(text)
        check(not clipped and len(x) == {7: 11, 10: 16}[len(prof)]
              and all(bnd[k][0] <= v <= bnd[k][1] for k, v in x.items()), f"{name}: x0 of {len(x)} variables in bounds")
        cfg = os.path.join(tmp, name + ".yaml")
        with open(cfg, "w") as f:
            f.write(study.set_x0(text, x))
        r = subprocess.run([abuopt, "optimize", cfg, "--out", os.path.join(tmp, name), "--max-evaluations", "1",
                            "--threads", "1"], capture_output=True, text=True)
        best = json.load(open(os.path.join(tmp, name, "result.json")))["best"] if r.returncode in (0, 3) else {}
        got = study.segments_of(best["profile"]) if best else []
        same = len(got) == len(prof) and all(abs(a - b) <= 1e-5 * b for p, q in zip(got, prof) for a, b in zip(p, q))
        check(same and best["metrics"]["peak_angular_acceleration_rad_s2"] <= 314.16,
              f"{name}: abuopt evaluates the inserted profile (peak "
              f"{best.get('metrics', {}).get('peak_angular_acceleration_rad_s2')} rad/s^2)")


def mean_goal(abuopt, tmp, cdir):
    """Stage 5c's pure helpers: the excursion inserted with T kept (f(t) unchanged before it, the dwell shortened by
    its 2 d, the peak |f'| at the limit, up or down), the acceleration repair (every too-fast segment slowed to the
    limit, the time from the longest dwell, no frequency moved, T kept), the profile of a config's x, and abuopt
    reading the deep family's x back as the inserted profile."""
    segs = [(23.867, 2.058), (28.915, 3.242), (28.915, 4.325), (100.0, 8.478)]  # the runner's k4_hold design
    total = sum(dt for _, dt in segs)
    up = study.insert_excursion(segs, 2, 2.77, 28.915 + 2.2)
    d = study.shake_duration(2.2)
    t_ins = 2.058 + 3.242 + 2.77
    grid = [total * k / 4000 for k in range(4001)]
    before = max(abs(study.frequency_at(up, t) - study.frequency_at(segs, t)) for t in grid if t <= t_ins)
    fine = [t_ins + 2 * d * k / 2000 for k in range(2001)]
    top = max(study.frequency_at(up, t) for t in fine)
    rate = max(abs(study.frequency_at(up, b) - study.frequency_at(up, a)) / (b - a) for a, b in zip(fine, fine[1:]))
    after = max(abs(study.frequency_at(up, t) - study.frequency_at(segs, t)) for t in grid if t >= t_ins + 2 * d)
    check(abs(sum(dt for _, dt in up) - total) < 1e-12 and len(up) == 7 and study.dwells(up) == [2, 5]
          and abs(up[5][1] - (4.325 - 2.77 - 2 * d)) < 1e-12 and before < 1e-12 and after < 1e-12
          and abs(top - 31.115) < 1e-9
          and study.MAX_RATE_HZ_S / study.SHAKE_RATE_MARGIN * 0.9999 < rate <= study.MAX_RATE_HZ_S,
          f"insert_excursion up 2.2 Hz: T kept, f(t) unchanged before ({before:.1e}) and after ({after:.1e}), top "
          f"{top:.6f} Hz, peak f' {rate:.4f} Hz/s")
    deep = study.insert_excursion(up, 2, 0.05, 24.0)
    dd = study.shake_duration(28.915 - 24.0)
    check(len(deep) == 10 and abs(sum(dt for _, dt in deep) - total) < 1e-12 and deep[3] == (24.0, dd)
          and deep[4] == (28.915, dd) and abs(deep[5][1] - (up[2][1] - 0.05 - 2 * dd)) < 1e-12
          and abs(dd - 2 * 4.915 / study.MAX_RATE_HZ_S * study.SHAKE_RATE_MARGIN) < 1e-12,
          f"insert_excursion down to 24 Hz 0.05 s in: 10 segments, T kept, {dd:.5f} s each way")
    for args, what in (((segs, 1, 1.0, 25.0), "a ramp"), ((segs, 2, 0.0, 25.0), "offset 0"),
                       ((segs, 2, 4.325, 25.0), "offset = the dwell"), ((segs, 2, 1.0, 28.915), "to = f"),
                       ((segs, 2, 4.3, 25.0), "no time left for the excursion"), ((segs, 5, 1.0, 25.0), "index")):
        try:
            study.insert_excursion(*args)
            check(False, f"insert_excursion refuses {what}")
        except ValueError:
            check(True, f"insert_excursion refuses {what}")
    # repair_rates: two segments 4 % over the limit (peak 2 H / dt), the second-longest dwell untouched
    r = study.MAX_RATE_HZ_S * 1.04
    bad = deep[:3] + [(24.0, 2 * 4.915 / r), (28.915, 2 * 4.915 / r)] + deep[5:]
    fixed, slowed = study.repair_rates(bad)
    ends = [0.0] + [f for f, _ in fixed]
    rates = [study.peak_rate(f - e, dt) for (f, dt), e in zip(fixed, ends)]
    added = 2 * (dd - 2 * 4.915 / r)
    longest = max(study.dwells(bad), key=lambda i: bad[i][1])
    check(slowed == [3, 4] and max(rates) <= study.MAX_RATE_HZ_S and abs(fixed[3][1] - dd) < 1e-12
          and [f for f, _ in fixed] == [f for f, _ in bad] and abs(sum(dt for _, dt in fixed) - sum(dt for _, dt in bad))
          < 1e-12 and abs(fixed[longest][1] - (bad[longest][1] - added)) < 1e-12
          and all(fixed[i] == bad[i] for i in range(len(bad)) if i not in (3, 4, longest)),
          f"repair_rates: segments {slowed} slowed to the limit ({max(rates):.4f} Hz/s), {added:.5f} s from dwell "
          f"{longest}, T kept")
    check(study.repair_rates(deep) == (deep, []), "repair_rates leaves a profile within the limit unchanged")
    try:
        study.repair_rates([(25.0, 0.1), (25.0, 0.25), (100.0, 8.0)])
        check(False, "repair_rates refuses when the longest dwell cannot give the time")
    except ValueError:
        check(True, "repair_rates refuses when the longest dwell cannot give the time")
    # fit_duration: the excess over T taken from the longest durations first, each kept at its lower bound
    x = study.fit_duration({"f1": 25.0, "dt1": 1.0, "dt2": 0.5, "dt3": 0.3}, {"dt1": (0.9, 3), "dt2": (0.2, 3),
                                                                           "dt3": (0.2, 3)}, 1.5)
    check(abs(x["dt1"] - 0.9) < 1e-12 and abs(x["dt2"] - 0.3) < 1e-12 and x["dt3"] == 0.3 and x["f1"] == 25.0,
          f"fit_duration takes 0.3 s from dt1 (to its bound 0.9) then dt2: {x}")
    # The deep family's x of that profile, read back by segments_of_x and by abuopt as the same profile.
    text = study.set_section_value(study.read(os.path.join(cdir, "mu02", "f1_mu02_deep_polish_6balls.yaml")), "runs", 4)
    x, clipped = study.design_x(deep, text)
    back = study.segments_of_x(text, x)
    check(not clipped and len(x) == 16 and all(abs(a - b) < 1e-12 for p, q in zip(back, deep) for a, b in zip(p, q)),
          f"the deep family's x of the profile: {len(x)} variables, no clipping, segments_of_x gives it back")
    cfg = os.path.join(tmp, "deep.yaml")
    with open(cfg, "w") as f:
        f.write(study.set_x0(text, x))
    res = subprocess.run([abuopt, "optimize", cfg, "--out", os.path.join(tmp, "deep"), "--max-evaluations", "1",
                          "--threads", "1"], capture_output=True, text=True)
    best = json.load(open(os.path.join(tmp, "deep", "result.json")))["best"] if res.returncode in (0, 3) else {}
    got = study.segments_of(best["profile"]) if best else []
    same = len(got) == len(deep) and all(abs(a - b) <= 1e-5 * b for p, q in zip(got, deep) for a, b in zip(p, q))
    check(same and best["metrics"]["peak_angular_acceleration_rad_s2"] <= 314.16,
          f"abuopt evaluates the deep family at that x as the profile (peak "
          f"{best.get('metrics', {}).get('peak_angular_acceleration_rad_s2')} rad/s^2)")


def end_to_end(abuopt, tmp):
    out = os.path.join(tmp, "study")
    base = [sys.executable, SCRIPT, "--abuopt", abuopt, "--out", out, "--scale", "0.02", "--val-runs", "8",
            "--threads", "2", "--nice", "0", "--shake-balls", "3"]
    cmd = base + ["--mean-goal-stop", "0"]  # stage 5c: every replication
    r = subprocess.run(cmd, capture_output=True, text=True)
    check(r.returncode == 0, f"the study runs end to end (status {r.returncode}) {r.stderr[-2000:]}")
    if r.returncode != 0:
        return
    s = json.load(open(os.path.join(out, "summary.json")))
    check(s["contact"] == "hard", "summary.json records contact hard")
    f3_aimed = ({"f3_mu03_from_global", "f3_mu03_from_k6", "f3_robust_k6_from_global"}
                | {"f3_mu03_k4_from_global", "f3_mu03_k4_from_k4", "f3_mu03_release_from_global",
                   "f3_mu03_release_from_scan"}
                | {"f3_mu03_shake1", "f3_mu03_shake2", "f3_mu03_shake2_balls3", "f3_mu03_shake2_deep_balls3"})
    # 16 + the seven aimed formulation-3 designs (the spread objective polished once) + formulation 2 with the PI
    # motor and with PI + 1 Hz + the 3 shakes + the deep excursion
    n_expected = 29
    check(len(s["table"]) == n_expected and f3_aimed <= set(s["table"])
          and all(row["ideal"]["ok"] == 8 and row["s9002"]["ok"] == 8 for row in s["table"].values()),
          f"{len(s['table'])} designs validated on seeds 9001 and 9002, every run ok")
    check(all(("mu0.03_s9002" in row) == (n in f3_aimed or n in ("report_2003", "f3_robust"))
              for n, row in s["table"].items()),
          "the formulation-3 designs and the 2003 profile also at mu 0.03 on seed 9002")
    check(all(f"{nb}_{n}" in s["balls"] for nb in range(2, 7) for n in ("report_2003", "reoptimised", "f1_design"))
          and all(int(k.split("_")[0]) in range(2, 7) for k in s["balls"]),
          "formulation 4: 2..6 balls, re-optimised, f1 design and 2003 each")
    check(len(s["f2"]["steps"]) == 4 and s["f2"]["ref"]["runs"] == 5 and
          {r["start"] for r in s["f2"]["steps"]} == {"front6", "front8", "front11", "sweep19_scaled8"},
          "formulation 2: one startup-time minimisation per start recorded")
    check(len(s["f2_pi"]["steps"]) == 3 and s["f2_pi"]["ref"]["runs"] == 5 and
          {r["start"] for r in s["f2_pi"]["steps"]} == {"pi_ideal_f2", "pi_front8", "pi_front11"} and
          "kind: pi" in study.read(os.path.join(out, "f2_pi_front8", "config.yaml")) and
          "kind: pi" in study.read(os.path.join(out, "f2_ref2003_pi", "config.yaml")) and
          "kind: pi" in study.read(os.path.join(out, "best", "f2pi_min_T.yaml")),
          "formulation 2 with the PI motor: three starts, the PI motor in every optimised config and in its design")
    quantised = "kind: pi\n  quantize_setpoint_1hz: true"
    # the polishes from 3b's and 3's designs run when those found a feasible design (at this scale they may not: then
    # the design is the 2003 profile, which has no design variables to start from); the front's 8 s design always
    q_starts = ({"q_global", "q_front8"} | ({"q_pi_f2"} if any(r["feasible"] for r in s["f2_pi"]["steps"]) else set())
                | ({"q_ideal_f2"} if any(r["feasible"] for r in s["f2"]["steps"]) else set()))
    check(s["f2_pi1hz"]["ref"]["runs"] == 5 and {r["start"] for r in s["f2_pi1hz"]["steps"]} == q_starts and
          all(quantised in study.read(os.path.join(out, d, "config.yaml"))
              for d in ["f2q_global", "f2_ref2003_pi1hz", "f2_ref2003_pi1hz_global"] + [f"f2_{n}" for n in q_starts]) and
          "algorithm: direct_l" in study.read(os.path.join(out, "f2q_global", "config.yaml")) and
          quantised in study.read(os.path.join(out, "best", "f2q_min_T.yaml")),
          f"formulation 2 with PI + 1 Hz: a global phase and the polishes {sorted(q_starts)}, the drive in every optimised "
          "config and in its design")
    for n, key in (("f2pi_min_T", "pi"), ("f2q_min_T", "pi_1hz")):
        row = s["table"][n]
        check(all(row[k]["ok"] == 8 for k in (key, key + "_s9002")) and
              all(row[f"paired_{k}{x}"]["n"] == 8 for k in (key, key + "_s9002") for x in ("", "_irx")) and
              s["table"]["report_2003"][key + "_s9002"]["ok"] == 8,
              f"{n}: validated under its drive ({key}) on seeds 9001 and 9002, paired against 2003, both definitions")
    sh = s["shake"]
    rows = {(r["design"], r["balls"], r["seed"]) for r in sh["rows"]}
    chain = [sh["start"], "f3_mu03_shake1", "f3_mu03_shake2", "f3_mu03_shake2_balls3", "f3_mu03_shake2_deep_balls3"]
    check(sh["balls"] == 3 and sh["start"] in ("f3_mu03_k4_from_global", "f3_mu03_k4_from_k4") and
          rows == {(n, 2, seed) for n in chain for seed in (9001, 9002)}
          | {(n, 3, seed) for n in ("f3_mu03_shake2", "f3_mu03_shake2_balls3", "f3_mu03_shake2_deep_balls3")
             for seed in (9001, 9002)}
          and all(r["x_better"] > 0 and r["paired"]["n"] == 8 for r in sh["rows"]),
          f"stage 4c: its start and four designs at mu 0.03 on both seeds, the last two also with 3 balls "
          f"({len(rows)} rows)")
    # the deep scan: the polished design and one deepened profile per bottom speed, each on the polish's 10 LHS starts
    # with 3 balls at mu 0.03; the kept one (in best/, with 3 balls) is one of them
    scan = sorted(x for x in os.listdir(os.path.join(out, "validation")) if x.startswith("deep_balls3_"))
    want = sorted(["deep_balls3_start"] + [f"deep_balls3_{b:g}Hz" for b in study.DEEP_BOTTOMS_HZ])
    scan_cfg = study.read(os.path.join(out, "validation", "deep_balls3_22.5Hz", "config.yaml")) if scan == want else ""
    kept = study.read(os.path.join(out, "best", "f3_mu03_shake2_deep_balls3.yaml"))
    check(scan == want and "# runs 10 seed 21 --mu 0.03 design lhs" in scan_cfg
          and len(re.findall(r"^    - \{mass_kg", scan_cfg, re.M)) == 3
          and len(re.findall(r"^    - \{mass_kg", kept, re.M)) == 3
          and re.search(r"end_frequency_hz: 22\.5,", scan_cfg)
          and any(study.profile_yaml(s["table"]["f3_mu03_shake2_deep_balls3"]["profile"]) in
                  study.read(os.path.join(out, "validation", x, "config.yaml")) for x in scan),
          f"stage 4c's deep scan: {scan}; the kept design is one of them, with 3 balls")
    s1, s2 = (study.read(os.path.join(out, n, "config.yaml")) for n in ("f3_mu03_shake1", "f3_mu03_shake2"))
    s3, b3 = (study.read(p) for p in (os.path.join(out, "f3_mu03_shake2_balls3", "config.yaml"),
                                      os.path.join(out, "best", "f3_mu03_shake2_balls3.yaml")))
    check(len(study.bounds_of(s1)) == 11 and len(study.bounds_of(s2)) == 16 and "friction_mu: 0.03" in s2
          and all(len(re.findall(r"^    - \{mass_kg", x, re.M)) == 3 for x in (s3, b3))
          and not re.search(r"mass_kg", s2), "stage 4c: one and two shakes, the last polish and its best/ config with 3 balls")
    check("## Shakes at mu 0.03" in study.read(os.path.join(out, "summary.md")), "summary.md has the shake table")
    # the designs shipped from outside the runner (8.13), as shipped, on both seeds, beside the 2003 profile with
    # their balls (paired) and the report's two balls at their friction
    sp = s["shipped"]
    want_rows = {(n, seed) for n, _, _ in study.SHIPPED for seed in (9001, 9002)}
    check({(r["design"], r["seed"]) for r in sp} == want_rows and len(sp) == 2 * len(study.SHIPPED)
          and all(r["ok"] == 8 and r["balls"] == 6 and r["paired"]["n"] == 8 and r["x_better_2balls"] > 0
                  and abs(r["x_better_2balls"] - r["ref2003_2balls"] / r["ir"]["mean"]) < 1e-12 for r in sp)
          and {r["mu"] for r in sp if r["design"] == "contact_best_19s_deep_6balls"} == {0.02}
          and "## The shipped designs made outside the runner" in study.read(os.path.join(out, "summary.md"))
          and "--mu 0.03" in study.read(os.path.join(out, "validation", "shipped_contact_best_mu03_g6", "config.yaml")),
          f"the shipped 8.13 designs validated as shipped on both seeds ({len(sp)} rows)")
    # stage 5c: the mean-goal chain from the k4_hold design (six balls, mu 0.02): the up-shake polish, the scan (the
    # shaken design and every (offset, bottom) that fits its dwell) on the polish's LHS starts, the deep polish; its
    # design within the bounds, in best/ and validated on both seeds beside the 2003 profile with six balls (paired)
    mg = s["mean_goal"]
    scan5c = [x for x in os.listdir(os.path.join(out, "validation")) if x.startswith("mean_goal_")]
    npoints = 1 + len(study.MEAN_GOAL_OFFSETS_S) * len(study.MEAN_GOAL_BOTTOMS_HZ)
    made_path = os.path.join(out, "best", "runner_mean_goal_6balls.yaml")
    made = study.read(made_path) if os.path.exists(made_path) else ""
    segs5c = study.segments_of(mg["profile"]) if mg else []
    ends = [0.0] + [f for f, _ in segs5c]
    # at this scale (5 starts) the chain may end with no point within every bound: then no design, nothing shipped
    none = not mg and "stage 5c has no design" in r.stdout and not os.path.exists(
        os.path.join(out, "best", "runner_mean_goal_6balls.yaml")) and "Stage 5c (the mean goal with six balls) found no" \
        in study.read(os.path.join(out, "summary.md"))
    check(none and "mean_goal_shaken" in scan5c or mg and {(r["design"], r["seed"]) for r in mg["rows"]} == {("runner_mean_goal_6balls", 9001),
                                                                     ("runner_mean_goal_6balls", 9002)}
          and all(r["ok"] == 8 and r["balls"] == 6 and r["mu"] == 0.02 and r["paired"]["n"] == 8 for r in mg["rows"])
          and len(re.findall(r"^    - \{mass_kg", made, re.M)) == 6 and active_contact_lines(made) == ["hard"]
          and sum(dt for _, dt in segs5c) <= 19 + 1e-9
          and max(study.peak_rate(f - e, dt) for (f, dt), e in zip(segs5c, ends)) <= study.MAX_RATE_HZ_S
          and "(made by the runner, stage 5c)" in study.read(os.path.join(out, "summary.md"))
          and len(re.findall(r"^    - \{mass_kg", study.read(os.path.join(out, "f1_mu02_shake_6balls", "config.yaml")),
                             re.M)) == 6
          and "mean_goal_shaken" in scan5c and npoints - 3 <= len([x for x in scan5c if "Hz_at" in x and "recheck" not in x
                                                                   and "_rep" not in x]) + 1 <= npoints
          and "# runs 5 seed 21 --mu 0.02 design lhs" in study.read(os.path.join(out, "validation", "mean_goal_shaken",
                                                                                 "config.yaml")),
          f"stage 5c: {mg.get('point') if mg else 'no design within the bounds'}, T {sum(dt for _, dt in segs5c):.3f} s, "
          f"{len(scan5c)} points run, validated on both seeds with six balls (when within the bounds)")
    # the replications (MEAN_GOAL_REPLICATIONS, the default 3; --mean-goal-stop 0 runs every one): the same chain on the
    # LHS starts of seeds 22 and 23, each its shake polish, its scan (the same points, suffixed _rep<k>) and its deep
    # polish in folders of their own
    possible = {"mean_goal_shaken"} | {f"mean_goal_deep{b:g}Hz_at{o:g}s" for o in study.MEAN_GOAL_OFFSETS_S
                                       for b in study.MEAN_GOAL_BOTTOMS_HZ}
    for k in range(2, study.MEAN_GOAL_REPLICATIONS + 1):
        names_k = {x[:-len(f"_rep{k}")] for x in scan5c if x.endswith(f"_rep{k}")}  # its scan (not its re-checks)
        shk = os.path.join(out, f"f1_mu02_shake_6balls_rep{k}", "config.yaml")
        tag = f"[mean goal, replication {k} (seed {20 + k})]"
        polished = os.path.isdir(os.path.join(out, f"f1_mu02_deep_6balls_rep{k}"))
        check(study.MEAN_GOAL_REPLICATIONS == 3 and "mean_goal_shaken" in names_k and names_k <= possible
              and npoints - 3 <= len(names_k) <= npoints and os.path.exists(shk)
              and re.search(rf"^  seed: {20 + k}\b", study.read(shk), re.M)
              and f"# runs 5 seed {20 + k} --mu 0.02 design lhs" in study.read(
                  os.path.join(out, "validation", f"mean_goal_shaken_rep{k}", "config.yaml"))
              and f"{tag} up-shake polished" in r.stdout and polished == (f"{tag} deep polish 1 from" in r.stdout),
              f"stage 5c's replication {k}: {len(names_k)} scan points on seed {20 + k}'s starts, its own shake polish"
              f"{', its own deep polish' if polished else ''}")
    check((mg and [x["seed"] for x in mg["steps"] if x["step"] == "shake polish"] == [21, 22, 23]
           and {x["replication"] for x in mg["steps"] if x["step"] == "re-check"} <= {1, 2, 3})
          or not mg and "[mean goal, replication 3 (seed 23)] up-shake polished" in r.stdout,
          "stage 5c ran the three replications (its summary records their shake polishes)")
    # its design = the best of the re-check (LHS starts of MEAN_GOAL_RECHECK_SEED) within every bound with the %MI margin
    rc = [x for x in mg["steps"] if x["step"] == "re-check"] if mg else []
    check(not mg or rc and any(x["point"] == mg["point"] and x["within"] and x["pct_mi"] <= study.MEAN_GOAL_RECHECK_MI
                               for x in rc)
          and abs(mg["in_sample"] - min(x["in_sample"] for x in rc if x["within"])) < 1e-12
          and all(f"seed {study.MEAN_GOAL_RECHECK_SEED} --mu 0.02 design lhs" in study.read(
              os.path.join(out, "validation", f"mean_goal_{x['point']}_recheck", "config.yaml")) for x in rc),
          f"stage 5c's re-check: {len(rc)} points, the design the best within the bounds and the %MI margin there")
    for fam in ("approach", "oscillate", "release"):
        md = os.path.join(out, f"stop_depth_{fam}", "stop_depth" + ("" if fam == "approach" else "_osc" if fam ==
                                                                       "oscillate" else "_release") + ".md")
        check(os.path.exists(md), f"stage 8 (stop depth, quick): {fam} family written")
    f2cfg = study.read(os.path.join(out, "f2_front8", "config.yaml"))
    check("kind: startup_time" in f2cfg and "max_mean_abs_ir:" in f2cfg and "max_startup_time_s: 19" in f2cfg,
          "formulation 2 minimises startup_time with the max_mean_abs_ir bound")
    cost = json.load(open(os.path.join(out, "stage_cost.json")))
    stages = [c["stage"] for c in cost]
    check(len(stages) == 13 and all(c["cpu_s"] >= 0 and c["wall_s"] >= 0 for c in cost) and cost[0]["cpu_s"] > 0
          and "[cost] whole study: CPU" in r.stdout, f"the cost of every stage is recorded: {stages}")
    configs = [os.path.join(d, "config.yaml") for d in
               [os.path.join(out, x) for x in os.listdir(out)] + [os.path.join(out, "validation", x) for x in
                                                                   os.listdir(os.path.join(out, "validation"))]
               if os.path.exists(os.path.join(d, "config.yaml"))]
    bad = [c for c in configs if active_contact_lines(study.read(c)) != ["hard"]]
    check(len(configs) > 60 and not bad, f"all {len(configs)} configs run carry ball_contact: hard {bad[:3]}")
    check(active_contact_lines(study.read(os.path.join(out, "best", "best_19s.yaml"))) == ["hard"],
          "best/best_19s.yaml is ready to run with contact")
    for png in ("front.png", "profiles.png", "profiles_full.png", "profiles_shake.png"):
        check(os.path.getsize(os.path.join(out, png)) > 1000 if os.path.exists(os.path.join(out, png)) else False,
              f"{png} drawn")
    r2 = subprocess.run(cmd, capture_output=True, text=True)
    computed = [l for l in r2.stdout.splitlines() if "(computed)" in l or l.startswith("[validation]")]
    check(r2.returncode == 0 and not computed and "(archive)" in r2.stdout,
          f"the rerun replays every evaluation and keeps every validation ({len(computed)} recomputed)")
    # the stop rule: with a stop value over every mean the first replication's design ends stage 5c (when it has one),
    # replayed from its archives, the other replications not run
    steps = (json.load(open(os.path.join(out, "summary.json")))["mean_goal"] or {}).get("steps", [])
    rep1 = [x for x in steps if x["step"] == "re-check" and x["replication"] == 1 and x["within"]]
    r3 = subprocess.run(base + ["--mean-goal-stop", "1000"], capture_output=True, text=True)
    mg3 = json.load(open(os.path.join(out, "summary.json")))["mean_goal"] if r3.returncode == 0 else {}
    computed = [l for l in r3.stdout.splitlines() if "(computed)" in l or l.startswith("[validation] mean_goal")]
    best1 = min(rep1, key=lambda x: x["in_sample"]) if rep1 else None
    check(r3.returncode == 0 and not computed and (
        best1 is None and "not run" not in r3.stdout and "[mean goal, replication 3 (seed 23)]" in r3.stdout
        or best1 is not None and "the other 2 replication(s) are not run" in r3.stdout and mg3["point"] == best1["point"]
        and [x["seed"] for x in mg3["steps"] if x["step"] == "shake polish"] == [21]
        and not any("_rep" in x.get("point", "") for x in mg3["steps"])),
          f"--mean-goal-stop 1000: stage 5c ends with the first replication's design "
          f"({best1['point'] if best1 else 'none within the bounds at this scale'}), replayed")


def main():
    abuopt, mode = sys.argv[1], sys.argv[2]
    with tempfile.TemporaryDirectory() as tmp:
        {"unit": unit, "end_to_end": end_to_end}[mode](abuopt, tmp)
    if failures:
        sys.exit(f"{len(failures)} check(s) failed")


if __name__ == "__main__":
    main()
