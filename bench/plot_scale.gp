# SPDX-License-Identifier: Apache-2.0
# bench/plot_scale.gp: the plot of `umbra-bench scale` (bench/scale.c loads it with `csv` and
# `out` set): time and memory against voxels, log-log, from scale.csv. Columns by name, so
# the CSV may grow. Rows of skipped sizes have empty fields, which gnuplot leaves out.
if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {
    set terminal pngcairo size 1500,460
} else {
    set terminal png size 1500,460
}
set output out
set datafile separator ','
set logscale xy
set grid
set key top left
set xlabel 'voxels'
set multiplot layout 1,3
set ylabel 'ms'
set title 'time (frames: device time of build + render)'
set key bottom right
plot csv using 'voxels':'time_to_first_frame_ms' with linespoints title 'to first frame', \
     '' using 'voxels':'none_frame_ms' with linespoints title 'none frame', \
     '' using 'voxels':'threshold_frame_ms' with linespoints title 'threshold frame', \
     '' using 'voxels':'cssm_frame_ms' with linespoints title 'cssm frame', \
     '' using 'voxels':'deep_frame_ms' with linespoints title 'deep frame'
set ylabel 'bytes'
set title 'memory'
set key top left
plot csv using 'voxels':'peak_rss_bytes' with linespoints title 'peak host RSS', \
     '' using 'voxels':'volume_device_bytes' with linespoints title 'volume device bytes', \
     '' using 'voxels':'voxels' with lines dt 2 title '1 byte per voxel'
set ylabel 'samples'
set title 'view samples per frame (none)'
set key bottom right
plot csv using 'voxels':'samples_none' with linespoints title 'samples', \
     '' using 'voxels':(column('voxels')**(1.0/3)*1e4) with lines dt 2 title 'voxels^{1/3} (ray length), scaled'
unset multiplot
