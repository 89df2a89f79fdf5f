#!/usr/bin/env bash
# Sweeps (issue 16, findings 6 and 7): duplicate points ("flow.J" = [0.1, 1e-1], seeds [1, 1])
# used to race in one directory on 2 workers, the sweep reported a failure but exited 0, and
# sweep.csv and fits.json counted the point twice; a directory as the base config ran the
# default scene. Now both are refused by `check` and by `sweep` (exit 2) before any point
# starts, and a sweep with a failed point exits 3.
#
#   sweep_duplicates.sh SHEARDIFF WORK_DIR
set -uo pipefail
bin=$(realpath "$1"); work=$2
rm -rf "$work"; mkdir -p "$work"; cd "$work" || exit 1
fail() { echo "FAIL: $*"; exit 1; }
expect() {  # expect CODE TEXT -- ARGS...
  local code=$1 text=$2 rc=0; shift 3
  "$bin" "$@" > cmd.out 2> cmd.err || rc=$?
  [ "$rc" = "$code" ] || fail "'sheardiff $*': exit $rc, expected $code: $(cat cmd.out cmd.err)"
  grep -qF -- "$text" cmd.err || fail "'sheardiff $*': stderr lacks '$text': $(cat cmd.err)"
}

cat > base.toml <<'TOML'
[scene]
type = "simple_shear"
[particles]
N = 40
phi_init = 0.75
[run]
strain = 0.2
[output]
frame_strain = 0.01
[analysis]
diffusion = false
TOML
sweep() {  # sweep FILE AXES...: a sweep file over base.toml
  local file=$1; shift
  { printf '[sweep]\nbase = "%s"\njobs = 2\n[sweep.axes]\n' "${BASE:-base.toml}"; printf '%s\n' "$@"; } > "$file"
}

sweep j.toml '"flow.J" = [0.1, 1e-1]'
msg='sweep.axes."flow.J": entries 1 and 2 of the list are the same value (0.1)'
expect 2 "$msg" -- check j.toml
expect 2 "$msg" -- sweep j.toml --out out_j --jobs 2
[ -e out_j/points ] && fail "the refused sweep started points"

sweep seeds.toml '"flow.J" = [0.1, 0.05]' '"run.seed" = [1, 1]'
expect 2 'sweep.axes."run.seed": entries 1 and 2 of the list are the same value (1)' -- sweep seeds.toml --out out_s --jobs 2
[ -e out_s/points ] && fail "the refused sweep started points"

# A base config that is a directory.
mkdir base_dir
BASE=base_dir sweep dir.toml '"flow.J" = [0.1]'
expect 2 'base_dir is a directory, not a config file' -- check dir.toml

# A failed point makes the sweep fail (exit 3), the others still collected.
sweep failing.toml '"flow.J" = [0.1]' '"health.max_overlap" = [0.1, 1e-9]'
expect 3 "sweep: 1 of 2 points not finished (1 failed in this sweep" -- sweep failing.toml --out out_f --jobs 2
grep -q 'run health' out_f/logs/*.failed || fail "no .failed marker names the health stop"
echo "sweep_duplicates: duplicate axis values and a directory as base refused (exit 2); a failed point exits 3"
