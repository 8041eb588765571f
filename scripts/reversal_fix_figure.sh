#!/usr/bin/env bash
# The reversal fix figure of docs/controllers.md (issue 24, item 5): the robust SMC on the sine
# (scenarios/robustness/robust_smc_sine.yaml: 0.1 m, 1 Hz, started at rest, reversal at 0.5 s)
# with the plant's Fs and Fc at half the model's, the 100 nm encoder with 40 nm RMS noise
# (seed 1), no delay; without and with the adapted friction level (controller.adaptation_rate:
# 50). Plots the error, the sliding variable, the bristle deflection of the plant (z) and of the
# controller's observer (z^), and the plant's friction around the reversal at t = 0.5 s to
# docs/img/robustness/reversal_fix.png, and prints the two runs' max |e| and the adapted level.
#   bash scripts/reversal_fix_figure.sh [BUILD_DIR] [WORK_DIR]
# A few seconds on two cores.
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=${1:-build}/bin
W=${2:-/tmp/feeddrive-reversal-fix}
IMG=docs/img/robustness
mkdir -p "$W" "$IMG"
SETS=(--set plant.sensor.quantization=1.0e-7 --set plant.sensor.noise_stddev=4.0e-8
      --set plant.friction.static_force=60 --set plant.friction.coulomb_force=40)
for rate in 0 50; do
  "$BIN/feeddrive-sim" scenarios/robustness/robust_smc_sine.yaml --out "$W/rate$rate" --no-plots -q "${SETS[@]}" \
    --set controller.adaptation_rate=$rate
  echo "adaptation_rate $rate: max |e| = $(jq '.position_error_max_abs_m * 1e6' "$W/rate$rate/summary.json") um," \
       "after 0.25 s $(jq '.position_error_max_abs_settled_m * 1e6' "$W/rate$rate/summary.json") um"
done
cat > "$W/reversal_fix.gp" <<GP
set encoding utf8
set datafile separator ','
set datafile missing 'nan'
set terminal pngcairo size 1000,1100 noenhanced
set output '$PWD/$IMG/reversal_fix.png'
set multiplot layout 4,1 title 'reversal at t = 0.5 s: robust SMC, sine 0.1 m 1 Hz, plant Fs/Fc x0.5, 100 nm encoder, no delay'
set grid
set key outside right top vertical
set lmargin at screen 0.1
set rmargin at screen 0.68
set xrange [0.495:0.525]
set arrow 1 from 0.5, graph 0 to 0.5, graph 1 nohead dt 3 lc rgb 'black'   # vd = 0
set format x ''
set ylabel 'e = xd - x [um]'
plot '$W/rate0/timeseries.csv' every ::1 using 1:((\$2-\$6)*1e6) with lines lw 2 lc 1 title 'model level (before)', \
     '$W/rate50/timeseries.csv' every ::1 using 1:((\$2-\$6)*1e6) with lines lw 2 lc 2 title 'adapted level (after)'
set ylabel 'S [mm/s]'
plot '$W/rate0/timeseries.csv' every ::1 using 1:(\$19*1e3) with lines lw 1 lc 1 title 'S before', \
     '$W/rate50/timeseries.csv' every ::1 using 1:(\$19*1e3) with lines lw 1 lc 2 title 'S after', \
     0.5 with lines dt 3 lc rgb 'gray' title 'boundary layer +-phi', -0.5 with lines dt 3 lc rgb 'gray' notitle
set ylabel 'bristle [um]'
plot '$W/rate0/timeseries.csv' every ::1 using 1:(\$10*1e6) with lines lw 3 lc rgb 'black' title 'plant z', \
     '$W/rate0/timeseries.csv' every ::1 using 1:(\$20*1e6) with lines lw 2 lc 1 title 'observer z^ before', \
     '$W/rate50/timeseries.csv' every ::1 using 1:(\$20*1e6) with lines lw 2 lc 2 dt 2 title 'observer z^ after'
set format x '%g'
set xlabel 't [s]'
set ylabel 'friction [N]'
plot '$W/rate0/timeseries.csv' every ::1 using 1:16 with lines lw 2 lc 1 title 'plant friction (before run)', \
     '$W/rate50/timeseries.csv' every ::1 using 1:16 with lines lw 2 lc 2 dt 2 title 'plant friction (after run)'
unset multiplot
GP
gnuplot "$W/reversal_fix.gp"
echo "$IMG/reversal_fix.png"
