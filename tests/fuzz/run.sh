#!/usr/bin/env bash
# Builds the fuzzer with clang (tests/fuzz/CMakeLists.txt) and runs it for a bounded time, seeded
# with every scene of scenes/ (good and bad) and the regressions of tests/fuzz/regressions (plugin
# parameter schemas, command lines). What varia prints is dropped (-close_fd_mask=3); libFuzzer's
# report and the sanitizers' go to BUILD_DIR/fuzz/fuzz.log.
# Usage: run.sh BUILD_DIR SOURCE_DIR CLANGXX SECONDS. SECONDS 0 only builds the fuzzer (the target
# scene_fuzzer of the build of everything, tests/CMakeLists.txt): then a fuzzer that cannot be
# built is an error. Otherwise exits 77 (ctest: skipped) when libFuzzer cannot be built here, and
# non-zero when the fuzzer finds a crash, which it writes to BUILD_DIR/fuzz/findings/ (turn each
# into a regression: scenes/bad/ or tests/fuzz/regressions/).
set -euo pipefail
build=$1 source=$2 clangxx=$3 seconds=$4
fuzz=$build/fuzz
mkdir -p "$fuzz"
if ! cmake -S "$source/tests/fuzz" -B "$fuzz/build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_COMPILER="$clangxx" -DVARIA_PLUGIN_DIR="$build/lib/varia/plugins" -DVARIA_CORE_LIBRARY="$build/core/libvaria_core.a" >"$fuzz.configure.log" 2>&1; then
  if [ "$seconds" = 0 ]; then
    tail -20 "$fuzz.configure.log"
    echo "fuzz: the fuzzer cannot be built (see $fuzz.configure.log; scripts/install-deps.sh installs libFuzzer)"
    exit 1
  fi
  echo "fuzz: skipped, libFuzzer cannot be built here (see $fuzz.configure.log)"
  exit 77
fi
cmake --build "$fuzz/build" >"$fuzz.build.log" 2>&1 || { tail -40 "$fuzz.build.log"; exit 1; }
[ "$seconds" = 0 ] && exit 0
corpus=$fuzz/corpus
mkdir -p "$corpus" "$fuzz/findings"
find "$source/scenes" "$source/tests/fuzz/regressions" -name '*.json' -exec cp {} "$corpus/" \; 2>/dev/null || true
cp "$source"/tests/fuzz/regressions/* "$corpus/" 2>/dev/null || true
export VARIA_FUZZ_SANDBOX=$fuzz/sandbox  # where the command lines run
rm -rf "$VARIA_FUZZ_SANDBOX"
trap 'rm -rf "$VARIA_FUZZ_SANDBOX"' EXIT
"$fuzz/build/scene_fuzzer" -max_total_time="$seconds" -max_len=65536 -timeout=10 -rss_limit_mb=4096 \
  -dict="$source/tests/fuzz/scene.dict" -close_fd_mask=3 -artifact_prefix="$fuzz/findings/" -print_final_stats=1 \
  "$corpus" 2>"$fuzz/fuzz.log" || { tail -40 "$fuzz/fuzz.log"; exit 1; }
grep -E "stat::number_of_executed_units|stat::peak_rss_mb|Done" "$fuzz/fuzz.log" || true
