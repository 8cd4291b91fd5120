# SPDX-License-Identifier: Apache-2.0
# bench/plot_distributed.gp: the plot of `umbra-bench distributed` (bench/distributed.c runs it
# with `csv` and `out` set): per-rank volume bytes and bytes sent against the ranks, log-log, one
# point per rank, beside the 1/P line.
if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {
    set terminal pngcairo size 1100,440
} else {
    set terminal png size 1100,440
}
set output out
set datafile separator ','
set logscale xy 2
set grid
set xlabel 'ranks P'
set xrange [0.8:10]
set multiplot layout 1,2
set ylabel 'bytes'
set title 'volume bytes per rank'
stats csv using 'volume_bytes' every ::0::0 nooutput
v1 = STATS_max
plot csv using 'ranks':'volume_bytes' with points pt 7 title 'each rank', \
     v1/x with lines dt 2 title 'whole / P'
set title 'bytes sent per rank (Open MPI pml monitoring)'
set key top left
plot csv using 'ranks':(column('mpi_bytes_sent') > 0 ? column('mpi_bytes_sent') : 1/0) with points pt 7 title 'each rank', \
     '' using 'ranks':(column('payload_bytes') > 0 ? column('payload_bytes') : 1/0) with points pt 6 title 'payload handed to MPI'
unset multiplot
