#!/usr/bin/env bash
# Progress and --quiet (issue 17, part 3). Before: progress lines off a terminal had no time
# stamp, `run` wrote its ETA "27 s" and `sweep` "1m13s", there was no --quiet, and on a terminal
# the live progress line never showed (stderr was a pipe into run.log by then). Now:
#   - off a terminal: lines "2025-03-01T14:07:09Z  strain ... ETA 3m13s" (ISO 8601 UTC), every
#     --progress-every seconds, the same lines in DIR/run.log;
#   - on a terminal (a pty from `script`): a live line redrawn with '\r', not logged; run.log
#     gets the timestamped lines;
#   - --quiet: no progress anywhere but run.log, the result's first line on stdout, the rest
#     of the result in run.log, errors still on stderr;
#   - sweep: its pool's lines timestamped off a terminal with the same ETA format, none with
#     --quiet, whose output is the one result line.
#
#   progress.sh SHEARDIFF WORK_DIR
set -uo pipefail
bin=$(realpath "$1"); work=$2
rm -rf "$work"; mkdir -p "$work"; cd "$work" || exit 1
fail() { echo "FAIL: $*"; exit 1; }
iso='[0-9]{4}-[0-9]{2}-[0-9]{2}T[0-9]{2}:[0-9]{2}:[0-9]{2}Z'
eta='ETA ([0-9]+h[0-9]{2}m|[0-9]+m[0-9]{2}s|[0-9]+s|\?)'
line_re="^$iso  strain [0-9.e+-]+ / [0-9.e+-]+  steps [0-9]+  [0-9]+ steps/s  $eta\$"

# A run of one to a few seconds.
cat > run.toml <<'TOML'
[scene]
type = "simple_shear"
[particles]
N = 60
phi_init = 0.7
[flow]
J = 3e-2
[contact]
ktilde = 1e3
[run]
strain = 6.0
[analysis]
diffusion = false
[output]
frame_strain = 0.05
TOML

# Off a terminal.
"$bin" run run.toml --out plain --progress-every 0.1 > plain.out 2> plain.err ||
  fail "run: $(cat plain.err)"
n=$(grep -cE "$line_re" plain.err)
[ "$n" -ge 2 ] || fail "fewer than 2 timestamped progress lines on stderr: $(cat plain.err)"
grep -vE "$line_re" plain.err | grep -q . && fail "other lines on stderr: $(grep -vE "$line_re" plain.err)"
grep -q $'\r' plain.err && fail "a live line ('\\r') off a terminal"
[ "$(grep -cE "$line_re" plain/run.log)" = "$n" ] || fail "run.log lacks the progress lines"
grep -q "^  shear stress" plain.out || fail "the result's second line: $(cat plain.out)"
echo "ok: $n timestamped progress lines off a terminal, in run.log too"

# --quiet off a terminal.
"$bin" run run.toml --out quiet --quiet --progress-every 0.1 > quiet.out 2> quiet.err ||
  fail "run --quiet: $(cat quiet.err)"
[ -s quiet.err ] && fail "run --quiet printed on stderr: $(cat quiet.err)"
[ "$(wc -l < quiet.out)" = 1 ] || fail "run --quiet: not one line on stdout: $(cat quiet.out)"
grep -q "^quiet: strain 6" quiet.out || fail "run --quiet: the result line: $(cat quiet.out)"
[ "$(grep -cE "$line_re" quiet/run.log)" -ge 2 ] || fail "run --quiet: run.log lacks progress"
grep -q "^quiet: strain 6" quiet/run.log && grep -q "^  shear stress" quiet/run.log ||
  fail "run --quiet: run.log lacks the result: $(cat quiet/run.log)"
# Errors are still printed.
rc=0; "$bin" run run.toml --out quiet --quiet > q2.out 2> q2.err || rc=$?
[ "$rc" = 2 ] && grep -q "^error: quiet holds a finished run" q2.err ||
  fail "run --quiet on a finished run: exit $rc, $(cat q2.err)"
echo "ok: --quiet"

