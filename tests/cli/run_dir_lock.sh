#!/usr/bin/env bash
# One writer per run directory (issue 16, finding 1): two `sheardiff run` processes started
# together on one DIR used to both proceed (one exited 0 with its summary over a trajectory the
# other had truncated). Now exactly one runs; the other, and any `run --resume`, `run
# --overwrite` or `analyse` of DIR while it runs, exits 2 naming the holder and changes nothing.
#
#   run_dir_lock.sh SHEARDIFF WORK_DIR
set -uo pipefail
bin=$(realpath "$1"); work=$2
rm -rf "$work"; mkdir -p "$work"; cd "$work" || exit 1
fail() { echo "FAIL: $*"; exit 1; }

cat > run.toml <<'TOML'
[scene]
type = "simple_shear"
[particles]
N = 200
[run]
strain = 1.5
[output]
frame_strain = 0.01
checkpoint_strain = 0.1
[analysis]
msd_window_lo = 0.2
msd_window_hi = 0.6
reference_times = 20
TOML

# Both started at once: the lock decides, not the timing of the first write.
"$bin" run run.toml --out d > a.out 2> a.err & pa=$!
"$bin" run run.toml --out d > b.out 2> b.err & pb=$!
# The loser is refused at once; the winner runs for a few seconds.
for _ in $(seq 100); do
  grep -q "is in use by" a.err b.err 2> /dev/null && break
  sleep 0.05
done
if grep -q "is in use by" a.err; then winner=$pb loser=a; else winner=$pa loser=b; fi
grep -q "is in use by process $winner " $loser.err ||
  fail "the refused run does not name the holder (pid $winner): $(cat a.err b.err)"

# While the winner runs, every other command on DIR is refused and changes nothing.
for _ in $(seq 200); do
  grep -qs '^===' d/run.log && break
  sleep 0.05
done
kill -0 "$winner" 2> /dev/null || fail "the run finished before the concurrent commands (too fast)"
headers=$(grep -c '^===' d/run.log)
for cmd in "run run.toml --resume d" "run run.toml --out d --overwrite" "analyse d"; do
  rc=0; "$bin" $cmd > other.out 2> other.err || rc=$?
  [ "$rc" = 2 ] || fail "'sheardiff $cmd' during the run: exit $rc, expected 2: $(cat other.err)"
  grep -q "is in use by process $winner " other.err || fail "'sheardiff $cmd': $(cat other.err)"
done
[ "$(grep -c '^===' d/run.log)" = "$headers" ] || fail "a refused command wrote to run.log"

wait "$pa"; ra=$?
wait "$pb"; rb=$?
[ "$(printf '%s\n' "$ra" "$rb" | sort | tr '\n' ' ')" = "0 2 " ] ||
  fail "exit codes $ra and $rb, expected one 0 and one 2: $(cat a.err b.err)"
[ "$(grep -c '^===' d/run.log)" = 1 ] || fail "run.log has more than one writer: $(cat d/run.log)"
# The winner's results are whole: its trajectory reads back and agrees with its summary.
"$bin" analyse d > analyse.out 2> analyse.err || fail "analyse of the finished run: $(cat analyse.err)"
echo "run_dir_lock: one of two concurrent runs ran (exit $ra / $rb); the other and resume," \
  "overwrite and analyse during it were refused naming pid $winner"
