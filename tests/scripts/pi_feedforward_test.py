#!/usr/bin/env python3
"""scripts/pi_feedforward.py (docs/pi_feedforward.md): the inclined-sine profile at closed-form points, the steady
state of the inverted loop (setpoint = speed, delta = T_b / (J w^2)), the whole-Hz error feedback (its running error
stays within half a hertz), and the point of it all through abuopt: under `motor: kind: pi` the feed-forward
setpoint of a profile with a fast 5 Hz dip makes the drive's real speed follow the profile within 0.05 Hz, where the
profile itself as setpoint is off by more than 1 Hz over the dip. The --whole-hz output with the input's sections,
drive parameters and --header. Bad input (refused, nothing written): a quantised or PI drive, a start above 0 Hz,
--knot 0, a dip too fast for the loop (a setpoint below 0 Hz)."""
import csv
import math
import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from script_check import ROOT, check, failures, load_script  # noqa: E402

SCRIPT = os.path.join(ROOT, "scripts", "pi_feedforward.py")
# Two report balls, no contact (fast), a run-up, a dwell, a 5 Hz dip and back at 50 Hz/s (0.2 s each way), a dwell.
SEGMENTS = [(25.0, 2.0), (25.0, 1.0), (20.0, 0.2), (25.0, 0.2), (25.0, 1.0)]
CONFIG = """abu:
  friction_mu: 0.02
profile:
  start_frequency_hz: 0
  segments:
""" + "".join(f"    - {{end_frequency_hz: {f}, duration_s: {d}}}\n" for f, d in SEGMENTS) + """motor:
  kind: ideal
simulation:
  method: event_driven
"""


def speed_error(abuopt, ff, cfg_path, d, t0=0.0):
    """the largest |real f - profile f| over the run's trajectory (0.01 s samples) from t0 to the profile's end under
    the PI drive"""
    traj = os.path.join(d, os.path.basename(cfg_path) + ".csv")
    r = subprocess.run([abuopt, "simulate", cfg_path, "--beta0", "0.5,2.0", "--trajectory", traj],
                       capture_output=True, text=True)
    if r.returncode != 0:
        return float("inf"), r.stderr
    worst = 0.0
    with open(traj) as f:
        for row in csv.DictReader(f):
            t = float(row["t_s"])
            if t > sum(dt for _, dt in SEGMENTS):
                break
            if t >= t0:
                worst = max(worst, abs(float(row["frequency_hz"]) - ff.ideal_f(SEGMENTS, 0.0, t)[0]))
    return worst, ""


def refused(args, what, needle):
    r = subprocess.run([sys.executable, SCRIPT] + args, capture_output=True, text=True)
    check(r.returncode != 0 and needle in r.stderr, f"refused: {what} ({r.returncode}, {r.stderr.strip()})")


