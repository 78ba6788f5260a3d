#!/usr/bin/env python3
"""Writes balls.dat and length.dat (x, rk CPU ms per run, exact CPU ms per run) for
bench/plot_scaling.gp from simulator_bench's JSON output.
Usage: python3 bench/scaling_data.py bench.json [out_dir]"""
import json
import os
import sys

if len(sys.argv) < 2:
    sys.exit(__doc__)
cpu = {b["name"]: b["cpu_time"] for b in json.load(open(sys.argv[1]))["benchmarks"]}
out = sys.argv[2] if len(sys.argv) > 2 else "."
for name, key, xs in (("balls.dat", "BM_BallCount/balls:", (2, 3, 4, 6, 9)),
                      ("length.dat", "BM_ProfileLength/seconds:", (10, 19, 30, 45, 60))):
    with open(os.path.join(out, name), "w") as f:
        for x in xs:
            rk = cpu[f"{key}{x}/exact:0/iterations:64"]
            ex = cpu[f"{key}{x}/exact:1/iterations:64"]
            f.write(f"{x} {rk:.4f} {ex:.4f}\n")
        print("wrote", os.path.join(out, name))
