# SPDX-License-Identifier: Apache-2.0
# bench/plot_accuracy.gp: the plots of `umbra-bench accuracy`, which sets the variables below and
# loads this file once per scene. To re-plot by hand from a committed CSV, set them with -e, e.g.
#   gnuplot -e "csv='bench/results/accuracy/accuracy.csv'; scene='walnut'; scene_title='walnut'; \
#     techniques='none reference threshold cssm deep'; styles='1 2 3 4 5'; \
#     techniques_memory='threshold cssm deep'; styles_memory='3 4 5'; \
#     pareto_time='bench/results/accuracy/plots/walnut-pareto-time.dat'; \
#     pareto_memory='bench/results/accuracy/plots/walnut-pareto-memory.dat'; \
#     out_time='/tmp/t.png'; out_memory='/tmp/m.png'; c_scene=1; c_tech=2; c_total=10; \
#     c_rmse=24; c_mem=20" bench/plot_accuracy.gp
# (the column numbers follow the CSV header; the bench passes the current ones).
#
#   csv            accuracy.csv (comma-separated, one header row)
#   scene          rows of this scene are plotted
#   techniques     space-separated technique names to draw, one marker series each
#   styles         one style index per technique, so that a technique looks the same everywhere
#   techniques_memory, styles_memory   the same for the memory plot (techniques holding memory)
#   pareto_*       the Pareto fronts the bench computed, "cost,rmse,label" sorted by cost
#   out_time       PNG: RMSE against build + render time
#   out_memory     PNG: RMSE against shadow memory ("" for none: no technique holds memory)
#   techniques_texel, styles_texel, pareto_texel, c_bpt   the light-space maps, their front and
#                  the CSV's bytes_per_texel column, for
#   out_texel      PNG: RMSE against bytes per map texel ("" for none: no map in the scene)

if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {
    set terminal pngcairo size 1000,660 noenhanced font 'sans,10'
} else {
    set terminal png size 1000,660 noenhanced
}
set datafile separator ','
set datafile missing ''
set grid xtics ytics mxtics mytics lc rgb '#dddddd'
set key outside right top box opaque
set logscale xy
set format y '%g'
set format x '%g'

# Marker shape and colour per style index, the technique registry's order: none, reference,
# threshold, cssm, deep, convolution, and room for the techniques added after them.
pt_of(i) = word('6 1 5 7 9 11 13 4 8 10 12 2', i) + 0
lc_list = '#777777 #000000 #d62728 #1f77b4 #2ca02c #9467bd '. \
          '#ff7f0e #8c564b #e377c2 #17becf #bcbd22 #7f7f7f'
lc_of(i) = word(lc_list, i)
sel(t) = (strcol(c_scene) eq scene && strcol(c_tech) eq t)

set output out_time
set title sprintf("%s\nimage error against the exact reference vs. time per frame with a fresh shadow build", scene_title)
set xlabel 'build + render time (ms, device time, log scale)'
set ylabel 'RMSE against the exact reference (display values, log scale)'
plot for [i=1:words(techniques)] csv skip 1 \
        using (sel(word(techniques, i)) && column(c_rmse) > 0 ? column(c_total) : NaN):(column(c_rmse)) \
        with points pt pt_of(word(styles, i) + 0) ps 1.6 lc rgb lc_of(word(styles, i) + 0) \
        title word(techniques, i), \
     pareto_time using 1:2 with steps lw 1.5 dt 2 lc rgb '#444444' title 'Pareto front', \
     pareto_time using 1:2:3 with labels left offset 0.8,0.6 font ',7' tc rgb '#444444' notitle

if (strlen(out_memory) > 0) {
    set output out_memory
    set title sprintf("%s\nimage error against the exact reference vs. shadow memory", scene_title)
    set xlabel 'shadow structure memory (MiB, log scale)'
    plot for [i=1:words(techniques_memory)] csv skip 1 \
            using (sel(word(techniques_memory, i)) && column(c_rmse) > 0 && column(c_mem) > 0 ? column(c_mem) / 1048576.0 : NaN):(column(c_rmse)) \
            with points pt pt_of(word(styles_memory, i) + 0) ps 1.6 lc rgb lc_of(word(styles_memory, i) + 0) \
            title word(techniques_memory, i), \
         pareto_memory using 1:2 with steps lw 1.5 dt 2 lc rgb '#444444' title 'Pareto front', \
         pareto_memory using 1:2:3 with labels left offset 0.8,0.6 font ',7' tc rgb '#444444' notitle
}

if (exists("out_texel") && strlen(out_texel) > 0) {
    set output out_texel
    set title sprintf("%s\nimage error against the exact reference vs. bytes per light-space map texel", scene_title)
    set xlabel 'shadow memory per map texel (bytes, log scale)'
    plot for [i=1:words(techniques_texel)] csv skip 1 \
            using (sel(word(techniques_texel, i)) && column(c_rmse) > 0 && column(c_bpt) > 0 ? column(c_bpt) : NaN):(column(c_rmse)) \
            with points pt pt_of(word(styles_texel, i) + 0) ps 1.6 lc rgb lc_of(word(styles_texel, i) + 0) \
            title word(techniques_texel, i), \
         pareto_texel using 1:2 with steps lw 1.5 dt 2 lc rgb '#444444' title 'Pareto front', \
         pareto_texel using 1:2:3 with labels left offset 0.8,0.6 font ',7' tc rgb '#444444' notitle
}
set output
