#!/usr/bin/env bash
# What a user watching a channel run sees (issue 15): the progress lines carry the migration's
# state (the last sample interval's centre distance and pressure-gradient ratio, and whether it
# is steady yet), and the result names the channel's own quantities (steady time, u_c, phi_c,
# u_p, Q_p, G / G0) instead of the pressure cell's stresses in units of P, which mean nothing in a
# channel driven at fixed flux.
#
#   channel_result.sh SHEARDIFF CONFIGS_DIR WORK_DIR
set -uo pipefail
bin=$(realpath "$1"); configs=$(realpath "$2"); work=$3
rm -rf "$work"; mkdir -p "$work"; cd "$work" || exit 1
fail() { echo "FAIL: $*"; exit 1; }

"$bin" run "$configs/channel/A.toml" --out run --set run.strain=120 \
  --set channel.sample_interval=20 --progress-every 0.2 > out.txt 2> err.txt ||
  fail "run failed: $(cat err.txt)"
grep -Eq 'centre distance [0-9.]+ d  G/G0 [0-9.]+  (not yet steady|steady from [0-9.e+]+)$' run/run.log ||
  fail "no migration state on the progress lines: $(tail -n 3 run/run.log)"
grep -q 'migration NOT steady: averaged from t = 60 a/<u>' out.txt ||
  fail "the result does not say the run is not steady: $(cat out.txt)"
grep -Eq 'u_c = [0-9.]+ <u>, phi_c = [0-9.]+, u_p = [0-9.]+ <u>, Q_p = [0-9.]+, pressure gradient [0-9.]+ x Poiseuille.s \(two_way coupling\)' out.txt ||
  fail "no Table 1 columns in the result: $(cat out.txt)"
grep -q 'particle pressure' out.txt && fail "the result prints the pressure cell's stresses"
echo "ok"
