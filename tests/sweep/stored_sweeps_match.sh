#!/usr/bin/env bash
# Every committed sweep store (a sweep file's `results` folder under results/) still matches its
# sweep file under the current code: `sweep --collect` into an empty folder compares each stored
# point's config.toml with the point the sweep file now makes, and refuses a difference. A
# changed default reaches every stored record that names the key; a change that makes the
# sweeps refuse their own results must be caught here, not on the next machine that resumes one.
# Usage: stored_sweeps_match.sh SHEARDIFF_BIN REPO_DIR WORK_DIR
set -uo pipefail
bin=$(realpath "$1"); repo=$(realpath "$2"); work=$3
rm -rf "$work"; mkdir -p "$work"
failed=0; checked=0
for file in "$repo"/configs/*.toml "$repo"/bench/*.toml; do
  grep -q '^results *=' "$file" || continue
  name=$(basename "$file" .toml)
  out="$work/$name"
  rc=0
  (cd "$(dirname "$file")" && "$bin" sweep "$(basename "$file")" --out "$out" --collect -q) \
    > "$work/$name.log" 2>&1 || rc=$?
  # A sweep file whose results are not stored yet (nothing run) has nothing to match.
  grep -q "no sweep there" "$work/$name.log" && continue
  checked=$((checked + 1))
  # 0: every point stored; 3: some not yet run (a sweep in progress). Anything else is a refusal.
  if [ "$rc" != 0 ] && [ "$rc" != 3 ]; then
    echo "FAIL  $name (exit $rc):"; tail -n 3 "$work/$name.log"; failed=$((failed + 1))
  elif grep -q "another configuration" "$work/$name.log"; then
    echo "FAIL  $name:"; grep "another configuration" "$work/$name.log" | head -n 2; failed=$((failed + 1))
  fi
done
echo "$checked sweep files with stored results checked, $failed refused"
[ "$checked" -gt 30 ] && [ "$failed" = 0 ]
