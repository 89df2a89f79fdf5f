#!/usr/bin/env bash
# Installs what sheardiff needs from Debian packages (only what is missing), then
# configures and builds a Release tree in build/. Idempotent: a second run on a
# machine that already has everything does no download and an incremental build.
set -euo pipefail
cd "$(dirname "$0")/.."

PKGS=(build-essential cmake ninja-build pkg-config
      libeigen3-dev libnanoflann-dev libhdf5-dev libtomlplusplus-dev libcli11-dev
      libfmt-dev nlohmann-json3-dev libgtest-dev libgmock-dev libbenchmark-dev
      libsuitesparse-dev libopenblas0-pthread
      zlib1g-dev  # crc32 of checkpoints
      strace      # the ctest run_dir_final_phase_kill (tests/cli/final_phase_kill.sh)
      clang-14 libclang-rt-14-dev  # libFuzzer for the ctest fuzz_config_smoke (tests/fuzz/)
      python3 python3-numpy python3-scipy python3-matplotlib python3-h5py
      python3-gsd  # the GSD export (tools/h5md_to_gsd.py) and its ctest h5md_outside_readers
      python3-mdanalysis)  # reads the LAMMPS dump export (tools/h5md_to_lammps.py) in that ctest

missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}" >&2
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release ${SHEARDIFF_CMAKE_ARGS:-} >/dev/null
cmake --build build -j "$(nproc)"
