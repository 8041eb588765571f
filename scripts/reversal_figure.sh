#!/usr/bin/env bash
# The reversal figure of docs/controllers.md (issue 24, item 5): the study studies/reversal.yaml
# (the paper's 1 Hz, 0.1 m sine started at rest; Fs/Fc of the plant -30 %, ideal sensor, no
# delay), then the robust SMC, the tuned cascade and the cascade on the observer's state rerun
# with their time series, and the error, velocity, sliding variable and friction force around the
# reversal at t = 0.5 s plotted to docs/img/robustness/reversal.png.
#   bash scripts/reversal_figure.sh [BUILD_DIR] [WORK_DIR]
# A few seconds on two cores.
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=${1:-build}/bin
W=${2:-/tmp/feeddrive-reversal}
IMG=docs/img/robustness
mkdir -p "$W" "$IMG"
"$BIN/feeddrive-study" studies/reversal.yaml --out "$W/study" --no-plots -q
for c in robust_smc cascade_tuned cascade_observer; do
  hash=$(awk -F, -v c="$c" 'NR > 1 && $2 == c && $3 == "coulomb_static" {print $6}' "$W/study/results.csv")
  "$BIN/feeddrive-sim" "$(ls "$W/study/cases/$hash"*.yaml)" --out "$W/$c" --no-plots > "$W/$c.log" 2>&1 || { cat "$W/$c.log" >&2; exit 1; }
done
cat > "$W/reversal.gp" <<GP
set encoding utf8
set datafile separator ','
set datafile missing 'nan'
set terminal pngcairo size 1000,1100 noenhanced
set output '$PWD/$IMG/reversal.png'
set multiplot layout 4,1 title 'velocity reversal at t = 0.5 s, sine 0.1 m 1 Hz, plant Fs/Fc -30 %, ideal sensor, no delay'
set grid
set key outside right top vertical
set lmargin at screen 0.1
set rmargin at screen 0.68
set xrange [0.49:0.53]
set arrow 1 from 0.5, graph 0 to 0.5, graph 1 nohead dt 3 lc rgb 'black'   # vd = 0
set format x ''
set ylabel 'e = xd - x [um]'
plot '$W/robust_smc/timeseries.csv' every ::1 using 1:((\$2-\$6)*1e6) with lines lw 2 title 'robust SMC', \
     '$W/cascade_observer/timeseries.csv' every ::1 using 1:((\$2-\$6)*1e6) with lines lw 2 title 'cascade, observer x^ v^', \
     '$W/cascade_tuned/timeseries.csv' every ::1 using 1:((\$2-\$6)*1e6) with lines lw 2 title 'tuned cascade (encoder x, v)'
set ylabel 'vd - v [mm/s]'
plot '$W/robust_smc/timeseries.csv' every ::1 using 1:((\$3-\$8)*1e3) with lines lw 2 title 'robust SMC', \
     '$W/cascade_observer/timeseries.csv' every ::1 using 1:((\$3-\$8)*1e3) with lines lw 2 title 'cascade, observer', \
     '$W/cascade_tuned/timeseries.csv' every ::1 using 1:((\$3-\$8)*1e3) with lines lw 2 title 'tuned cascade',
set ylabel 'S of the robust SMC [mm/s]'
set yrange [-0.6:0.6]
plot '$W/robust_smc/timeseries.csv' every ::1 using 1:(\$19*1e3) with lines lw 2 lc 1 title 'S = de/dt + lambda e', \
     5.0e-4*1e3 with lines dt 3 lc rgb 'gray' title 'boundary layer +-phi', -5.0e-4*1e3 with lines dt 3 lc rgb 'gray' notitle
set yrange [*:*]
set format x '%g'
set xlabel 't [s]'
set ylabel 'friction [N]'
plot '$W/robust_smc/timeseries.csv' every ::1 using 1:16 with lines lw 2 lc 1 title 'plant friction (robust SMC run)', \
     '$W/cascade_tuned/timeseries.csv' every ::1 using 1:16 with lines lw 1 lc 3 title 'plant friction (tuned cascade run)'
unset multiplot
GP
gnuplot "$W/reversal.gp"
echo "$IMG/reversal.png"
