#!/usr/bin/env bash
# The SDK end to end: install varia into a temporary prefix, build examples/out-of-tree-plugin
# against the installed CMake package, run the installed conformance suite on it (its ctest test,
# which runs varia-conformance), drop the plugin into a directory, list it and run it.
set -euo pipefail
build=$1 source=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cmake --install "$build" --prefix "$work/prefix" >/dev/null
for f in bin/varia bin/varia-conformance include/varia/sdk/plugin.hpp include/varia/sdk/conformance/plugin.hpp \
  lib/cmake/varia/variaConfig.cmake lib/varia/plugins/lagrangian_pendulum.so; do
  test -e "$work/prefix/$f" || { echo "not installed: $f" >&2; exit 1; }
done
# Core's internals (the constructions, the driver) are not part of the package.
for f in include/varia/core/galerkin.hpp include/varia/core/trajectory.hpp include/varia/core/mechanics.hpp; do
  test ! -e "$work/prefix/$f" || { echo "installed, but internal: $f" >&2; exit 1; }
done
cmake -S "$source/examples/out-of-tree-plugin" -B "$work/duffing" -G Ninja \
  -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$work/prefix" >/dev/null
cmake --build "$work/duffing" >/dev/null
# A plugin project that names no build type is built in Release (the package's default).
cmake -S "$source/examples/out-of-tree-plugin" -B "$work/default" -G Ninja -DCMAKE_PREFIX_PATH="$work/prefix" >/dev/null
grep -q '^CMAKE_BUILD_TYPE:STRING=Release$' "$work/default/CMakeCache.txt" ||
  { echo "a plugin project without a build type is not built in Release" >&2; exit 1; }
ctest --test-dir "$work/duffing" --output-on-failure >/dev/null
"$work/prefix/bin/varia-conformance" "$work/duffing/plugins/lagrangian_duffing.so" | grep -q "conforms"
mkdir -p "$work/dropin" && chmod 755 "$work/dropin"
cp "$work/duffing/plugins/lagrangian_duffing.so" "$work/dropin/"
chmod 755 "$work/dropin/lagrangian_duffing.so"
"$work/prefix/bin/varia" plugins --plugin-path "$work/dropin" | grep -q duffing
VARIA_PLUGIN_PATH="$work/dropin" "$work/prefix/bin/varia" run \
  "$source/examples/out-of-tree-plugin/duffing.json" --out "$work/duffing.csv" --quiet
test "$(head -1 "$work/duffing.csv")" = "t,q0,p0,energy"
echo "out-of-tree plugin: built, conforms, listed and run ($(($(wc -l <"$work/duffing.csv") - 1)) rows)"
