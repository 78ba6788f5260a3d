#!/usr/bin/env python3
"""Writes balls.dat (N, then CPU ms per run: rk and exact for identical balls without contact,
exact for identical balls with hard contact, equal total mass without and with contact) and
length.dat (T, rk and exact CPU ms per run) for bench/plot_scaling.gp from simulator_bench's
JSON output.
Usage: python3 bench/scaling_data.py bench.json [out_dir]"""
import json
import os
import sys

if len(sys.argv) < 2:
    sys.exit(__doc__)
cpu = {b["name"]: b["cpu_time"] for b in json.load(open(sys.argv[1]))["benchmarks"]}
out = sys.argv[2] if len(sys.argv) > 2 else "."
with open(os.path.join(out, "balls.dat"), "w") as f:
    for n in (2, 3, 4, 6, 9):
        cols = [cpu[f"BM_BallCount/balls:{n}/exact:{e}/cfg:{c}/iterations:64"]
                for e, c in ((0, 0), (1, 0), (1, 1), (1, 2), (1, 3))]
        f.write(f"{n} " + " ".join(f"{v:.4f}" for v in cols) + "\n")
    print("wrote", os.path.join(out, "balls.dat"))
with open(os.path.join(out, "length.dat"), "w") as f:
    for x in (10, 19, 30, 45, 60):
        rk = cpu[f"BM_ProfileLength/seconds:{x}/exact:0/iterations:64"]
        ex = cpu[f"BM_ProfileLength/seconds:{x}/exact:1/iterations:64"]
        f.write(f"{x} {rk:.4f} {ex:.4f}\n")
    print("wrote", os.path.join(out, "length.dat"))
