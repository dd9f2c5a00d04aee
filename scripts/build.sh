#!/usr/bin/env bash
# Installs the dependencies (Debian 12) and builds varia in build/ (Release): the targets named
# (e.g. varia_program: the program and its bundled plugins), or everything (tests and benchmarks
# too). Uses ccache when it is installed (a cache never replaces a build step: CI starts empty).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" >/dev/null
targets=()
for t in "$@"; do targets+=(--target "$t"); done
cmake --build build -j"$(nproc)" "${targets[@]}"
