#!/usr/bin/env bash
# The figures and tables of docs/analysis.md: the closed-loop frequency response
# (feeddrive-sim --frequency-response) of the paper's drive under its sliding-mode controllers and
# the tuned cascade, and the dynamic stiffness at the grinding process's frequencies.
#   bash scripts/analysis_figures.sh [BUILD_DIR] [WORK_DIR] [--plots-only]
# Writes WORK_DIR (default /tmp/feeddrive-analysis) and docs/img/analysis/*.png. About 5 minutes on
# two cores (the paper's sgn law at 20 us is most of it); --plots-only redraws from WORK_DIR.
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=${1:-build}/bin
W=${2:-/tmp/feeddrive-analysis}
IMG=docs/img/analysis
mkdir -p "$W" "$IMG"
SCENARIOS="paper/smc_jerk_limited paper/smc_bl_jerk_limited robustness/robust_smc robustness/cascade_tuned analysis/cascade_tuned_feedback_only"
for sc in $SCENARIOS; do
  [ "${3:-}" = --plots-only ] && break
  n=$(basename "$sc")
  "$BIN/feeddrive-sim" "scenarios/$sc.yaml" --out "$W/$n" --frequency-response --fr-from 1 --fr-to 4000 --fr-points 18 -j2 > "$W/$n.txt"
  for F in 100 1000; do
    "$BIN/feeddrive-sim" "scenarios/$sc.yaml" --out "$W/${n}_grind_$F" --frequency-response \
      --fr-frequencies 0.41,1.9,28,100,300,1000 --fr-amplitude 0 --fr-force "$F" -j2 > "$W/${n}_grind_$F.txt"
  done
done
cp "$W/cascade_tuned/bode_loop.png" "$IMG/cascade_tuned_bode_loop.png"
cp "$W/robust_smc/bode_compliance.png" "$IMG/robust_smc_bode_compliance.png"
cat > "$W/overlay.gp" <<GP
set encoding utf8
set datafile separator ','
set datafile missing 'nan'
set terminal pngcairo size 1000,700 noenhanced
set grid
set key outside right top vertical
set logscale x
set xlabel 'f [Hz]'
set output '$PWD/$IMG/dynamic_stiffness.png'
set title 'dynamic stiffness |F_d/x|, force 100 N (dots: grinding frequencies)'
set logscale y
set xrange [0.3:5000]
set ylabel 'dynamic stiffness [N/um]'
set arrow 1 from 0.41, graph 0 to 0.41, graph 1 nohead dt 3
set arrow 2 from 1.9, graph 0 to 1.9, graph 1 nohead dt 3
set arrow 3 from 28, graph 0 to 28, graph 1 nohead dt 3
plot '$W/smc_jerk_limited/frequency_response.csv' every ::1 using 1:7 with linespoints title 'paper SMC (sgn, 20 us)', \
     '$W/smc_bl_jerk_limited/frequency_response.csv' every ::1 using 1:7 with linespoints title 'paper SMC, boundary layer', \
     '$W/robust_smc/frequency_response.csv' every ::1 using 1:7 with linespoints title 'robust SMC (observers)', \
     '$W/cascade_tuned/frequency_response.csv' every ::1 using 1:7 with linespoints title 'tuned cascade', \
     '$W/smc_jerk_limited_grind_100/frequency_response.csv' every ::1 using 1:7 with points lt 1 pt 7 notitle, \
     '$W/smc_bl_jerk_limited_grind_100/frequency_response.csv' every ::1 using 1:7 with points lt 2 pt 7 notitle, \
     '$W/robust_smc_grind_100/frequency_response.csv' every ::1 using 1:7 with points lt 3 pt 7 notitle, \
     '$W/cascade_tuned_grind_100/frequency_response.csv' every ::1 using 1:7 with points lt 4 pt 7 notitle
set xrange [*:*]
unset arrow 1
unset arrow 2
unset arrow 3
unset logscale y
set output '$PWD/$IMG/closed_loop.png'
set title 'reference -> position |T|, amplitude min(10 um, a_lim/w^2)'
set ylabel '|T| [dB]'
plot '$W/smc_jerk_limited/frequency_response.csv' every ::1 using 1:3 with linespoints title 'paper SMC (sgn, 20 us)', \
     '$W/smc_bl_jerk_limited/frequency_response.csv' every ::1 using 1:3 with linespoints title 'paper SMC, boundary layer', \
     '$W/robust_smc/frequency_response.csv' every ::1 using 1:3 with linespoints title 'robust SMC (observers)', \
     '$W/cascade_tuned/frequency_response.csv' every ::1 using 1:3 with linespoints title 'tuned cascade', \
     '$W/cascade_tuned_feedback_only/frequency_response.csv' every ::1 using 1:3 with linespoints lc rgb 'black' title 'cascade, feedback only', \
     -3.01 with lines dt 2 title '-3 dB'
set output '$PWD/$IMG/sensitivity.png'
set title 'input sensitivity |S| at the force set-point, force 100 N'
set ylabel '|S| [dB]'
plot '$W/smc_bl_jerk_limited/frequency_response.csv' every ::1 using 1:10 with linespoints title 'paper SMC, boundary layer', \
     '$W/robust_smc/frequency_response.csv' every ::1 using 1:10 with linespoints title 'robust SMC (observers)', \
     '$W/cascade_tuned/frequency_response.csv' every ::1 using 1:10 with linespoints title 'tuned cascade', \
     0 with lines dt 2 notitle
GP
gnuplot "$W/overlay.gp"
echo "tables in $W/*.txt, figures in $IMG"
