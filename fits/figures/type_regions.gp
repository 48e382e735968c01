# What decides the spring type: where in (rho, s/H) each type can be placed under conifit's
# default limits (3 <= D1/d <= 12, 2 <= n <= 30, D2 <= 10 H, rho >= 0.05; G <= 80 GPa bounds the
# stress scale, the third quantity, and is not drawn), against the rho and solid strain that the
# published tables call for when no limit holds them. Regions (README, "Limits"):
#   telescoping:      rho <= 12/16 and s/H >= max(1 - 10 rho/3, 1 - 2.5 (1 - rho))
#   non-telescoping:  rho >= 0.05   and s/H >= 1 - 100 rho
# Points: the non-telescoping fit of each stress-strain table of ../shared/datasets with the limits
# widened (conifit fit TABLE --target spring --type non-telescoping --rho-min 0.001 --G-max 1e15
# --n-max 1e5 --D2-max-H 1e5; the muscle tables without their time column); values as measured.
# Run: gnuplot fits/figures/type_regions.gp (make figures)
set terminal pngcairo size 900,560 font ",11" noenhanced
set output "fits/figures/type_regions.png"
set title "What decides the type: the rho a table calls for against what each geometry permits"
set logscale x
set xrange [0.001:1]
set yrange [0:1]
set xlabel "diameter ratio rho = D1/D2"
set ylabel "solid strain s/H"
set key outside right top box
set grid
tele_lo(x) = (x > 0.75 || x < 0.05) ? 1/0 : (m = 1 - 10*x/3, k = 1 - 2.5*(1 - x), mx = (m > k ? m : k), (mx > 0 ? mx : 0))
nt_lo(x) = x < 0.05 ? 1/0 : ((1 - 100*x) > 0 ? 1 - 100*x : 0)
set samples 2000
set arrow from 0.05, graph 0 to 0.05, graph 1 nohead dt 2 lw 1.5 lc rgb "black"
set label "rho_min = 0.05" at 0.052, 0.04 left
$called << EOD
0.0011066 0.19241 "CR compression"
0.70328 0.11889 "CR tension"
0.0011357 0.20428 "cortex compression"
0.0084502 0.37406 "cortex shear"
0.44826 0.13300 "cortex tension"
0.0066104 0.14989 "myocardium biaxial"
0.0026745 0.74299 "myocardium shear"
0.96571 0.81207 "muscle cross-fibre"
0.0026792 0.75672 "muscle fibre"
0.0027086 0.32088 "skin (Cauchy -> nominal)"
EOD
plot '+' using 1:(nt_lo($1)):(1) with filledcurves lc rgb "#9ecae1" fs transparent solid 0.5 title "non-telescoping can be placed", \
     '+' using 1:(tele_lo($1)):(1) with filledcurves lc rgb "#fdae6b" fs transparent solid 0.6 title "telescoping can be placed (non-telescoping too)", \
     $called using 1:2 with points pt 7 ps 1.3 lc rgb "#d62728" title "called for (limits widened)", \
     $called using 1:2:3 with labels offset 0.8,0.5 left font ",9" notitle
