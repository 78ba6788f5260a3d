# 95 % interval half-width of mean |I_r| (in % of the mean) against the run count, per sampling
# scheme, over the issue-30 envelope (start angles + 4 parameters). Data: sampling_study's CSV
# split into <design>_<scheme>.dat files (two columns: runs, half-width %); docs/montecarlo.md
# "Sampling the envelope" says how. Usage (from the folder holding them):
#   gnuplot plot_sampling.gp                      -> sampling.png
#   gnuplot -e "term='dumb'" plot_sampling.gp     (text, as in docs/montecarlo.md)
if (!exists("term")) term = 'pngcairo'
if (term eq 'dumb') { set terminal dumb size 110,30 } else { set terminal pngcairo size 1200,560; set output 'sampling.png' }
set multiplot layout 1,2
set logscale xy
set grid
set key top right
set xlabel 'runs'
set ylabel '95 % half-width of mean |I_r| [% of mean]'
set xrange [48:5500]
set yrange [0.7:15]
do for [d in "p2003 robust"] {
  set title (d eq "p2003" ? "2003 profile (2 balls)" : "contact\\_best\\_robust.yaml (2 balls)")
  plot d.'_random.dat' using 1:2 with linespoints pt 7 title 'random', \
       d.'_sobol.dat' using 1:2 with linespoints pt 5 title 'scrambled Sobol (16 repl.)', \
       d.'_lhs.dat' using 1:2 with linespoints pt 9 title 'LHS (16 repl.)', \
       d.'_strat.dat' using 1:2 with linespoints pt 11 title 'stratified (16 cells)', \
       1.0 with lines dt 2 lc rgb 'black' title '+-1 %'
}
unset multiplot
