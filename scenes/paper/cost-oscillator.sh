#!/bin/sh
# Paper sec. 3 "Examples", harmonic oscillator (q0 = 1, p0 = 0.5, T = 2000): shooting with RK4 and
# Simpson's rule (sviRK4Sim) against RK4 with the Euler-Maclaurin formula truncated after its
# second term (sviRK4EM); both order 4.
# Writes out/paper/oscillator/cost.{csv,svg,json} and docs/figures/cost-oscillator.svg.
set -eu
cd "$(dirname "$0")/../.."
out=${1:-out/paper/oscillator}
"${VARIA:-build/bin/varia}" cost scenes/paper/svirk4sim-oscillator.json scenes/paper/svirk4em-oscillator.json \
  --h 0.4,0.2,0.1,0.05,0.025,0.0125 --out "$out"
mkdir -p docs/figures
cp "$out/cost.svg" docs/figures/cost-oscillator.svg
