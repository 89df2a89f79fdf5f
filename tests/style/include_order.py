#!/usr/bin/env python3
"""ctest: no include runs against the data flow between the folders of include/sheardiff/ and
src/ (README, "The source, in the order a run uses it"): the state and the configuration first, then scene set-up, neighbour
list, interactions, solver, integrator, observers, and what composes a run on top. A file may
include its own folder and any folder before it, never one after it. A parameters header
(NAME_params.hpp: one unit's configuration keys, declared by the unit that owns them) includes
no sheardiff header, so the configuration may gather them from every folder.

Fails naming each include that goes up, and each parameters header that includes the library.
With --selftest, checks the rule on a sample it must flag.
"""
import argparse
import pathlib
import re
import sys

# Folder (or top-level header stem) -> its place in the data flow.
ORDER = {
    "core": 0, "version": 0,
    "config": 1, "io": 2, "setup": 3, "scene": 4, "neighbour": 5, "interactions": 6,
    "solver": 7, "integrator": 8, "analysis": 9, "observe": 10,
    "engine": 11, "run_parts": 12, "run_extension": 12, "run": 13, "sweep": 14, "app": 15,
}
# The one include against the order, and why: the configuration's `scene.type` choices and each
# scene's own checks, frame spacing and planned cell are rows of the scene registry, which the
# configuration reads to validate a file before any work starts (config.cpp, not config.hpp:
# no header of the configuration depends on a scene).
ALLOWED = {("config.cpp", "scene/registry.hpp")}
INCLUDE = re.compile(r'^#include "sheardiff/([^"]+)"', re.M)


def unit(rel):
    """The data-flow unit of a path relative to include/sheardiff/ or src/."""
    parts = pathlib.PurePosixPath(rel).parts
    return parts[0] if len(parts) > 1 else pathlib.PurePosixPath(rel).stem


def violations(files):
    """files: {relative path: text}. Returns the offending (file, included, reason) triples."""
    bad = []
    for rel, text in sorted(files.items()):
        here = unit(rel)
        if here not in ORDER:
            bad.append((rel, "", f"unit {here!r} has no place in the data flow (ORDER)"))
            continue
        for target in INCLUDE.findall(text):
            if rel.endswith("_params.hpp"):
                bad.append((rel, target, "a parameters header includes the library"))
                continue
            there = unit(target)
            if target.endswith("_params.hpp"):
                continue
            if there not in ORDER:
                bad.append((rel, target, f"unit {there!r} has no place in the data flow"))
            elif ORDER[there] > ORDER[here] and (rel, target) not in ALLOWED:
                bad.append((rel, target, f"{here} includes {there}, which comes after it"))
    return bad


def tree(root):
    files = {}
    for base in ("include/sheardiff", "src"):
        for f in (root / base).rglob("*"):
            if f.suffix in (".hpp", ".cpp"):
                files[str(f.relative_to(root / base))] = f.read_text()
    return files


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--root", type=pathlib.Path, default=pathlib.Path(__file__).resolve().parents[2])
    ap.add_argument("--selftest", action="store_true")
    a = ap.parse_args()
    if a.selftest:
        sample = {"neighbour/list.hpp": '#include "sheardiff/interactions/pair_laws.hpp"\n',
                  "scene/x_params.hpp": '#include "sheardiff/core/types.hpp"\n',
                  "solver/ok.cpp": '#include "sheardiff/core/types.hpp"\n#include "sheardiff/x/y_params.hpp"\n'}
        found = {b[0] for b in violations(sample)}
        if found != {"neighbour/list.hpp", "scene/x_params.hpp"}:
            sys.exit(f"selftest: flagged {sorted(found)}")
        print("selftest ok")
        return
    bad = violations(tree(a.root))
    for rel, target, why in bad:
        print(f"{rel}: #include \"sheardiff/{target}\": {why}")
    if bad:
        sys.exit(f"{len(bad)} includes against the data flow")
    print("ok: every include follows the data flow")


if __name__ == "__main__":
    main()
