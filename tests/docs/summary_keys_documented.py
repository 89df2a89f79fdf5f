#!/usr/bin/python3
"""ctest: every key a run writes to summary.json is documented in docs/outputs.md.

Runs a small simple-shear run and a small pressure-cell run (both with the diffusion analysis)
and a short channel run, then reads the keys of their summary.json files; each must appear as
the first cell of a table row of docs/outputs.md, in backticks. Fails naming the keys that are
not, so that a new key cannot go undocumented. Every dataset of their analysis.h5 and channel.h5
must carry "unit" and "description" attributes (issue 34: the files described nothing).

    summary_keys_documented.py --bin build/sheardiff --root . --work DIR
"""
import argparse
import json
import pathlib
import re
import shutil
import subprocess
import sys

RUNS = {
    "simple_shear": """[scene]
type = "simple_shear"
[particles]
N = 60
phi_init = 0.7
[flow]
J = 1e-1
[contact]
ktilde = 1e3
[run]
strain = 1.5
transient_strain = 0.3
[analysis]
msd_window_lo = 0.2
msd_window_hi = 0.5
reference_times = 30
vacf_max_lag = 0.3
[output]
frame_strain = 0.01
""",
    "pressure_cell": """[scene]
type = "pressure_shear"
[particles]
N = 60
phi_init = 0.74
[flow]
J = 1e-2
[contact]
ktilde = 1e3
[run]
strain = 6.0
seed = 3
[steady]
window = 1.0
h_tolerance = 0.05
mu_tolerance = 0.3
measure_strain = 2.0
[analysis]
error_block = 0.5
msd_window_lo = 0.2
msd_window_hi = 0.5
reference_times = 30
vacf_max_lag = 0.3
[output]
frame_strain = 0.02
""",
}


def documented_keys(doc):
    keys = set()
    for line in doc.read_text().splitlines():
        m = re.match(r"^\|\s*`([^`]+)`\s*\|", line)
        if m:
            keys.add(m.group(1))
    return keys


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--root", required=True, type=pathlib.Path)
    ap.add_argument("--work", required=True, type=pathlib.Path)
    args = ap.parse_args()
    shutil.rmtree(args.work, ignore_errors=True)
    args.work.mkdir(parents=True)
    summaries = {}
    for name, text in RUNS.items():
        cfg = args.work / f"{name}.toml"
        cfg.write_text(text)
        out = args.work / name
        p = subprocess.run([args.bin, "run", str(cfg), "--out", str(out), "-q"], capture_output=True, text=True)
        if p.returncode != 0:
            sys.exit(f"{name}: sheardiff run failed ({p.returncode}): {p.stderr}")
        summaries[name] = json.loads((out / "summary.json").read_text())
    out = args.work / "channel"
    p = subprocess.run([args.bin, "run", str(args.root / "configs" / "channel" / "A.toml"), "--out", str(out),
                        "--set", "run.strain=150", "-q"], capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"channel: sheardiff run failed ({p.returncode}): {p.stderr}")
    summaries["channel"] = json.loads((out / "summary.json").read_text())

    documented = documented_keys(args.root / "docs" / "outputs.md")
    missing = sorted({(k, name) for name, s in summaries.items() for k in s if k not in documented})
    seen = set().union(*(s.keys() for s in summaries.values()))
    print(f"{len(seen)} keys in {len(summaries)} summaries, {len(documented)} documented")
    for scene in ("simple_shear", "pressure_cell", "channel"):
        if not summaries[scene]:
            sys.exit(f"{scene}: empty summary")
    import h5py

    bare = []
    for f in (args.work / "simple_shear" / "analysis.h5", args.work / "pressure_cell" / "analysis.h5",
              args.work / "channel" / "channel.h5"):
        with h5py.File(f, "r") as h:
            def visit(name, obj):
                if isinstance(obj, h5py.Dataset) and not ("unit" in obj.attrs and "description" in obj.attrs):
                    bare.append(f"{f.parent.name}/{f.name}:{name}")
            h.visititems(visit)
    for b in bare:
        print(f"FAIL  {b} has no unit or description attribute")
    if not bare:
        print("ok    every dataset of analysis.h5 and channel.h5 has a unit and a description")
    if missing or bare:
        for key, name in missing:
            print(f"FAIL  `{key}` ({name}) is not documented in docs/outputs.md")
        sys.exit(1)
    print("ok    every summary.json key is documented in docs/outputs.md")


if __name__ == "__main__":
    main()
