#!/usr/bin/env bash
# The shipped quick sweep end to end on the local backend with 2 workers, then its results
# checked for shape and trends (check_fits.py). Usage: sweep_quick.sh SHEARDIFF_BIN REPO WORK
set -euo pipefail
bin=$(realpath "$1"); repo=$(realpath "$2"); work=$3
rm -rf "$work"; mkdir -p "$work"
# The machinery and the trends, not the steady state: the shipped quick sweep's few-strain
# windows at J >= 3e-2 are transients that its points report as "done, not stationary" and its fits
# leave out. Here the stationarity verdict is relaxed so that all four points are fitted; the
# verdict itself is tested by tests/unit/test_stationarity.cpp and
# PressureShear.DilatingWindowIsFlaggedNotStationary.
sed -e "s|^base = \"pressure_shear.toml\"|base = \"$repo/configs/pressure_shear.toml\"|" \
    -e '/^\[sweep.set\]/a "steady.drift_z" = 100.0\n"steady.bulk_load_tolerance" = 1.0' \
    "$repo/configs/sweep_quick.toml" > "$work/sweep_quick.toml"
"$bin" sweep "$work/sweep_quick.toml" --out "$work/out" --jobs 2
/usr/bin/python3 "$repo/tests/sweep/check_fits.py" "$work/out" 4
