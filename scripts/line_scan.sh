#!/usr/bin/env bash
# Line scan of the startup-profile statistics (docs/sao.md, "Smooth statistics"): 200 designs on
# the segment from the report's final profile (the x0 of configs/optimize/cobyla.yaml) to the best
# design COBYLA finds from it (rounded), 128 Monte Carlo runs each (common random numbers), exact
# against smoothed statistics. Writes OUT/line_scan.csv, OUT/summary.txt and OUT/line_scan.png.
#   scripts/line_scan.sh [OUT=results/line_scan] [BUILD=build]     (about 2-5 min on 2 cores)
set -euo pipefail
out=${1:-results/line_scan}
build=${2:-build}
mkdir -p "$out"
"$build/bench/line_scan" configs/optimize/cobyla.yaml 25,1,29.5,10,8 27.5,1.17,29.35,10.97,7.67 200 \
  "$out/line_scan.csv" | tee "$out/summary.txt"
gnuplot <<GP
set terminal pngcairo size 1000,700 font ",10"
set output "$out/line_scan.png"
set datafile separator ","
set multiplot layout 2,1
set key top right
set xlabel "t (0: report's final profile, 1: COBYLA's best)"
set ylabel "%MI [%]"
plot "$out/line_scan.csv" using 1:2 every ::1 with steps lw 1.5 title "%MI (count, exact)", \
     "" using 1:3 every ::1 with lines lw 2 title "%MI smoothed (Gaussian kernel, Silverman h)"
set ylabel "|I_r| [1e-7 kg m]"
plot "$out/line_scan.csv" using 1:4 every ::1 with lines lw 1.5 title "mean |I_r|", \
     "" using 1:5 every ::1 with lines lw 1.5 title "|I_r| quantile 0.9", \
     "" using 1:6 every ::1 with lines lw 2 title "|I_r| CVaR 0.9"
unset multiplot
GP
echo "plot: $out/line_scan.png"
