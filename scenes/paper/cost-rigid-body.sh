#!/bin/sh
# Paper sec. 2 example, the free rigid body on SO(3) (inertia 1, 2, 3; T = 30): the Lie group
# variational integrator LGVI (Lie group velocity Verlet) with its Cayley and its exponential
# solve. The paper also compares RK, SRK and LGM (one-step methods on SO(3)); their scenes join
# this command once the one-step construction runs on SO(3) (it takes vector spaces today). The
# rigid body has no closed-form solution here: errors are measured against a converged reference
# run that the output and cost.json name.
# Writes out/paper/rigid-body/cost.{csv,svg,json} and docs/figures/cost-rigid-body.svg.
set -eu
cd "$(dirname "$0")/../.."
out=${1:-out/paper/rigid-body}
"${VARIA:-build/bin/varia}" cost scenes/paper/rigid-body-lgvi-cayley.json scenes/paper/rigid-body-lgvi-exp.json \
  --h 0.04,0.02,0.01,0.005,0.0025,0.00125 --out "$out"
mkdir -p docs/figures
cp "$out/cost.svg" docs/figures/cost-rigid-body.svg
