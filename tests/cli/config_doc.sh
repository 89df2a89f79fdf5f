#!/usr/bin/env bash
# `sheardiff config-doc` in a terminal (issue 17, part 3): it printed the Markdown table, with
# lines up to 309 characters. Now it prints a commented TOML file of the defaults, every line
# within 100 columns, that `sheardiff check` reads back to the defaults; `--markdown` prints the
# table docs/config.md is made from (ctest config_doc_up_to_date), with the same keys.
#
#   config_doc.sh SHEARDIFF WORK_DIR
set -uo pipefail
bin=$(realpath "$1"); work=$2
rm -rf "$work"; mkdir -p "$work"; cd "$work" || exit 1
fail() { echo "FAIL: $*"; exit 1; }
"$bin" config-doc > doc.toml || fail "config-doc exited $?"
"$bin" config-doc --markdown > doc.md || fail "config-doc --markdown exited $?"
/usr/bin/python3 - doc.toml doc.md <<'PY' || exit 1
import re, sys
text = open(sys.argv[1], encoding="utf-8").read().splitlines()
wide = [l for l in text if len(l) > 100]
if wide: sys.exit(f"FAIL: {len(wide)} lines over 100 columns, e.g. {wide[0]!r}")
keys = re.findall(r"^\| `([a-z_]+)\.([A-Za-z0-9_]+)` \|", open(sys.argv[2]).read(), re.M)
section, found = None, set()
for l in text:
    m = re.match(r"^\[(\w+)\]$", l)
    if m: section = m.group(1)
    m = re.match(r"^(\w+) = ", l)
    if m: found.add((section, m.group(1)))
missing = [f"{s}.{k}" for s, k in keys if (s, k) not in found]
if missing or len(found) != len(keys): sys.exit(f"FAIL: keys differ from the table: {missing}")
print(f"ok: {len(text)} lines within 100 columns, the {len(keys)} keys of the table")
PY
# It is a TOML file of the defaults (scene.type given): check resolves it like no file at all.
printf '[scene]\ntype = "simple_shear"\n' > minimal.toml
"$bin" check doc.toml > doc.resolved || fail "check of config-doc's output: $(cat doc.resolved)"
"$bin" check minimal.toml > minimal.resolved || fail "check minimal.toml"
diff doc.resolved minimal.resolved || fail "config-doc's defaults differ from the code's"
echo "ok: config-doc is a valid config of the defaults"