# On a terminal: a pty from util-linux's script.
if script -qec true /dev/null > /dev/null 2>&1; then
  script -qec "'$bin' run run.toml --out tty --progress-every 0.1" /dev/null > tty.txt ||
    fail "run on a terminal: $(cat tty.txt)"
  tr '\r' '\n' < tty.txt | grep -qE "^strain [0-9.e+-]+ / [0-9.e+-]+  steps [0-9]+  [0-9]+ steps/s  $eta *\$" ||
    fail "no live progress line on the terminal: $(cat -A tty.txt | head -5)"
  grep -qE "$iso  strain" tty.txt && fail "timestamped lines on a terminal: $(cat -A tty.txt | head -5)"
  grep -q $'\r' tty/run.log && fail "the live line was logged: $(cat -A tty/run.log)"
  [ "$(grep -cE "$line_re" tty/run.log)" -ge 2 ] || fail "run.log of a terminal run lacks progress"
  script -qec "'$bin' run run.toml --out ttyq --quiet" /dev/null > ttyq.txt ||
    fail "run --quiet on a terminal: $(cat ttyq.txt)"
  [ "$(tr -d '\r' < ttyq.txt)" = "$(cat ttyq/run.log | grep '^ttyq: strain')" ] ||
    fail "run --quiet on a terminal printed more than its result line: $(cat -A ttyq.txt)"
  echo "ok: a live line on a terminal, not logged"
else
  echo "skipped: the terminal part (util-linux's script cannot open a pty here)"
fi

# A resumed run's rate counts the steps taken since it resumed (it used to divide every step
# of the run by this process's time: 20x too fast a second after resuming a 2 s run).
"$bin" run run.toml --out resumed --set run.strain=1000 --progress-every 0.2 2> r1.err &
pid=$!; sleep 2; kill -INT $pid; wait $pid
[ -f resumed/checkpoint.bin ] || fail "no checkpoint after SIGINT: $(cat r1.err)"
"$bin" run run.toml --resume resumed --set run.strain=1000 --progress-every 0.1 2> r2.err &
pid=$!; sleep 1.5; kill -INT $pid; wait $pid
rate() { grep -oE '[0-9]+ steps/s' "$1" | awk '{print $1}' | sed -n "$2"; }
before=$(rate r1.err '$p'); after=$(rate r2.err 1p)
[ -n "$before" ] && [ -n "$after" ] || fail "no rates: $(cat r1.err r2.err)"
awk -v a="$after" -v b="$before" 'BEGIN { exit !(a < 6 * b) }' ||
  fail "resumed rate $after steps/s against $before before the stop"
echo "ok: a resumed run's rate ($after steps/s) is its own (before the stop: $before)"

# sweep: timestamps and the ETA format; --quiet.
cat > base.toml <<'TOML'
[scene]
type = "simple_shear"
[particles]
N = 40
phi_init = 0.75
[run]
strain = 0.3
[output]
frame_strain = 0.05
[analysis]
diffusion = false
TOML
printf '[sweep]\nbase = "base.toml"\njobs = 2\n[sweep.axes]\n"flow.J" = [0.1, 0.03]\n' > sweep.toml
"$bin" sweep sweep.toml --out s > s.out 2> s.err || fail "sweep: $(cat s.err)"
grep -qE "^$iso  sweep: 2/2 done .* elapsed, $eta\$" s.err || fail "sweep progress lines: $(cat s.err)"
grep -vE "^$iso  sweep: " s.err | grep -q . && fail "untimestamped sweep lines: $(cat s.err)"
"$bin" sweep sweep.toml --out sq --quiet > sq.out 2> sq.err || fail "sweep --quiet: $(cat sq.err)"
[ -s sq.err ] && fail "sweep --quiet printed on stderr: $(cat sq.err)"
[ "$(wc -l < sq.out)" = 1 ] && grep -q "^sq: 2/2 points finished" sq.out ||
  fail "sweep --quiet: $(cat sq.out)"
echo "ok: sweep progress timestamped, --quiet"
