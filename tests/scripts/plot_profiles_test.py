#!/usr/bin/env python3
"""scripts/plot_profiles.py: the profile read from a config, f(t) of the inclined-sine ramps at closed-form points,
the peak |f'| = 2 |H| / dt, the shipped designs it is meant for, and bad input (no profile section, a bad --zoom)."""
import math
import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from script_check import ROOT, check, failures, load_script  # noqa: E402

SCRIPT = os.path.join(ROOT, "scripts", "plot_profiles.py")
CONFIG = """abu:
  friction_mu: 0.02
profile:
  start_frequency_hz: 0
  segments:
    - {end_frequency_hz: 24.0, duration_s: 1.2}     # 2 x 24 / 1.2 = 40 Hz/s at its middle
    - {end_frequency_hz: 28.9, duration_s: 4.0}
    - {end_frequency_hz: 22.5, duration_s: 0.32}    # 2 x 6.4 / 0.32 = 40 Hz/s
    - {end_frequency_hz: 28.9, duration_s: 0.32}
    - {end_frequency_hz: 100, duration_s: 6.0}
motor:
  kind: ideal
"""


def main():
    pp = load_script("plot_profiles")
    f0, segs = pp.read_profile(CONFIG)
    check(f0 == 0.0 and segs == [(24.0, 1.2), (28.9, 4.0), (22.5, 0.32), (28.9, 0.32), (100.0, 6.0)],
          f"the profile section read as written: {segs}")
    check(abs(pp.peak_rate(f0, segs) - 40.0) < 1e-12, f"peak |f'| = max 2 |H| / dt = 40 Hz/s (first ramp and excursion; "
          f"{pp.peak_rate(f0, segs):.4f})")
    # inclined sine: half way through a segment f is the mean of its ends; at its end, its end frequency
    pts = pp.samples(f0, segs, n=1184)  # every 0.01 s
    at = {round(t, 6): v for t, v in pts}
    check(len(pts) == 1185 and abs(pts[-1][0] - 11.84) < 1e-12 and abs(at[0.6] - 12.0) < 1e-9
          and abs(at[5.2] - 28.9) < 1e-9 and abs(at[5.36] - (28.9 + 22.5) / 2) < 1e-9 and abs(at[5.52] - 22.5) < 1e-9,
          f"f(t) at the middles and ends of segments ({at[0.6]:.6f}, {at[5.2]:.6f}, {at[5.36]:.6f}, {at[5.52]:.6f})")
    with tempfile.TemporaryDirectory() as tmp:
        cfg = os.path.join(tmp, "design.yaml")
        with open(cfg, "w") as f:
            f.write(CONFIG)
        best = os.path.join(ROOT, "configs", "designs", "mu03_6balls_17s.yaml")
        r = subprocess.run([sys.executable, SCRIPT, cfg, best, "--out", os.path.join(tmp, "out")],
                           capture_output=True, text=True)
        dat = os.path.join(tmp, "out", "profiles.dat")
        blocks = open(dat).read().strip().split("\n\n\n") if os.path.exists(dat) else []
        check(r.returncode == 0 and len(blocks) == 3 and blocks[0].startswith("# 2003 profile")
              and "design: 11.84 s, peak |f'| 40.0 Hz/s" in r.stdout
              and "lowest speed after reaching 28 Hz 22.50 Hz" in r.stdout
              and "mu03_6balls_17s: 17.25 s, peak |f'| 49.5 Hz/s (311.0 rad/s^2)" in r.stdout,
              f"two configs and the 2003 profile written and summarised (status {r.returncode}) {r.stderr[-300:]}")
        bad = os.path.join(tmp, "bad.yaml")
        with open(bad, "w") as f:
            f.write("abu:\n  friction_mu: 0.02\n")
        r = subprocess.run([sys.executable, SCRIPT, bad, "--out", tmp], capture_output=True, text=True)
        check(r.returncode != 0 and "bad.yaml: no profile section" in r.stderr, f"no profile: refused ({r.stderr.strip()})")
        r = subprocess.run([sys.executable, SCRIPT, cfg, "--out", tmp, "--zoom", "30:20"], capture_output=True, text=True)
        check(r.returncode != 0 and "--zoom 30:20" in r.stderr, f"a bad --zoom: refused ({r.stderr.strip()})")
    if failures:
        sys.exit(f"{len(failures)} check(s) failed")


if __name__ == "__main__":
    main()