def main():
    abuopt = sys.argv[1]
    ff = load_script("pi_feedforward")
    # the inclined sine: half way through a segment the mean of its ends, f' = 2 H / dt there, flat at its ends
    f, fp = ff.ideal_f(SEGMENTS, 0.0, 1.0)
    check(abs(f - 12.5) < 1e-12 and abs(fp - 25.0) < 1e-12, f"half way up the run-up: 12.5 Hz, 25 Hz/s ({f}, {fp})")
    f, fp = ff.ideal_f(SEGMENTS, 0.0, 3.1)
    check(abs(f - 22.5) < 1e-12 and abs(fp + 50.0) < 1e-12, f"half way down the dip: 22.5 Hz, -50 Hz/s ({f}, {fp})")
    check(ff.ideal_f(SEGMENTS, 0.0, 99.0) == (25.0, 0.0), "held at its end after the profile")

    # steady state: up to 25 Hz from rest, then a long dwell: the setpoint becomes the speed (e -> 0, pole -w / (2 xi))
    sp = ff.setpoint([(25.0, 2.0), (25.0, 10.0)])
    check(len(sp) == 1200 and all(abs(d - 0.01) < 1e-12 for _, d in sp), "sampled every 0.01 s")
    check(abs(sp[-1][0] - 25.0) < 1e-6, f"after 10 s of dwell (22 time constants) the setpoint is the speed: "
          f"{sp[-1][0]:.9f} Hz")
    # during the run-up the setpoint leads the speed: e = delta' > 0 while the angle error builds up
    check(sp[99][0] > ff.ideal_f([(25.0, 2.0)], 0.0, 1.0)[0] + 1.0, f"the setpoint leads on the run-up: "
          f"{sp[99][0]:.3f} Hz at 1 s against the speed 12.5 Hz")

    # whole Hz by error feedback: integers whose running sum follows the setpoint's within half a hertz sample
    raw = [(25.3 + 0.4 * math.sin(k / 7.0), 0.01) for k in range(500)]
    q = ff.whole_hz(raw)
    run, worst = 0.0, 0.0
    for (a, _), (b, _) in zip(raw, q):
        run += a - b
        worst = max(worst, abs(run))
    check(all(b == round(b) for b, _ in q), "whole-Hz samples")
    check(worst <= 0.5 + 1e-12, f"running error of the whole-Hz samples within 0.5 Hz sample ({worst:.3f})")
    check(all(abs(a - b) < 1.0 for (a, _), (b, _) in zip(raw, q)), "each whole-Hz sample within 1 Hz of the setpoint")

    with tempfile.TemporaryDirectory() as d:
        cfg = os.path.join(d, "design.yaml")
        with open(cfg, "w") as f:
            f.write(CONFIG)
        out = os.path.join(d, "design_pi.yaml")
        r = subprocess.run([sys.executable, SCRIPT, cfg, "--out", out], capture_output=True, text=True)
        check(r.returncode == 0 and os.path.exists(out), f"writes the feed-forward config ({r.stdout.strip()} "
              f"{r.stderr.strip()})")
        if r.returncode == 0:
            text = open(out).read()
            check("kind: pi" in text and text.count("end_frequency_hz") == 440,
                  f"a PI-motor config of 4.4 s / 0.01 s = 440 segments ({text.count('end_frequency_hz')})")
            err_ff, msg = speed_error(abuopt, ff, out, d)
            check(err_ff < 0.05, f"under PI the real speed follows the design within 0.05 Hz: {err_ff:.4f} Hz {msg}")
            plain = os.path.join(d, "design_plain_pi.yaml")
            with open(plain, "w") as f:
                f.write(CONFIG.replace("kind: ideal", "kind: pi"))
            # from 3.0 s: the dip (3.0 - 3.4 s) and the dwell after it, not the run-up's lag
            err_dip, _ = speed_error(abuopt, ff, out, d, t0=3.0)
            err_plain, msg = speed_error(abuopt, ff, plain, d, t0=3.0)
            check(err_dip < 0.05 and err_plain > 1.0, f"over the dip: the feed-forward within 0.05 Hz ({err_dip:.4f}), "
                  f"the design itself as the PI drive's setpoint off by > 1 Hz ({err_plain:.3f} Hz) {msg}")
        # --whole-hz, the input's other sections and drive parameters carried over, --header first
        custom = os.path.join(d, "custom.yaml")
        with open(custom, "w") as f:
            f.write("# a design\n" + CONFIG.replace("kind: ideal", "kind: ideal\n  omega_m_rad_s: 3.0")
                    + "montecarlo:\n  design: random\n  runs: 8\n")
        head = os.path.join(d, "head.txt")
        with open(head, "w") as f:
            f.write("# HEADER\n")
        outq = os.path.join(d, "custom_q.yaml")
        r = subprocess.run([sys.executable, SCRIPT, custom, "--out", outq, "--whole-hz", "--header", head],
                           capture_output=True, text=True)
        text = open(outq).read() if r.returncode == 0 else ""
        check(text.startswith("# HEADER\nabu:\n  friction_mu: 0.02\nprofile:") and "kind: pi\n  omega_m_rad_s: 3.0\n"
              "  quantize_setpoint_1hz: true\nsimulation:\n  method: event_driven\nmontecarlo:\n  design: random\n  runs: 8\n"
              in text,
              f"--whole-hz: header, abu, the setpoint, the drive with its omega_m and the 1 Hz flag, simulation and "
              f"montecarlo ({r.stderr.strip()})")
        segs_q = [float(x.split("end_frequency_hz: ")[1].split(",")[0]) for x in text.splitlines() if "end_frequency_hz" in x]
        check(len(segs_q) == 440 and all(v == round(v) for v in segs_q), "--whole-hz: 440 whole-Hz setpoints")
        r = subprocess.run([abuopt, "simulate", outq, "--beta0", "0.5,2.0"], capture_output=True, text=True)
        check(r.returncode == 0, f"abuopt runs the whole-Hz output ({r.stderr.strip()[:200]})")
        refused([out, "--out", os.path.join(d, "x.yaml")], "a PI config as input", "motor.kind = pi: must be ideal")
        with open(os.path.join(d, "s25.yaml"), "w") as f:
            f.write(CONFIG.replace("start_frequency_hz: 0", "start_frequency_hz: 25"))
        refused([os.path.join(d, "s25.yaml"), "--out", os.path.join(d, "x.yaml")], "a start from 25 Hz",
                "start_frequency_hz = 25: must be 0")
        refused([cfg, "--out", os.path.join(d, "x.yaml"), "--knot", "0"], "--knot 0", "--knot 0.0: must be in (0, 4.4] s")
        with open(os.path.join(d, "fast.yaml"), "w") as f:  # a 20 Hz dip in 0.05 s: e ~ f' / (2 xi w) far below 0 Hz
            f.write(CONFIG.replace("{end_frequency_hz: 20.0, duration_s: 0.2}", "{end_frequency_hz: 5.0, duration_s: 0.05}"))
        refused([os.path.join(d, "fast.yaml"), "--out", os.path.join(d, "x.yaml")], "a dip too fast for the loop",
                "must be in [0, 1e4] Hz")
        check(not os.path.exists(os.path.join(d, "x.yaml")), "nothing written when refused")
        bad = os.path.join(d, "quantised.yaml")
        with open(bad, "w") as f:
            f.write(CONFIG.replace("kind: ideal", "kind: ideal\n  quantize_setpoint_1hz: true"))
        r = subprocess.run([sys.executable, SCRIPT, bad, "--out", os.path.join(d, "x.yaml")], capture_output=True,
                           text=True)
        check(r.returncode != 0 and "only the plain PI drive" in r.stderr and not os.path.exists(os.path.join(d, "x.yaml")),
              f"a quantised drive is refused ({r.returncode}, {r.stderr.strip()})")
    print(f"{len(failures)} failure(s)")
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
