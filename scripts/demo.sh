#!/usr/bin/env bash
# The README's first command: install, build what the bundled default scene needs (the program and
# its three plugins: `scripts/build.sh varia_program` builds every plugin), and run it.
# Writes out/default.csv (trajectory), out/default.json (run record) and out/default.svg (plot).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh varia_demo
mkdir -p out
build/bin/varia run scenes/default.json --out out/default.csv --summary out/default.json \
  --plot out/default.svg
echo "wrote out/default.csv (the trajectory), out/default.json (the run record) and out/default.svg (the plot)"
