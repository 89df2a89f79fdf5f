#!/usr/bin/python3
"""The index of results/: one row per stored folder, written from the folders themselves.

For each folder of results/: the sweep file that stores into it (the `results = ...` line of a
configs/*.toml), its points, J values, how many windows passed the stationarity test (and how
many predate it), and how many points carry the diffusion analysis's warning that C(tau) was
under-resolved (a Psi from frames fewer than 10 per Psi; the streaming analysis, the default
now, does not warn). `--check` exits 1 if results/README.md differs from what it would write.

    /usr/bin/python3 tools/results_index.py            # rewrite results/README.md
    /usr/bin/python3 tools/results_index.py --check    # ctest results_index_up_to_date
"""
import argparse
import pathlib
import re
import sys

import rundir

ROOT = pathlib.Path(__file__).resolve().parent.parent
RESULTS = ROOT / "results"

HEAD = """# Stored results

Small summaries of finished runs (no trajectories), so that a later session or another machine
continues and refits them: `points/NAME/` holds a point's config.toml, summary.json and its
small analysis file; `sweep.csv` and `fits.json` are the folder's collected table and fits
(docs/sweeps.md). `table1_*` are fits over several folders (`sheardiff fit`, with their
fit_sources.txt); `scratch/` holds checkpoints of points in progress (its own README).
This table is written by `/usr/bin/python3 tools/results_index.py` (ctest
`results_index_up_to_date` fails until it is rerun).

Columns: the sweep file storing into the folder; finished points; the J they cover; windows
that passed the stationarity test / were judged by it (points written before the test are not
judged); points whose Psi carries "C(tau) is under-resolved" (frame-based, fewer than 10 frames
per Psi).

| folder | sweep file | points | J | stationary / judged | under-resolved Psi |
|---|---|---|---|---|---|
"""


def sweep_files():
    out = {}
    for f in sorted((ROOT / "configs").glob("*.toml")):
        m = re.search(r'^results\s*=\s*"\.\./results/([^"/]+)/?"', f.read_text(), re.M)
        if m:
            out.setdefault(m.group(1), []).append(f"configs/{f.name}")
    return out


def row(folder, files):
    sources = folder / "fit_sources.txt"
    if sources.exists():
        stores = [ln.strip().removeprefix("../") for ln in sources.read_text().splitlines()[1:]
                  if ln.strip()]
        files = ["fit over " + ", ".join(stores)]
    # A store's points, else a folder of runs, else a folder of stores (results/channel).
    summaries = [rundir.read_summary(p)
                 for p in sorted(folder.glob(f"{rundir.POINTS}/*/{rundir.FILES['summary']}")) or
                 sorted(folder.glob(f"*/{rundir.FILES['summary']}")) or
                 sorted(folder.glob(f"*/{rundir.POINTS}/*/{rundir.FILES['summary']}"))]
    if sources.exists():
        return f"| {folder.name} | {files[0]} | - | - | - | - |"
    js = sorted({s["J"] for s in summaries if "J" in s})
    judged = [s for s in summaries if "stationary" in s]
    passed = sum(1 for s in judged if s["stationary"])
    warned = sum(1 for s in summaries
                 if any("under-resolved" in w for w in s.get("analysis_warnings", [])))
    jtext = ", ".join(f"{j:g}" for j in js) if js else "-"
    judged_text = f"{passed} / {len(judged)}" if judged else "-"
    return (f"| {folder.name} | {', '.join(files) or '-'} | {len(summaries)} | {jtext} | "
            f"{judged_text} | {warned or '-'} |")


def index():
    files = sweep_files()
    rows = [row(d, files.get(d.name, [])) for d in sorted(RESULTS.iterdir())
            if d.is_dir() and d.name != "scratch"]
    return HEAD + "\n".join(rows) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true")
    a = ap.parse_args()
    text = index()
    target = RESULTS / "README.md"
    if a.check:
        if not target.exists() or target.read_text() != text:
            sys.exit("results/README.md is not the index of results/: run "
                     "/usr/bin/python3 tools/results_index.py")
        return
    target.write_text(text)


if __name__ == "__main__":
    main()
