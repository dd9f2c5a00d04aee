#!/usr/bin/env bash
# The README's second command: install, build everything (every test program, the scene fuzzer of
# tests/fuzz included), and run the quick test suite (everything but the ctest labels "long" and
# "fuzz"; run those with `ctest --test-dir build -L long` or `-L fuzz`).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh
ctest --test-dir build -LE "long|fuzz" --output-on-failure -j"$(nproc)" --timeout 600
