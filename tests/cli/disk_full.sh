#!/usr/bin/env bash
# A full disk (issue 16, finding 4) ended in a segfault at HDF5's teardown (exit 139) or an
# endless HDF5 close loop, its cause buried under thousands of HDF5-DIAG lines, partial .tmp
# files left. Here one run is made on tmpfs mounts of several sizes, so that the disk fills at
# different moments (a trajectory frame, a checkpoint, the end of the run). Each must end with
# exit 1 and one line naming the file and "No space left on device", no HDF5 stack on the
# terminal, no FILE.tmp, its last checkpoint intact: once the mount is enlarged, --resume
# completes it to the summary of a run that never failed (the clock aside). Skipped (77) where
# tmpfs cannot be mounted.
#
#   disk_full.sh SHEARDIFF WORK_DIR
set -uo pipefail
bin=$(realpath "$1"); work=$(realpath -m "$2")
umount -q "$work/mnt" 2> /dev/null
rm -rf "$work"; mkdir -p "$work/mnt"; cd "$work" || exit 1
mount -t tmpfs -o size=1m tmpfs mnt 2> /dev/null || { echo "SKIP: cannot mount tmpfs here"; exit 77; }
trap 'cd /; umount -q "$work/mnt"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
py=/usr/bin/python3

cat > run.toml <<'TOML'
[scene]
type = "simple_shear"
[particles]
N = 100
[run]
strain = 1.0
[output]
frame_strain = 0.004
checkpoint_strain = 0.4
[analysis]
msd_window_lo = 0.2
msd_window_hi = 0.5
sample_strain = 0.004
TOML
"$bin" run run.toml --out ref > /dev/null 2>&1 || fail "reference run"
full_kb=$(du -sk --apparent-size ref | cut -f1)

# One run in a tmpfs of SIZE kB: 0 if it fits; 1 if it met the full disk as it should, then
# resumed to the reference once there was room again (WHAT: the file it named).
try_size() {
  local size_kb=$1 rc=0
  umount -q mnt && mount -t tmpfs -o size=${size_kb}k tmpfs mnt || fail "mount ${size_kb}k"
  "$bin" run run.toml --out mnt/r > out.txt 2> err.txt || rc=$?
  [ "$rc" = 0 ] && return 0
  [ "$rc" = 1 ] || fail "${size_kb}k: exit $rc, expected 1: $(head -3 err.txt)"
  grep -q "HDF5" err.txt && fail "${size_kb}k: HDF5 diagnostics on the terminal: $(head -3 err.txt)"
  [ "$(grep -c . err.txt)" = 1 ] || fail "${size_kb}k: more than one line on stderr: $(cat err.txt)"
  grep -q "^error: .*mnt/r/[a-z0-9._]*.*: No space left on device" err.txt ||
    fail "${size_kb}k: the message lacks the file or the reason: $(cat err.txt)"
  compgen -G "mnt/r/*.tmp" > /dev/null && fail "${size_kb}k: partial files left: $(ls mnt/r)"
  [ -e mnt/r/summary.json ] && fail "${size_kb}k: a failed run looks finished"
  what=$(sed -n 's#^error: [^/]*mnt/r/\([a-z0-9._]*\).*#\1#p' err.txt | head -1)
  # Room again: the run continues from its last checkpoint (or from 0 if it had none).
  mount -o remount,size=64m mnt || fail "remount"
  "$bin" run run.toml --resume mnt/r > out.txt 2> err.txt || fail "${size_kb}k: resume: $(cat err.txt)"
  "$py" - ref/summary.json mnt/r/summary.json <<'PY' || fail "${size_kb}k: the resumed run differs"
import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:3])
for k in ("wall_seconds", "ms_per_step", "started", "finished"):  # the clock
    a.pop(k, None); b.pop(k, None)
diff = sorted(k for k in set(a) | set(b) if a.get(k) != b.get(k))
sys.exit(f"summaries differ in {diff}" if diff else 0)
PY
  return 1
}

report=""
for percent in 15 50 85; do
  size_kb=$((full_kb * percent / 100 + 4))
  try_size $size_kb && fail "${size_kb}k: the run fitted in $percent% of its size"
  report+=" ${size_kb}k:$what"
done
# The largest mount the run does not fit in: the disk is full at its very last writes.
lo=$((full_kb * 85 / 100)) hi=$((full_kb * 3))
try_size $hi || fail "the run does not fit in ${hi}k"
while ((hi - lo > 4)); do
  mid=$(((lo + hi) / 2))
  if try_size $mid; then hi=$mid; else lo=$mid last=$what; fi
done
report+=" ${lo}k:$last (the largest that fails; ${hi}k fits)"
# `analyse` meeting the full disk as it writes analysis.h5 (issue 35, case 8, left a 0-byte
# analysis.h5.tmp): exit 1 naming the file and the reason, no FILE.tmp, summary.json as it was.
umount -q mnt && mount -t tmpfs -o size=4m tmpfs mnt || fail "mount for analyse"
cp -r ref mnt/a && rm mnt/a/analysis.h5 || fail "copy for analyse"
# Fill the mount, then free two pages: the log's lines fit, the 14 kB analysis.h5 does not.
dd if=/dev/zero of=mnt/fill bs=4k > /dev/null 2>&1
truncate -s -8k mnt/fill || fail "truncate"
rc=0
"$bin" analyse mnt/a > out.txt 2> err.txt || rc=$?
[ "$rc" = 1 ] || fail "analyse on a full disk: exit $rc, expected 1: $(head -3 err.txt)"
grep -q "^error: .*mnt/a/analysis.h5.*: No space left on device" err.txt ||
  fail "analyse on a full disk: the message lacks the file or the reason: $(cat err.txt)"
compgen -G "mnt/a/*.tmp" > /dev/null && fail "analyse on a full disk left partial files: $(ls mnt/a)"
cmp -s mnt/a/summary.json ref/summary.json || fail "analyse on a full disk changed summary.json"
report+="; analyse on a full disk: exit 1, no partial file"

echo "disk_full: a run of $full_kb kB on tmpfs mounts of size:file that met the full disk, each" \
  "then resumed to the reference:$report"
