#!/usr/bin/env bash
# The repository stands alone (issue 14): no project file may point outside it, to the team's
# shared folder one level above the clone, or to a path of the machine it was written on.
# Papers are cited in docs/references.md instead. Checks every tracked file (every file under
# ROOT outside build trees and run folders when ROOT is not a git work tree), text files only,
# this script excepted.
#   usage: standalone.sh ROOT
set -euo pipefail
root=${1:?usage: standalone.sh ROOT}
cd "$root"
self=tests/standalone.sh

list_files() {
  if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
    git ls-files -z
  else
    find . \( -name .git -o -name 'build*' -o -name runs \) -prune -o -type f -print0 |
      sed -z 's#^\./##'
  fi
}

# -I: binary files (figures, HDF5) are skipped; each hit is printed as FILE:LINE:TEXT.
hits=$(list_files | grep -zv -x -F "$self" |
  xargs -0 -r grep -I -n -E -e '\.\.''/sha''red' -e '/wo''rk/' -e 'sha''red/(docs|seeds)/' || true)
if [[ -n $hits ]]; then
  echo "files that point outside the repository (cite papers in docs/references.md instead):"
  echo "$hits"
  exit 1
fi
echo "standalone: no file points outside the repository"
