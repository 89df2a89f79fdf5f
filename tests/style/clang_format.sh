#!/usr/bin/env bash
# Every C++ file of the repository is as clang-format (.clang-format at the root) writes it.
# Skipped (77) where clang-format is not installed.
#   clang_format.sh REPO_DIR
set -uo pipefail
cd "$1" || exit 1
command -v clang-format > /dev/null || { echo "clang-format not installed: skipped"; exit 77; }
files=$(git ls-files '*.cpp' '*.hpp' 2>/dev/null || find include src tests bench -name '*.[ch]pp')
clang-format --dry-run -Werror $files || { echo "run: clang-format -i \$(git ls-files '*.cpp' '*.hpp')"; exit 1; }
echo "ok: $(echo "$files" | wc -w) files formatted"
