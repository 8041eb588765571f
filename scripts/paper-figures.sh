#!/usr/bin/env bash
# Runs every scenario of scenarios/paper/ with feeddrive-sim into ${OUT:-out/paper}/<name>/ and
# draws the comparison figures of docs/paper-reproduction.md into docs/img/paper/.
# Needs a build (scripts/build.sh) and gnuplot.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build}
OUT=${OUT:-out/paper}
IMG=docs/img/paper
mkdir -p "$OUT" "$IMG"
for f in scenarios/paper/*.yaml; do
  name=$(basename "$f" .yaml)
  "$BUILD_DIR/bin/feeddrive-sim" "$f" --out "$OUT/$name" --quiet --no-plots
done
# Breakaway force (v first > 1 mm/s) per force rate, for the bar chart.
for r in 10 50 100 500 1000; do
  awk -F, -v r=$r 'NR > 1 && $8 > 1e-3 { print r, $15; exit }' "$OUT/open_loop_breakaway_${r}Nps/timeseries.csv"
done > "$OUT/breakaway.dat"

# Columns of timeseries.csv: 1 t, 2 xd, 3 vd, 4 ad, 5 jd, 6 x, 7 x_measured, 8 v, 9 v_measured,
# 10 z, 11 fg, 12 i, 13 u, 14 u_unsaturated, 15 f_thrust, 16 f_friction, 17 f_ripple,
# 18 f_grinding, 19 sliding, 20 z_estimate.
gnuplot <<GP
set datafile separator ','
set terminal pngcairo size 900,520 noenhanced font ',11'
set grid
set key top left
O = '$OUT/'
I = '$IMG/'

set output I.'open_loop_presliding_12N.png'
set title 'Fig. 8: 12 N force step (presliding)'
set xlabel 't [s]'; set ylabel '[um]'
plot O.'open_loop_step_12N/timeseries.csv' every ::1 using 1:(\$6*1e6) w l lw 2 t 'x', '' every ::1 using 1:(\$10*1e6) w l lw 2 dt 2 t 'z'

set output I.'open_loop_breakaway_130N.png'
set title 'Fig. 9: 130 N force step (breakaway): friction falls to Fc = 80 N'
set ylabel 'friction [N]'; set yrange [70:130]
plot O.'open_loop_step_130N/timeseries.csv' every ::1 using 1:16 w l lw 2 t 'F_friction', 80 w l dt 2 t 'Fc', 120 w l dt 3 t 'Fs'
set yrange [*:*]

set output I.'open_loop_sines_12N.png'
set title 'Fig. 10: 12 N sines, x against the phase of the force (last period)'
set xlabel 'phase of the force [cycles]'; set ylabel 'x [um]'
plot O.'open_loop_sine_12N_0p1Hz/timeseries.csv' every ::1 using (\$1*0.1 - floor(\$1*0.1)):(\$1 >= 10 ? \$6*1e6 : 1/0) w l lw 2 t '0.1 Hz', \
     O.'open_loop_sine_12N_1Hz/timeseries.csv' every ::1 using (\$1 - floor(\$1)):(\$1 >= 2 ? \$6*1e6 : 1/0) w l lw 2 dt 2 t '1 Hz', \
     O.'open_loop_sine_12N_10Hz/timeseries.csv' every ::1 using (\$1*10 - floor(\$1*10)):(\$1 >= 0.4 ? \$6*1e6 : 1/0) w l lw 2 t '10 Hz (lags)'

set output I.'open_loop_sines_120N.png'
set title 'Fig. 11: 120 N sines: displacement falls as frequency rises (first period)'
set xlabel 'phase of the force [cycles]'; set ylabel 'x [um]'; set xrange [0:1]
plot O.'open_loop_sine_120N_0p1Hz/timeseries.csv' every ::1 using (\$1*0.1):(\$1 <= 10 ? \$6*1e6 : 1/0) w l lw 2 t '0.1 Hz', \
     O.'open_loop_sine_120N_1Hz/timeseries.csv' every ::1 using 1:(\$1 <= 1 ? \$6*1e6 : 1/0) w l lw 2 t '1 Hz', \
     O.'open_loop_sine_120N_10Hz/timeseries.csv' every ::1 using (\$1*10):(\$1 <= 0.1 ? \$6*1e6 : 1/0) w l lw 2 t '10 Hz'
set xrange [*:*]

set datafile separator whitespace
set output I.'open_loop_breakaway_rate.png'
set title 'Fig. 12: breakaway force (v > 1 mm/s) against force rate'
set xlabel 'force rate [N/s]'; set ylabel 'breakaway force [N]'; set logscale x
plot O.'breakaway.dat' using 1:2 w lp lw 2 pt 7 t 'ours', 120 w l dt 2 t 'Fs'
unset logscale x
set datafile separator ','

set output I.'open_loop_all_forces_180N.png'
set title 'Fig. 15: 180 N with friction, ripple and grinding'
set xlabel 't [s]'; set ylabel 'force [N]'
plot O.'open_loop_all_forces_180N/timeseries.csv' every ::1 using 1:18 w l lw 2 t 'grinding', '' every ::1 using 1:16 w l lw 2 t 'friction', '' every ::1 using 1:17 w l lw 2 t 'ripple'

set output I.'open_loop_ripple_sine_130N.png'
set title 'Fig. 14: 130 sin(2 pi t) N with ripple: the position drifts'
set ylabel 'x [um]'
plot O.'open_loop_ripple_sine_130N/timeseries.csv' every ::1 using 1:(\$6*1e6) w l lw 2 t 'x'

set output I.'smc_sine_error.png'
set title 'Fig. 18: SMC on the 100 mm, 1 Hz sinusoid (hard sgn, 20 us)'
set ylabel 'e = x_d - x [mm]'
plot O.'smc_sine/timeseries.csv' every ::1 using 1:((\$2-\$6)*1e3) w l lw 2 t 'e (max 6.83 mm at 29 ms)'

set output I.'jerk_limited_error.png'
set title 'Figs. 21-22: jerk-limited move, tracking error'
set ylabel 'e [um]'; set yrange [-0.8:0.8]
plot O.'smc_jerk_limited/timeseries.csv' every 10::1 using 1:((\$2-\$6)*1e6) w l t 'paper: hard sgn, 20 us, true z', \
     O.'beyond_jerk_limited/timeseries.csv' every ::1 using 1:((\$2-\$6)*1e6) w l lw 2 t 'beyond: 10 kHz, observers, 50 nm encoder', \
     0.2 w l dt 2 lc 'black' t '+-0.2 um', -0.2 w l dt 2 lc 'black' notitle
set yrange [*:*]

set output I.'jerk_limited_control.png'
set title 'Jerk-limited move, control input (chattering)'
set ylabel 'u [V]'
plot O.'smc_jerk_limited/timeseries.csv' every 10::1 using 1:13 w l t 'paper: hard sgn, 20 us', \
     O.'beyond_jerk_limited/timeseries.csv' every ::1 using 1:13 w l lw 3 t 'beyond: sat(S/phi) + observers'

set output I.'ramp_velocity_error.png'
set title 'Fig. 23: 1 um/s ramp with all three forces, |velocity error|'
set ylabel '|v_d - v| [nm/s]'; set logscale y; set yrange [1e-3:1e6]
plot O.'smc_ramp_all_forces/timeseries.csv' every 10::2 using 1:(abs(\$3-\$8)*1e9) w l t 'paper: hard sgn, 20 us', \
     O.'smc_bl_ramp_all_forces/timeseries.csv' every ::2 using 1:(abs(\$3-\$8)*1e9) w l lw 2 t 'boundary layer, 10 kHz, true z', \
     O.'beyond_ramp_all_forces/timeseries.csv' every ::2 using 1:(abs(\$3-\$8)*1e9) w l lw 2 t 'beyond', \
     150 w l dt 2 lc 'black' t '150 nm/s', 4 w l dt 3 lc 'black' t '4 nm/s'
unset logscale y; set yrange [*:*]

set output I.'ramp_forces.png'
set title 'Fig. 23: 1 um/s ramp, forces (boundary layer, 10 kHz)'
set ylabel 'force [N]'
plot O.'smc_bl_ramp_all_forces/timeseries.csv' every ::1 using 1:16 w l lw 2 t 'friction (2 N/s)', '' every ::1 using 1:18 w l lw 2 t 'grinding', '' every ::1 using 1:17 w l lw 2 t 'ripple'
GP
echo "figures in $IMG/"
