#!/usr/bin/env bash
# Exit codes exactly as README's list ("Exit codes"): usage errors of the command line
# exited 105-114 (CLI11's own codes), I/O errors 3 (documented 1), a damaged summary.json 1
# without its name. Each case: the exit code and a fragment of stderr (or stdout for --help).
#
#   exit_codes.sh SHEARDIFF WORK_DIR
set -uo pipefail
bin=$(realpath "$1"); work=$2
rm -rf "$work"; mkdir -p "$work"; cd "$work" || exit 1
failed=0
expect() {  # expect CODE TEXT -- ARGS...
  local code=$1 text=$2 rc=0; shift 3
  "$bin" "$@" > cmd.out 2> cmd.err || rc=$?
  if [ "$rc" != "$code" ] || ! grep -qF -- "$text" cmd.out cmd.err; then
    echo "FAIL: 'sheardiff $*': exit $rc (expected $code), output: $(cat cmd.out cmd.err | head -5)"
    failed=1
  else
    echo "ok: exit $rc: sheardiff $*"
  fi
}

cat > run.toml <<'TOML'
[scene]
type = "simple_shear"
[particles]
N = 30
[run]
strain = 0.05
[output]
frame_strain = 0.01
TOML

# 0: help and a finished run.
expect 0 "Usage:" -- --help
expect 0 "Usage:" -- run --help
expect 0 "strain 0.05" -- run run.toml --out ok

# 2: the command line (CLI11's usage errors), refused before anything is written.
expect 2 "A subcommand is required" --
expect 2 "config is required" -- run
expect 2 "The following argument was not expected: --bogus" -- run run.toml --bogus
expect 2 "--out excludes --resume" -- run run.toml --out a --resume ok
expect 2 "--resume excludes --overwrite" -- run run.toml --resume ok --overwrite
expect 2 "--jobs: Value 0 not in range" -- sweep s.toml --out o --jobs 0
expect 2 "--point: Value abc not in range" -- sweep s.toml --out o --point abc
expect 2 "--backend: pbs not in {local,slurm}" -- sweep s.toml --out o --backend pbs
# Issue 35, case 12: nan seconds turned progress off, "" exited 1, / wrote a run into the root.
expect 2 "--progress-every: nan: must be a finite number > 0" -- run run.toml --out a --progress-every nan
expect 2 "--progress-every: inf: must be a finite number > 0" -- run run.toml --out a --progress-every inf
expect 2 "--out: an empty path" -- run run.toml --out ""
expect 2 "--out: / is a filesystem root" -- run run.toml --out /
expect 2 "--out: / is a filesystem root" -- sweep s.toml --out /
expect 2 "--out: an empty path" -- fit ok --out ""
# A folder of someone else's files is not a run directory.
mkdir mine && echo "notes" > mine/notes.txt
expect 2 "--out mine: the folder holds other files (notes.txt) and no run" -- run run.toml --out mine
expect 2 "--out mine: the folder holds other files (notes.txt) and no run" -- run run.toml --out mine --overwrite
[ "$(ls mine)" = notes.txt ] || { echo "FAIL: a refused run wrote into mine/: $(ls mine)"; failed=1; }
[ -e a ] || [ -e o ] && { echo "FAIL: a refused command created its folder"; failed=1; }

# 2: a damaged summary.json is an invalid input file, named.
mkdir bad && cp ok/config.toml ok/trajectory.h5 bad/ && echo '{bad' > bad/summary.json
expect 2 "bad/summary.json: not a valid summary" -- analyse bad

# 1: I/O, with the file and the operating system's reason.
touch plain
expect 1 "cannot create the directory plain/out: Not a directory" -- run run.toml --out plain/out
expect 1 "cannot create the directory /proc/sheardiff_exit_codes" -- run run.toml --out /proc/sheardiff_exit_codes

exit $failed
