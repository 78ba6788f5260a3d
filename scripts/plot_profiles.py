#!/usr/bin/env python3
"""Speed against time of the startup profiles of ready-to-run configs, the 2003 profile beside them (issue 10,
docs/studies/startup-profile.md 8.13: the shipped designs of configs/studies/best/, which the runner did not make).

    scripts/plot_profiles.py configs/studies/best/best_19s.yaml configs/designs/mu03_6balls_17s.yaml \
        --out results/profiles [--title TEXT] [--zoom 18:32]

Reads each config's `profile` section (start_frequency_hz and the segments' end_frequency_hz / duration_s; the
inclined-sine ramps of docs/model.md), samples f(t) and writes OUT/profiles.dat (one gnuplot index per profile,
the 2003 profile first), OUT/profiles.gp and, with gnuplot installed, OUT/profiles.png: the whole startup above,
the slow part (--zoom, Hz) below. Prints per profile its duration, peak |f'| [Hz/s] and lowest speed after its
first 28 Hz. Needs python3 only.
"""
import argparse
import math
import os
import re
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from final_states_in_set import profile_frequency  # noqa: E402

REPORT_2003 = (0.0, [(25.0, 1.0), (29.5, 10.0), (100.0, 8.0)])
SEGMENT = re.compile(r"^\s*-\s*\{\s*end_frequency_hz:\s*([-+\d.eE]+)\s*,\s*duration_s:\s*([-+\d.eE]+)\s*\}")


def read_profile(text, where="config"):
    """(start_frequency_hz, [(end_frequency_hz, duration_s)]) of a config's `profile` section (flow-style segments,
    as every shipped config writes them). ValueError naming the config when it has none."""
    m = re.search(r"^profile:\s*\n((?:[ #].*\n|\s*\n)*)", text, re.M)
    if not m:
        raise ValueError(f"{where}: no profile section")
    body = m.group(1)
    f0 = re.search(r"^\s*start_frequency_hz:\s*([-+\d.eE]+)", body, re.M)
    segs = [(float(a), float(b)) for a, b in (SEGMENT.match(l).groups() for l in body.split("\n") if SEGMENT.match(l))]
    if not segs:
        raise ValueError(f"{where}: profile.segments has no `- {{end_frequency_hz: F, duration_s: T}}` entries")
    if any(dt <= 0 for _, dt in segs):
        raise ValueError(f"{where}: profile.segments: every duration_s must be > 0")
    return (float(f0.group(1)) if f0 else 0.0, segs)


def peak_rate(f0, segs):
    """The largest |f'| [Hz/s] of inclined-sine segments: 2 |H| / dt per segment (f' = H / dt (1 - cos phi))."""
    ends = [f0] + [f for f, _ in segs]
    return max(2 * abs(segs[i][0] - ends[i]) / segs[i][1] for i in range(len(segs)))


def samples(f0, segs, n=4000):
    total = sum(dt for _, dt in segs)
    return [(total * k / n, profile_frequency(segs, total * k / n, f0)) for k in range(n + 1)]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("configs", nargs="+")
    ap.add_argument("--out", required=True)
    ap.add_argument("--title", default="startup profiles against the 2003 profile")
    ap.add_argument("--zoom", default="18:32", help="speed range [Hz] of the lower panel, LO:HI")
    a = ap.parse_args()
    try:
        lo, hi = (float(v) for v in a.zoom.split(":"))
        if not lo < hi:
            raise ValueError
    except ValueError:
        sys.exit(f"--zoom {a.zoom}: must be LO:HI with LO < HI (Hz)")
    profiles = [("2003 profile", REPORT_2003)]
    for c in a.configs:
        try:
            with open(c) as f:
                profiles.append((os.path.splitext(os.path.basename(c))[0], read_profile(f.read(), c)))
        except (OSError, ValueError) as e:
            sys.exit(f"plot_profiles: {e}")
    dat = os.path.join(a.out, "profiles.dat")
    try:
        os.makedirs(a.out, exist_ok=True)
        with open(dat, "w") as f:
            for name, (f0, segs) in profiles:
                f.write(f"# {name}\n" + "".join(f"{t:.5f} {v:.5f}\n" for t, v in samples(f0, segs)) + "\n\n")
    except OSError as e:
        sys.exit(f"plot_profiles: cannot write {dat}: {e}")
    for name, (f0, segs) in profiles:
        pts = samples(f0, segs)
        first = next((i for i, (_, v) in enumerate(pts) if v >= 28.0), None)
        low = min(v for _, v in pts[first:] if v < 60) if first is not None else float("nan")
        print(f"{name}: {sum(dt for _, dt in segs):.2f} s, peak |f'| {peak_rate(f0, segs):.1f} Hz/s "
              f"({2 * math.pi * peak_rate(f0, segs):.1f} rad/s^2), lowest speed after reaching 28 Hz {low:.2f} Hz")
    tmax = max(sum(dt for _, dt in segs) for _, (_, segs) in profiles)
    plots = ", ".join(f"'profiles.dat' index {i} with lines lw {3 if i == 0 else 1.5} dt {2 if i == 0 else 1} "
                      f"title '{name}'" for i, (name, _) in enumerate(profiles))
    gp_text = ("set terminal pngcairo size 1100,900 noenhanced\nset output 'profiles.png'\nset grid\n"
               "set multiplot layout 2,1\n"
               f"set title '{a.title}'\nset xlabel 'time [s]'; set ylabel 'speed [Hz]'; set xrange [0:{tmax:.2f}]\n"
               f"set key top left\nplot {plots}\n"
               f"set title 'the slow part ({lo:g} - {hi:g} Hz)'\nset yrange [{lo:g}:{hi:g}]\nset key bottom right\n"
               f"plot {plots}\nunset multiplot\n")
    gp = os.path.join(a.out, "profiles.gp")
    try:
        with open(gp, "w") as f:
            f.write(gp_text)
    except OSError as e:
        sys.exit(f"plot_profiles: cannot write {gp}: {e}")
    exe = shutil.which("gnuplot")
    if exe:
        r = subprocess.run([exe, "profiles.gp"], cwd=a.out, capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit(f"plot_profiles: gnuplot failed on {gp}: {r.stderr.strip()}")
        print(f"wrote {os.path.join(a.out, 'profiles.png')}, {dat}, {gp}")
    else:
        print(f"wrote {dat}, {gp} (no gnuplot: no PNG)")


if __name__ == "__main__":
    main()
