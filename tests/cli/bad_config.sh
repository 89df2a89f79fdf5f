#!/usr/bin/env bash
# One case of the malformed-config corpus (tests/config_corpus/, issue 6):
#
#   bad_config.sh SHEARDIFF CASE.toml
#
# Runs `sheardiff run CASE --out TMP/out` and `sheardiff check CASE` and asserts, for both:
#   - exit code 2 (invalid configuration, docs/config.md),
#   - stderr holds every fragment of the case's `# expect: TEXT` lines (the key, the value,
#     the allowed range or the did-you-mean suggestion) and names where the error comes from
#     (the config path, or the text of an `# origin: TEXT` line, e.g. "--set"),
#   - nothing was created: TMP/out does not exist and the working folder (TMP) stays empty.
#
# Directives, read from the file's leading '#' comment lines:
#   # expect: TEXT     fragment stderr must contain (one or more lines; at least one required)
#   # set: KEY=VALUE   passed as --set KEY=VALUE (repeatable)
#   # set-escaped: KEY=VALUE  the same, with printf escapes (\n) expanded first
#   # origin: TEXT     the origin the message must name instead of the config path
#   # path: REL        run on this path (relative to the case's folder) instead of the case,
#                      e.g. a config file that does not exist
set -uo pipefail

bin=$1
case_file=$(realpath "$2")
case_dir=$(dirname "$case_file")
name=$(basename "$case_file")

expects=() sets=() origin="" path="$case_file"
while IFS= read -r line; do
  [[ $line == \#* ]] || break
  case $line in
    "# expect: "*) expects+=("${line#\# expect: }") ;;
    "# set: "*) sets+=(--set "${line#\# set: }") ;;
    "# set-escaped: "*) sets+=(--set "$(printf '%b' "${line#\# set-escaped: }")") ;;
    "# origin: "*) origin=${line#\# origin: } ;;
    "# path: "*) path="$case_dir/${line#\# path: }" ;;
  esac
done < "$case_file"
[[ -n $origin ]] || origin=$path

if ((${#expects[@]} == 0)); then
  echo "FAIL $name: no '# expect:' line in the case" >&2
  exit 1
fi

work=$(mktemp -d)          # the run's working folder: must stay empty
logs=$(mktemp -d)          # stdout/stderr captures, outside the working folder
trap 'rm -rf "$work" "$logs"' EXIT
fail=0

check_output() {  # $1 = subcommand, $2 = exit code
  local sub=$1 rc=$2 err
  err=$(cat "$logs/$sub.err")
  if [[ $rc -ne 2 ]]; then
    echo "FAIL $name: 'sheardiff $sub' exited with $rc, expected 2 (invalid configuration)"
    fail=1
  fi
  for frag in "${expects[@]}" "$origin"; do
    if [[ $err != *"$frag"* ]]; then
      echo "FAIL $name: 'sheardiff $sub' stderr lacks: $frag"
      fail=1
    fi
  done
  echo "  $sub -> exit $rc, stderr: $err"
}

(cd "$work" && "$bin" run "$path" --out "$work/out" "${sets[@]}") >"$logs/run.out" 2>"$logs/run.err"
check_output run $?
if [[ -e $work/out ]]; then
  echo "FAIL $name: the output folder was created: $(cd "$work/out" && ls -A | tr '\n' ' ')"
  fail=1
fi
if [[ -n $(ls -A "$work") ]]; then
  echo "FAIL $name: files were created in the working folder: $(ls -A "$work" | tr '\n' ' ')"
  fail=1
fi
rm -rf "${work:?}"/* "$work"/.[!.]* 2>/dev/null

(cd "$work" && "$bin" check "$path" "${sets[@]}") >"$logs/check.out" 2>"$logs/check.err"
check_output check $?
if [[ -n $(ls -A "$work") ]]; then
  echo "FAIL $name: 'sheardiff check' created files: $(ls -A "$work" | tr '\n' ' ')"
  fail=1
fi

((fail)) && exit 1
echo "ok $name"
