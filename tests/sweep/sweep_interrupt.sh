#!/usr/bin/env bash
# A sweep killed mid-run (SIGKILL to its whole process group, as a cluster's job killer or a
# closed terminal does) and run again must finish without redoing finished points, keep their
# files and sweep.csv rows unchanged, and never report a half-finished point as done.
# Usage: sweep_interrupt.sh SHEARDIFF_BIN REPO_DIR WORK_DIR
set -euo pipefail
bin=$(realpath "$1"); repo=$(realpath "$2"); work=$3
rm -rf "$work"; mkdir -p "$work"; cd "$work"
# A failure names its line and shows what the sweeps printed (it once failed under a loaded
# machine with nothing to read).
trap 'rc=$?; echo "FAILED (exit $rc) at line $LINENO"; for f in first concurrent collect second; do [ -f $f.log ] && { echo "--- $f.log"; tail -n 15 $f.log; }; done; ls out/points 2>/dev/null' ERR
cat > tiny.toml <<TOML
[sweep]
base = "$repo/configs/quick.toml"
jobs = 2
[sweep.set]
"particles.N" = 60
"run.strain" = 3.0
"steady.window" = 0.5
"steady.measure_strain" = 1.0
"output.checkpoint_strain" = 0.2
# A machinery test: its 1-strain windows are transients; the stationarity verdict (tested in
# test_stationarity.cpp) is relaxed so that every point counts as done.
"steady.drift_z" = 100.0
"steady.bulk_load_tolerance" = 1.0
[sweep.axes]
"flow.J" = [0.1, 0.05, 0.02, 0.01]
TOML

setsid "$bin" sweep tiny.toml --out out > first.log 2>&1 &
pgid=$!
for _ in $(seq 600); do  # up to 120 s for the first point to finish
  compgen -G "out/points/*/summary.json" > /dev/null && break
  sleep 0.2
done
compgen -G "out/points/*/summary.json" > /dev/null || { echo "no point finished"; cat first.log; exit 1; }
# A second sweep on the same folder while the first runs is refused (exit 2), touching nothing.
rc=0; "$bin" sweep tiny.toml --out out > concurrent.log 2>&1 || rc=$?
[ "$rc" = 2 ] && grep -q "already being run by another process" concurrent.log ||
  { echo "concurrent sweep: exit $rc"; cat concurrent.log; exit 1; }
kill -KILL -- -"$pgid"
wait "$pgid" 2>/dev/null || true

# What the killed sweep had finished, and its rows.
finished=$(cd out/points && ls -d */summary.json | xargs -n1 dirname)
rc=0; "$bin" sweep tiny.toml --out out --collect > collect.log 2>&1 || rc=$?
[ "$rc" = 3 ] || { echo "collect of an unfinished sweep: exit $rc, expected 3"; exit 1; }
grep -q ',"\?done' out/sweep.csv
rows() {  # a point's filled cells as key=value lines: the columns grow with later points' keys
  /usr/bin/python3 -c 'import csv,sys
for r in csv.DictReader(open("out/sweep.csv")):
    if r["point"] == sys.argv[1]:
        print("\n".join(f"{k}={v}" for k, v in sorted(r.items()) if v))' "$1"
}
for p in $finished; do
  sha256sum "out/points/$p/summary.json" "out/points/$p/trajectory.h5" >> before.sha
  rows "$p" >> before.rows
  wc -c < "out/logs/$p.log" >> before.logsize
done
# No unfinished point is reported as done.
n_done=$(grep -c '^[^,]*,"\?done' out/sweep.csv || true)
[ "$n_done" = "$(echo "$finished" | wc -w)" ] || { echo "done rows $n_done != finished points"; exit 1; }

