#!/usr/bin/env bash
# The README's second command: install, build what the tests run (varia_tests: the test programs,
# the program and its plugins; not the benchmarks, not the scene fuzzer), and run the quick test
# suite (everything but the ctest labels "long" and "fuzz"; run those with
# `ctest --test-dir build -L long` or `-L fuzz`, which builds the fuzzer).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh varia_tests
ctest --test-dir build -LE "long|fuzz" --output-on-failure -j"$(nproc)" --timeout 600
