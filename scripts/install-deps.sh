#!/usr/bin/env bash
# Installs varia's build dependencies from Debian 12's packages. Idempotent: packages already
# present are left alone, and apt-get is not called at all when nothing is missing.
set -euo pipefail
packages=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev libboost-dev nlohmann-json3-dev libfmt-dev doctest-dev libcli11-dev
  libvalijson-dev gnuplot-nox libhdf5-dev
  libopenmpi-dev openmpi-bin  # varia ensemble under mpirun (docs/ensembles.md)
  clang libclang-rt-14-dev  # the scene fuzzer (ctest -L fuzz): libFuzzer
  gfortran  # bench_gni: the GNI peer (../shared/peers/gni) it times varia against
  pybind11-dev python3-dev python3-numpy python3-sympy python3-matplotlib  # the Python module (docs/python.md), for /usr/bin/python3
  python3-h5py  # reading ensembles from Python (docs/ensembles.md)
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  sudo_cmd=()
  [ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
  echo "installing: ${missing[*]}" >&2
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
