#!/usr/bin/env bash
# The README's first command: install, build, and run the bundled default scene.
# Writes out/default.csv (trajectory), out/default.json (run record) and out/default.svg (plot).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh varia_program
mkdir -p out
build/bin/varia run scenes/default.json --out out/default.csv --summary out/default.json \
  --plot out/default.svg
