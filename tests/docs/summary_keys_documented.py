#!/usr/bin/python3
"""ctest: every key a run writes to summary.json is declared (include/sheardiff/io/summary_keys.hpp).

Runs a small simple-shear run and a small pressure-cell run (both with the diffusion analysis)
and a short channel run, then reads the keys of their summary.json files; each must be in the
list `sheardiff summary-keys` prints, the declaration docs/outputs.md's tables are printed from
(ctest summary_keys_doc_up_to_date) and tools/rundir.py reads. Fails naming the keys that are
not, so that a new key cannot go undeclared or undocumented. Every dataset of their analysis.h5 and channel.h5
must carry "unit" and "description" attributes (issue 34: the files described nothing).

    summary_keys_documented.py --bin build/sheardiff --root . --work DIR
"""
import argparse
import json
import pathlib
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


def declared_keys(binary):
    out = subprocess.run([binary, "summary-keys"], capture_output=True, text=True, check=True).stdout
    return {row["key"] for row in json.loads(out)}


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

    documented = declared_keys(args.bin)
    # The names of the header (what tools/rundir.py reads) are exactly the documented rows, and
    # a tool reading a misspelt key is stopped.
    sys.path.insert(0, str(args.root / "tools"))
    import rundir

    if rundir.SUMMARY_KEYS != documented:
        sys.exit(f"FAIL  header constants without a row: {sorted(rundir.SUMMARY_KEYS - documented)}; "
                 f"rows without a constant: {sorted(documented - rundir.SUMMARY_KEYS)}")
    try:
        rundir.Summary({"psi": 1.0}).get("Psi")
        sys.exit("FAIL  rundir.Summary read the undeclared key 'Psi'")
    except KeyError:
        pass
    print(f"ok    the {len(documented)} declared keys are the {len(rundir.SUMMARY_KEYS)} names "
          "tools/rundir.py reads; an undeclared key is refused")
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
            print(f"FAIL  `{key}` ({name}) is not declared in include/sheardiff/io/summary_keys.hpp")
        sys.exit(1)
    print("ok    every summary.json key is declared (and so documented in docs/outputs.md)")


if __name__ == "__main__":
    main()