"$bin" sweep tiny.toml --out out > second.log 2>&1
sha256sum -c --quiet before.sha                       # finished points untouched
for p in $finished; do rows "$p"; done | diff before.rows -   # same rows
for p in $finished; do wc -c < "out/logs/$p.log"; done | diff before.logsize - # not rerun
[ "$(grep -c '^[^,]*,"\?done' out/sweep.csv)" = 4 ] || { echo "not all points done"; cat second.log; exit 1; }
grep -q "before this start" second.log
# Every point's log holds its result as `run` prints it (issue 35, case 9: they were empty),
# and so does its run.log.
for d in out/points/*/; do
  p=$(basename "$d")
  grep -q "steps" "out/logs/$p.log" || { echo "out/logs/$p.log lacks the point's result"; exit 1; }
  grep -q "steps" "$d/run.log" || { echo "$d/run.log lacks the point's result"; exit 1; }
done

# Issue 35, case 6: a point whose lock another process holds (the worker of a pool that was
# killed alone lives on) was started again, failed (exit 3) and left a .failed marker behind.
# It is waited for instead; a stale marker of a finished point is removed.
mkdir -p out2/logs
first_point=$("$bin" check tiny.toml | sed -n 2p | tr -d ' ')
flock -n "out2/logs/$first_point.lock" -c "sleep 3" &
holder=$!
sleep 0.5
rc=0; "$bin" sweep tiny.toml --out out2 > orphan.log 2>&1 || rc=$?
wait "$holder" || true
[ "$rc" = 0 ] || { echo "sweep beside a running worker: exit $rc"; cat orphan.log; exit 1; }
grep -q "being run by other processes" orphan.log || { echo "no word of the other process"; cat orphan.log; exit 1; }
[ "$(grep -c '^[^,]*,"\?done' out2/sweep.csv)" = 4 ] || { echo "not all points done"; cat orphan.log; exit 1; }
compgen -G "out2/logs/*.failed" > /dev/null && { echo "failure markers left: $(ls out2/logs)"; exit 1; }
echo "an earlier failure" > "out2/logs/$first_point.failed"
"$bin" sweep tiny.toml --out out2 > again.log 2>&1
[ -e "out2/logs/$first_point.failed" ] && { echo "a stale failure marker of a finished point stayed"; exit 1; }

# A sweep started again resumes its part-run points before it begins fresh ones, whatever their
# cost: J = 0.1, the cheaper of two points, is stopped after its first checkpoint, and the sweep
# (one worker) must finish it before it begins J = 0.01.
sed 's/"flow.J" = \[0.1, 0.05, 0.02, 0.01\]/"flow.J" = [0.1, 0.01]/' tiny.toml > two.toml
grep -q '"flow.J" = \[0.1, 0.01\]' two.toml
for _ in 1 2 3 4 5; do  # a run that finishes before the stop lands is tried again
  rm -rf out3
  "$bin" sweep two.toml --out out3 --point 0 > part.log 2>&1 &
  pid=$!
  for _ in $(seq 500); do [ -e out3/points/J=0.1/checkpoint.bin ] && break; sleep 0.01; done
  kill -TERM "$pid" 2> /dev/null || true
  wait "$pid" 2> /dev/null || true
  [ -e out3/points/J=0.1/checkpoint.bin ] && [ ! -e out3/points/J=0.1/summary.json ] && break
done
[ -e out3/points/J=0.1/checkpoint.bin ] && [ ! -e out3/points/J=0.1/summary.json ] ||
  { echo "J=0.1 was not stopped part-way"; cat part.log; exit 1; }
"$bin" sweep two.toml --out out3 --jobs 1 > order.log 2>&1
[ -e out3/points/J=0.1/summary.json ] &&
  [ out3/points/J=0.1/summary.json -ot out3/points/J=0.01/summary.json ] ||
  { echo "the fresh J=0.01 was begun before the part-run J=0.1"; cat order.log; exit 1; }

echo "sweep_interrupt: killed after $(echo "$finished" | wc -w) finished point(s); resumed to 4/4 with them untouched"
