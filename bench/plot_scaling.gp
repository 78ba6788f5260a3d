# Runs per second (1 / CPU time per run) against ball count and profile length, both stuck
# integrators. Data: two columns extracted from simulator_bench's JSON output, see
# docs/performance.md "Re-measuring". Usage (from the folder holding balls.dat, length.dat):
#   gnuplot plot_scaling.gp            -> scaling.png
#   gnuplot -e "term='dumb'" plot_scaling.gp   (text, as in docs/performance.md)
if (!exists("term")) term = 'pngcairo'
if (term eq 'dumb') { set terminal dumb size 100,28 } else { set terminal pngcairo size 1100,560; set output 'scaling.png' }
set multiplot layout 1,2
set logscale y
set grid
set key below
set ylabel 'runs per second (1 / CPU per run)'
set xlabel 'number of balls (final profile)'
set title 'cost against ball count'
plot 'balls.dat' using 1:(1000/$3) with linespoints title 'exact, identical balls, no contact', \
     'balls.dat' using 1:(1000/$2) with linespoints title 'rk, identical balls, no contact', \
     'balls.dat' using 1:(1000/$4) with linespoints title 'exact, identical balls, hard contact', \
     'balls.dat' using 1:(1000/$5) with linespoints title 'exact, equal total mass, no contact', \
     'balls.dat' using 1:(1000/$6) with linespoints title 'exact, equal total mass, hard contact'
set xlabel 'profile length [s] (final profile scaled, end time 2x)'
set title 'cost against profile length'
plot 'length.dat' using 1:(1000/$3) with linespoints title 'exact', \
     'length.dat' using 1:(1000/$2) with linespoints title 'rk'
unset multiplot
