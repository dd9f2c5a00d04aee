#!/bin/sh
# Paper sec. 2, Figure 1: LGVI (Lie group velocity Verlet), RK (explicit midpoint in the
# embedding), SRK (implicit midpoint in the embedding) and LGM (Crouch-Grossman on the group) on a
# heavy rigid body, scenes/paper/rigid-body-{lgvi,rk,srk,lgm}.json, over 30 s. For each method and
# step size h: the mean orthogonality error ||I - R^T R|| and the mean energy error |E - E0| over
# the written steps (from the trajectory CSV), and the CPU time of the stepping loop (the run
# record's wall_seconds) from a second run that observes nothing, since the observables cost more
# than a step. Writes $out/figure1.csv and, with gnuplot, docs/figures/figure1.svg.
# VARIA names the host (default build/bin/varia).
set -eu
cd "$(dirname "$0")/../.."
varia=${VARIA:-build/bin/varia}
out=${1:-out/paper/figure1}
mkdir -p "$out"
table="$out/figure1.csv"
echo "method,h,mean_orthogonality_error,mean_energy_error,seconds" > "$table"
for method in lgvi rk srk lgm; do
  for h in 0.08 0.04 0.02 0.01 0.005 0.0025; do
    scene="$out/$method-$h.json"
    sed "s/\"step\": 0.01/\"step\": $h/" "scenes/paper/rigid-body-$method.json" > "$scene"
    "$varia" run "$scene" --out "$out/$method-$h.csv" --quiet > /dev/null
    sed '/"observe"/d; s/"t_end": 30.0,/"t_end": 30.0/' "$scene" > "$out/$method-$h-timed.json"
    "$varia" run "$out/$method-$h-timed.json" --summary "$out/$method-$h.summary.json" --quiet > /dev/null
    seconds=$(sed -n 's/.*"wall_seconds": *\([0-9.eE+-]*\).*/\1/p' "$out/$method-$h.summary.json")
    # Columns: t, q0..q8, p0..p2, energy, orthogonality; the first row is the initial state.
    awk -F, -v m="$method" -v h="$h" -v s="$seconds" '
      NR == 2 { e0 = $14 }
      NR > 2 { d = $14 - e0; energy += (d < 0 ? -d : d); orthogonality += $15; n++ }
      END { printf "%s,%s,%.6e,%.6e,%s\n", m, h, orthogonality / n, energy / n, s }' \
      "$out/$method-$h.csv" >> "$table"
  done
done
cat "$table"
command -v gnuplot > /dev/null || exit 0
mkdir -p docs/figures
gnuplot <<GNUPLOT
set terminal svg size 900,640 dynamic font "sans,11"
set output "docs/figures/figure1.svg"
set datafile separator ","
set multiplot layout 2,2 title "Figure 1: LGVI, RK, SRK, LGM on a heavy rigid body, 30 s"
set key bottom right
set xlabel "t"
set ylabel "E (h = 0.01)"
plot for [m in "lgvi rk srk lgm"] "$out/".m."-0.01.csv" using 1:14 every 10::1 with lines title m
set logscale xy
set format y "%.0e"
set xlabel "h"
set ylabel "mean ||I - R^T R||"
plot for [m in "lgvi rk srk lgm"] "< grep ^".m." $table" using 2:3 with linespoints title m
set ylabel "mean |E - E0|"
plot for [m in "lgvi rk srk lgm"] "< grep ^".m." $table" using 2:4 with linespoints title m
set ylabel "CPU seconds"
plot for [m in "lgvi rk srk lgm"] "< grep ^".m." $table" using 2:5 with linespoints title m
unset multiplot
GNUPLOT
