# The three regions of the tailed spring (law family conical-tail, src/model/law.md): a cone
# (D1 10, D2 30 mm, n 4, d 1 mm, G 80 GPa, free length 30 mm) alone, and the same cone in series
# with one cylindrical coil of diameter D1 in a further 20 mm (n_tail 1, H_tail 20, H 50).
# The curves are conifit's own: make figures writes them with `conifit curve` into build/.
# Run: make figures (or gnuplot fits/figures/three_regions.gp after the two curve commands there)
set terminal pngcairo size 900,560 font ",11" noenhanced
set output "fits/figures/three_regions.png"
set datafile separator ","
set title "Linear, nonlinear, linear again: a conical spring with a cylindrical tail"
set xlabel "compression u [mm]"
set ylabel "force F [N]"
set key left top box
set grid
set xrange [0:50]
set yrange [0:200]
# region boundaries of the tailed spring (conifit info): u_T, u_C (the cone closes), solid
uT = 11.00925926
uC = 36.25
us = 48
set arrow from uT, graph 0 to uT, graph 1 nohead dt 2 lc rgb "grey40"
set arrow from uC, graph 0 to uC, graph 1 nohead dt 2 lc rgb "grey40"
set arrow from us, graph 0 to us, graph 1 nohead dt 2 lc rgb "grey40"
set label "1: linear" at 1, 120
set label "2: the cone's coils close" at uT + 2, 120
set label "3: linear,\nthe tail alone" at uC + 1, 60
plot "build/three_regions_tail.csv" every ::1 using 1:2 with lines lw 2.5 lc rgb "#1f5fa8" title "cone + tail (conical-tail)", \
     "build/three_regions_cone.csv" every ::1 using 1:2 with lines lw 2 dt 4 lc rgb "#c0392b" title "the cone alone (conical): solid at 29 mm"
