#!/usr/bin/env python3
"""Tests of scripts/switch_contact_check.py (the switch-model check of docs/studies/startup-profile.md 8.11).

    switch_contact_check_test.py ABUOPT

The config variants it runs are what the check claims (every design with hard contact, once with
each friction method, the band only where asked, and an error where a config has no method line to
set), and the script runs end to end on 4 starts per design: two summary rows per design, the
paired table has a row per design, and its run counts add up.
"""
import os
import subprocess
import sys
import tempfile

from script_check import ROOT, check, failures, load_script

sc = load_script("switch_contact_check")


def main(abuopt):
    for name, cfg, _ in sc.DESIGNS:
        with open(os.path.join(ROOT, cfg)) as f:
            text = f.read()
        for method in ("event_driven", "switch_model"):
            v = sc.variant(text, method, "")
            lines = [l.strip() for l in v.splitlines()]
            check(lines.count("method: " + method) == 1, f"{name}: one 'method: {method}' line")
            check(lines.count("ball_contact: hard") == 1, f"{name}: hard contact, once")
            check(not any(l.startswith("switch_band:") for l in lines), f"{name}: no band unless asked")
        v = sc.variant(text, "switch_model", "2e-5")
        check([l.strip() for l in v.splitlines()].count("switch_band: 2e-5") == 1, f"{name}: the band when asked")
    try:
        sc.variant("abu:\n  friction_mu: 0.02\n", "switch_model", "")
        check(False, "a config without a method line is an error")
    except ValueError:
        check(True, "a config without a method line is an error")
    with tempfile.TemporaryDirectory() as tmp:
        r = subprocess.run([sys.executable, os.path.join(ROOT, "scripts", "switch_contact_check.py"), "--abuopt", abuopt,
                            "--out", tmp, "--runs", "4", "--seed", "3"], capture_output=True, text=True, cwd=ROOT)
        check(r.returncode == 0, "the check runs on 4 starts per design: " + r.stderr[-300:])
        rows = [l for l in r.stdout.splitlines() if l.startswith("| ") and not l.startswith("| design")]
        n = len(sc.DESIGNS)
        check(len(rows) == 3 * n, f"{2 * n} summary rows and {n} paired rows (got {len(rows)})")
        for l in rows[2 * n:]:
            cells = [c.strip() for c in l.strip("|").split("|")]
            agree, both = cells[3].split(" of ")
            check(0 <= int(agree) <= int(both) <= 4, f"paired row {cells[0]}: {cells[3]} runs agree, of at most 4")
    print("%d failure(s)" % len(failures))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
