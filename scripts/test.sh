#!/usr/bin/env bash
# The README's second command: install, build, and run the quick test suite (everything but the
# ctest label "long"; run those with `ctest --test-dir build -L long`).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh
ctest --test-dir build -LE long --output-on-failure -j"$(nproc)" --timeout 600
