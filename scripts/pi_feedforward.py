#!/usr/bin/env python3
"""Feed-forward setpoint for the PI-controlled drive: the setpoint program that makes the drive's REAL speed follow a
profile designed with the ideal motor. Derivation: docs/pi_feedforward.md.

    python3 scripts/pi_feedforward.py configs/studies/best/contact_best_19s_deep_6balls.yaml \
        --out configs/studies/best/contact_best_19s_deep_6balls_pi.yaml [--knot 0.01]

The PI loop (docs/model.md section 7), with e = Omega_ref - Omega and delta' = e:
    Omega' = 2 xi w e + w^2 delta - (T_b/J) sat(Omega/0.1)          (+ the balls' torque, ~1e-3 of it: neglected)
For a wanted real speed Omega_d(t) = 2 pi f(t) (the ideal design):
    2 xi w delta' + w^2 delta = Omega_d' + (T_b/J) sat(Omega_d/0.1),  delta(0) = 0
a stable first-order ODE (pole -w/(2 xi)), integrated by RK4; the setpoint is Omega_ref = Omega_d + delta'. It is
sampled every --knot s and written as inclined-sine segments between the samples (each flat at its ends: the drive's
loop, bandwidth 0.35 Hz, smooths the small staircase). The output is the input's sections (abu, simulation,
montecarlo, ...) with the new profile and a `kind: pi` motor of the input's drive parameters; --header FILE puts
FILE's text (the comment lines of a shipped config's header) first, so a shipped config regenerates byte for byte:

    python3 scripts/pi_feedforward.py configs/studies/best/contact_best_19s_deep_6balls.yaml --out X.yaml \
        --header <(grep '^#' configs/studies/best/contact_best_19s_deep_6balls_pi.yaml)

Refused: an input that is not an ideal-motor design starting from rest, a setpoint outside [0, 1e4] Hz (a design
too fast for the loop), a --knot outside (0, T].
"""
import argparse
import math
import re
import sys

import yaml


def ideal_f(segs, f_start, t):
    """frequency and its derivative of the inclined-sine profile at time t (held after the end)"""
    f0 = f_start
    t0 = 0.0
    for f1, dt in segs:
        if t <= t0 + dt:
            h = f1 - f0
            x = (t - t0) / dt
            return f0 + h * x - h / (2 * math.pi) * math.sin(2 * math.pi * x), h / dt * (1 - math.cos(2 * math.pi * x))
        f0 = f1
        t0 += dt
    return f0, 0.0


def setpoint(segs, f_start=0.0, knot=0.01, substeps=100, omega_m=0.7 * math.pi, xi=0.5, tb=5e-4, j=30e-6):
    total = sum(d for _, d in segs)
    n = int(round(total / knot))
    h = total / n
    dt = h / substeps

    def ddelta(t, delta):
        f, fp = ideal_f(segs, f_start, t)
        wd = 2 * math.pi * f
        wdp = 2 * math.pi * fp
        return (wdp + tb / j * max(-1.0, min(1.0, wd / 0.1)) - omega_m ** 2 * delta) / (2 * xi * omega_m)

    t = 0.0
    delta = 0.0
    out = []
    for _ in range(n):
        for _ in range(substeps):
            k1 = ddelta(t, delta)
            k2 = ddelta(t + dt / 2, delta + dt / 2 * k1)
            k3 = ddelta(t + dt / 2, delta + dt / 2 * k2)
            k4 = ddelta(t + dt, delta + dt * k3)
            delta += dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
            t += dt
        f, _ = ideal_f(segs, f_start, t)
        out.append((f + ddelta(t, delta) / (2 * math.pi), h))
    return out


def whole_hz(sp):
    """the drive's 1 Hz setpoints: whole-Hz samples chosen by first-order error feedback (sigma-delta), so that their
    running sum follows the setpoint's: the loop (0.35 Hz) averages the +-1 Hz dither; plain rounding leaves up to
    0.5 Hz offsets in the dwells (docs/pi_feedforward.md)"""
    err = 0.0
    out = []
    for f, d in sp:
        q = round(f + err)
        err += f - q
        out.append((float(q), d))
    return out


