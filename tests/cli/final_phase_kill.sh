#!/usr/bin/env bash
# Every instant of a run's end is resumable (issue 16, finding 3). A pressure-cell run killed
# after its profiles table was written and before summary.json could never be resumed
# ("object already exists", exit 3, after recomputing to its end). Here a run is killed (strace
# fault injection, SIGKILL) at its summary.json rename; that state must resume. Then its resume
# is itself killed at every write-like system call it makes (pwrite64, write, fsync, ftruncate,
# rename, unlink: the end of the run, cutting the trajectory back, the logs), and each of those
# states must resume to exit 0 with a summary equal to an uninterrupted run's (the clock aside)
# and nothing left behind. Skipped (77) where strace is missing or may not trace.
#
#   final_phase_kill.sh SHEARDIFF WORK_DIR
set -uo pipefail
bin=$(realpath "$1"); work=$2
rm -rf "$work"; mkdir -p "$work"; cd "$work" || exit 1
fail() { echo "FAIL: $*"; exit 1; }
command -v strace > /dev/null || { echo "SKIP: strace is not installed"; exit 77; }
strace -f -qq -o /dev/null true 2> /dev/null || { echo "SKIP: strace cannot trace here"; exit 77; }
py=/usr/bin/python3
# Two summaries equal but for the clock.
same_summary() {
  "$py" - "$1" "$2" <<'PY'
import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:3])
for k in ("wall_seconds", "ms_per_step", "started", "finished"):  # the clock
    a.pop(k, None); b.pop(k, None)
diff = sorted(k for k in set(a) | set(b) if a.get(k) != b.get(k))
sys.exit(f"summaries differ in {diff}" if diff else 0)
PY
}
resumed_ok() {  # resumed_ok DIR WHAT: DIR resumes to the reference
  local rc=0
  "$bin" run run.toml --resume "$1" > resume.out 2> resume.err || rc=$?
  [ "$rc" = 0 ] || fail "$2: resume exited $rc: $(cat resume.err)"
  same_summary ref/summary.json "$1/summary.json" || fail "$2: the resumed run differs"
  [ -e "$1/checkpoint.bin" ] && fail "$2: checkpoint.bin left after the resume"
  compgen -G "$1/*.tmp" > /dev/null && fail "$2: partial files left: $(ls "$1")"
  return 0
}

# A pressure cell that reaches steady state (profiles written at the end) with a checkpoint at
# every frame, the last one at its last step.
cat > run.toml <<'TOML'
[scene]
type = "pressure_shear"
[particles]
N = 60
phi_init = 0.72
[flow]
J = 3e-2
[contact]
ktilde = 1e3
[run]
strain = 1.2
seed = 4
[steady]
window = 0.3
measure_strain = 0.3
[analysis]
msd_window_lo = 0.05
msd_window_hi = 0.15
reference_times = 20
vacf_max_lag = 0.1
[output]
frame_strain = 0.02
checkpoint_strain = 0.02
TOML
"$bin" run run.toml --out ref > ref.out 2>&1 || fail "reference run: $(cat ref.out)"
grep -q '"steady": true' ref/summary.json || fail "the reference run did not reach steady state"

# The state of finding 3: killed at the rename of summary.json, profiles already written.
strace -f -qq -o trace.txt -e trace=rename "$bin" run run.toml --out probe > /dev/null 2>&1
summary_rename=$(grep 'rename(' trace.txt | grep -n 'summary.json.tmp' | cut -d: -f1)
[ -n "$summary_rename" ] || fail "no summary.json rename in the trace"
# (In a subshell that waits: bash would report each kill on stderr.)
(strace -f -qq -o /dev/null -e trace=rename -e inject=rename:signal=KILL:when="$summary_rename" \
  "$bin" run run.toml --out template > /dev/null 2>&1; true) 2> /dev/null
[ -e template/summary.json ] && fail "the kill at the summary rename did not land"
[ -e template/checkpoint.bin ] || fail "no checkpoint before the end"
cp -a template killed_at_summary
resumed_ok killed_at_summary "killed at the summary.json rename"

# Its resume, killed at each of its write-like calls in turn.
calls=(pwrite64 write fsync ftruncate rename unlink)
cp -a template probe_resume
strace -f -qq -o resume_trace.txt -e trace="$(IFS=,; echo "${calls[*]}")" \
  "$bin" run run.toml --resume probe_resume > /dev/null 2>&1 || fail "traced resume"
calls_seen=0 kills=0
for call in "${calls[@]}"; do
  n=$(grep -c " $call(" resume_trace.txt || true)
  for ((k = 1; k <= n; ++k)); do
    rm -rf w; cp -a template w
    rc=$( (strace -f -qq -o /dev/null -e trace="$call" -e inject="$call":signal=KILL:when="$k" \
      "$bin" run run.toml --resume w > /dev/null 2>&1; echo $?) 2> /dev/null)
    [ "$rc" = 137 ] && kills=$((kills + 1))
    resumed_ok w "killed at $call #$k of the resume"
    calls_seen=$((calls_seen + 1))
  done
done
# The log thread's writes are counted with the main thread's: a few injections find no call.
[ "$kills" -ge $((calls_seen * 3 / 4)) ] || fail "only $kills of $calls_seen kills landed"
echo "final_phase_kill: killed at the summary.json rename, then its resume killed at $kills of" \
  "its $calls_seen write-like calls: every state resumed to the uninterrupted run's summary"
