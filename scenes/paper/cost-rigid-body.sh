#!/bin/sh
# Paper sec. 2 example, Figure 1's heavy top on SO(3) (inertia 1, 1.5, 0.8; m g = 1; T = 30): the
# Lie group variational integrator LGVI (Lie group velocity Verlet, Cayley solve), the paper's
# comparison methods run as one-step constructions (RK: explicit midpoint in the embedding; SRK:
# implicit midpoint in the embedding; LGM: Crouch-Grossman on the group), and varia's Galerkin
# Lie group integrator of degree 2 (order 4) in the natural chart. The heavy top has no
# closed-form solution: errors are measured against a converged reference run (a Galerkin Lie
# group integrator of degree 4, order 8) that the output and cost.json name.
# Writes out/paper/rigid-body/cost.{csv,svg,json} and docs/figures/cost-rigid-body.svg.
set -eu
cd "$(dirname "$0")/../.."
out=${1:-out/paper/rigid-body}
"${VARIA:-build/bin/varia}" cost scenes/paper/rigid-body-lgvi.json scenes/paper/rigid-body-rk.json \
  scenes/paper/rigid-body-srk.json scenes/paper/rigid-body-lgm.json scenes/paper/heavy-top-galerkin-s2.json \
  --h 0.04,0.02,0.01,0.005,0.0025 --out "$out"
mkdir -p docs/figures
cp "$out/cost.svg" docs/figures/cost-rigid-body.svg
