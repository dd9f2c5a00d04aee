#!/bin/sh
# Paper sec. 3 "Examples", pendulum (q0 = 1, p0 = 0.5, T = 2000): the shooting-based variational
# integrators against the one-step methods they are built from, as error against step size and
# work-precision. SVIMID (implicit midpoint + trapezoid, order 2) against MID (the implicit
# midpoint rule run directly); SVIRK4 (RK4 + Simpson, order 4) against SRK4 (2-stage Gauss).
# Writes out/paper/pendulum/cost.{csv,svg,json} and docs/figures/cost-pendulum.svg.
set -eu
cd "$(dirname "$0")/../.."
out=${1:-out/paper/pendulum}
"${VARIA:-build/bin/varia}" cost scenes/paper/svimid-pendulum.json scenes/paper/mid-pendulum.json \
  scenes/paper/svirk4-pendulum.json scenes/paper/srk4-pendulum.json \
  --h 0.4,0.2,0.1,0.05,0.025,0.0125 --out "$out"
mkdir -p docs/figures
cp "$out/cost.svg" docs/figures/cost-pendulum.svg
