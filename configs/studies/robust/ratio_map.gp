# Issue 30: the ratio map. The mean |I_r| of the 2003 profile over that of a design, in bins of (friction mu,
# imbalance mass / 5.6e-4 kg), from two `abuopt montecarlo --out` folders of the SAME draws (same seed, runs
# and envelope: common random numbers, paired by run index). Values > 1: the design is better there.
#   gnuplot -e "base='R/2003/runs.csv'; design='R/robust_2balls/runs.csv'; out='R/map_2balls'; title='robust_2balls'" \
#           configs/studies/robust/ratio_map.gp
# writes OUT.png, OUT.pdf and OUT.dat (mu centre, imbalance centre, ratio, 2003 mean, design mean, runs per bin).
if (!exists("nb")) nb = 5
if (!exists("title")) title = "design"
awk = sprintf("awk -F, -v nb=%d 'FNR==1{for(i=1;i<=NF;i++)c[$i]=i;f++;next} $c[\"status\"]!=\"ok\"{next} " . \
  "{m=$c[\"mu\"];im=$c[\"imbalance_mass_kg\"];if(im==\"\")im=5.6e-4;im/=5.6e-4;" . \
  "i=int((m-0.02)/0.02*nb);if(i>=nb)i=nb-1;j=int((im-0.5)*nb);if(j>=nb)j=nb-1;k=$c[\"index\"];v=$c[\"ir_magnitude_kgm\"]*1e7;" . \
  "if(f==1){a[k]=v;bi[k]=i;bj[k]=j}else if(k in a){sa[i,j]+=a[k];sb[i,j]+=v;n[i,j]++}} " . \
  "END{for(i=0;i<nb;i++){for(j=0;j<nb;j++){x=0.02+(i+0.5)*0.02/nb;y=0.5+(j+0.5)/nb;" . \
  "if(n[i,j]>0)printf \"%%.5f %%.4f %%.4f %%.3f %%.3f %%d\\n\",x,y,sa[i,j]/sb[i,j],sa[i,j]/n[i,j],sb[i,j]/n[i,j],n[i,j]}print \"\"}}' %s %s > %s.dat", \
  nb, base, design, out)
system(awk)
set xlabel "friction mu"
set ylabel "imbalance mass / 5.6e-4 kg"
set title sprintf("mean |I_r| of the 2003 profile / of %s (>1: design better), %d x %d bins;\nlabels: ratio (2003 mean / design mean) [1e-7 kg m]", title, nb, nb)
set cbrange [0.5:2.0]
set palette defined (0.5 "#b2182b", 1.0 "#f7f7f7", 2.0 "#2166ac")
set xrange [0.02:0.04]
set yrange [0.5:1.5]
set tics out
set cblabel "ratio"
do for [t in "png pdf"] {
  if (t eq "png") { set terminal pngcairo size 900,700 font ",11" } else { set terminal pdfcairo size 6in,4.7in }
  set output out . "." . t
  plot out . ".dat" u 1:2:3 with image notitle, \
       out . ".dat" u 1:2:(sprintf("%.2f\n(%.1f / %.1f)", $3, $4, $5)) with labels font ",9" notitle
}
