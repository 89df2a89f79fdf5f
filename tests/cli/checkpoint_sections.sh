#!/usr/bin/env bash
# tools/checkpoint_sections.py on a real end state (final_state.bin is a checkpoint): it finds
# the sections a pressure-cell run writes, in the order the run writes them, and their sizes add
# up to the file's.
#
#   checkpoint_sections.sh SHEARDIFF PROJECT_DIR WORK_DIR
set -uo pipefail
bin=$(realpath "$1"); root=$(realpath "$2"); work=$3
rm -rf "$work"; mkdir -p "$work"; cd "$work" || exit 1
fail() { echo "FAIL: $*"; exit 1; }

"$bin" run "$root/configs/quick.toml" --out run --set run.strain=0.2 --set steady.window=0.1 \
  --set output.frame_strain=0.01 -q > out.txt 2> err.txt || fail "run failed: $(cat err.txt)"
/usr/bin/python3 "$root/tools/checkpoint_sections.py" run/final_state.bin > sections.txt ||
  fail "the tool failed: $(cat sections.txt)"
order=$(awk 'NR > 2 { print $3 }' sections.txt | grep -E "^(dynamics|integrator|rheology|pressure_cell)$" | tr '\n' ' ')
[ "$order" = "dynamics integrator rheology pressure_cell " ] ||
  fail "sections not found in the run's order: '$order'; $(cat sections.txt)"
size=$(stat -c %s run/final_state.bin)
total=$(awk 'NR > 2 { s += $2 } END { printf "%.0f", s * 1e6 }' sections.txt)
# Sizes are printed to 1 kB: their sum is the file's within 1 kB per section.
lines=$(awk 'NR > 2' sections.txt | wc -l)
[ $(( total > size ? total - size : size - total )) -le $(( lines * 1000 )) ] ||
  fail "sections add up to $total bytes, the file has $size"
# A section whose first byte is a lowercase letter: its tag is still read by its length (the
# tool once read the letters after a name greedily and lost such a tag, "dynamicsf").
/usr/bin/python3 - "$root/tools" <<'PY' || fail "a tag followed by a letter was not found"
import struct, sys
sys.path.insert(0, sys.argv[1])
import checkpoint_sections
tag = lambda name: struct.pack("<Q", len(name)) + name
data = b"header" + tag(b"dynamics") + b"f" * 10 + tag(b"integrator") + b"\x01" * 4
found = [name for _, name in checkpoint_sections.sections(data)]
assert found == ["dynamics", "integrator"], found
PY
echo "ok"