def top_level_sections(src):
    """{name: text} of a config's top-level sections, each from its `name:` line to the next one (comments and blank
    lines before the first section under ''), in the file's order"""
    out, name = {}, ''
    for line in src.splitlines(keepends=True):
        m = re.match(r'([A-Za-z_][A-Za-z0-9_]*):', line)
        if m:
            name = m.group(1)
        out[name] = out.get(name, '') + line
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('config', help='a design config made for the ideal motor (profile.segments: end_frequency_hz, duration_s)')
    ap.add_argument('--out', required=True)
    ap.add_argument('--knot', type=float, default=0.01, help='setpoint sample interval in s')
    ap.add_argument('--whole-hz', action='store_true', help='whole-Hz setpoints for quantize_setpoint_1hz (error feedback)')
    ap.add_argument('--header', default='', help='a file whose text (comment lines) heads the output')
    a = ap.parse_args()
    cfg = yaml.safe_load(open(a.config)) or {}
    prof = cfg.get('profile') or {}
    if not prof.get('segments'):
        sys.exit(f'{a.config}: profile.segments: missing or empty (a design config with an inclined-sine profile)')
    segs = [(float(s['end_frequency_hz']), float(s['duration_s'])) for s in prof['segments']]
    bad = [i for i, (_, d) in enumerate(segs) if not d > 0]
    if bad:
        sys.exit(f'{a.config}: profile.segments[{bad[0]}].duration_s = {segs[bad[0]][1]}: must be > 0')
    if float(prof.get('start_frequency_hz', 0)) != 0.0:
        sys.exit(f"{a.config}: profile.start_frequency_hz = {prof['start_frequency_hz']}: must be 0 (the PI drive "
                 "starts the disc at rest; the inversion assumes it)")
    total = sum(d for _, d in segs)
    if not 0 < a.knot <= total:
        sys.exit(f'--knot {a.knot}: must be in (0, {total:g}] s (the profile\'s duration)')
    m = cfg.get('motor', {}) or {}
    if m.get('kind', 'ideal') != 'ideal':
        sys.exit(f"{a.config}: motor.kind = {m.get('kind')}: must be ideal (the design whose speed the drive is to "
                 "follow; a PI config is already a setpoint)")
    if m.get('setpoint_mismatch') or m.get('quantize_setpoint_1hz'):
        sys.exit('only the plain PI drive (no mismatch, no quantisation) is inverted here')
    params = {k: m[k] for k in ('omega_m_rad_s', 'xi', 'bearing_torque_Nm', 'inertia_kgm2') if k in m}
    kw = dict(omega_m=float(params.get('omega_m_rad_s', 0.7 * math.pi)), xi=float(params.get('xi', 0.5)),
              tb=float(params.get('bearing_torque_Nm', 5e-4)), j=float(params.get('inertia_kgm2', 30e-6)))
    sp = setpoint(segs, float(prof.get('start_frequency_hz', 0)), a.knot, **kw)
    if a.whole_hz:
        sp = whole_hz(sp)
    lo, hi = min(f for f, _ in sp), max(f for f, _ in sp)
    if lo < 0 or hi > 1e4:
        sys.exit(f'the setpoint needs {lo:.3f} .. {hi:.3f} Hz: a profile.segments end_frequency_hz must be in '
                 '[0, 1e4] Hz (the design asks the drive for more than its loop can be steered to: make it slower)')
    text = open(a.header).read() if a.header else ''
    sections = top_level_sections(open(a.config).read())
    text += sections.get('abu', '')
    text += 'profile:                       # the feed-forward setpoint (scripts/pi_feedforward.py), every %.3f s\n' % (sp[0][1])
    text += '  start_frequency_hz: %r\n  segments:\n' % float(prof.get('start_frequency_hz', 0))
    for f, d in sp:
        text += '    - {end_frequency_hz: %.6f, duration_s: %.9f}\n' % (f, d)
    text += 'motor:\n  kind: pi\n' + ''.join(f'  {k}: {v}\n' for k, v in params.items())
    text += '  quantize_setpoint_1hz: true\n' if a.whole_hz else ''
    text += ''.join(body for name, body in sections.items() if name not in ('abu', 'profile', 'motor', ''))
    open(a.out, 'w').write(text)
    print('%d segments, T %.6f s, setpoint %.2f .. %.2f Hz' % (len(sp), sum(d for _, d in sp), min(f for f, _ in sp),
                                                              max(f for f, _ in sp)))


if __name__ == '__main__':
    main()
