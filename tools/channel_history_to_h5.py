#!/usr/bin/python3
"""Moves the migration history of channel runs made before 2026-12-02 out of summary.json.

Those runs wrote the history (a row of five profiles every channel.sample_interval) into
RUN_DIR/summary.json, megabytes of text for a long run. Runs made since write it to
RUN_DIR/channel.h5 (src/observe/channel.cpp) and summary.json names the file under
channel_history_file. For each RUN_DIR this tool

- writes RUN_DIR/channel.h5 in that layout: /channel_history/{y, time, pressure_gradient_ratio,
  centre_distance, u_p_mean} as float64, the profiles {phi, u_p, u_f, T_time, T_instant} as
  float32 (rows x bins, nan for an empty bin, shuffle + gzip). The old text kept 4 significant
  digits, which float32 holds exactly enough;
- then rewrites summary.json without channel_history and with channel_history_file.

Both files are written under a temporary name and renamed, channel.h5 first, so a kill leaves
either the old summary (the history still in it) or the new pair. A directory whose summary
holds no history is left alone. tools/channel_table.py reads either layout.

Usage
-----
    /usr/bin/python3 tools/channel_history_to_h5.py results/channel/*/points/*
"""
import argparse
import json
import os
import sys

import h5py
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import rundir  # noqa: E402
from channel_table import HISTORY_SERIES as SERIES, PROFILES  # noqa: E402


def write_history(h, y, file):
    tmp = file + ".tmp"
    with h5py.File(tmp, "w") as f:
        g = f.create_group("channel_history")
        g.create_dataset("y", data=np.asarray(y, float))
        for k in SERIES:
            g.create_dataset(k, data=np.asarray(h[k], float))
        for k in PROFILES:
            rows = np.array([[np.nan if x is None else x for x in r] for r in h[k]], np.float32)
            rows = rows.reshape(len(h[k]), len(y))
            chunk = (max(1, min(rows.shape[0], 256)), max(1, rows.shape[1]))
            g.create_dataset(k, data=rows, chunks=chunk, shuffle=True, compression="gzip",
                             compression_opts=6)
    os.replace(tmp, file)


def convert(run_dir):
    """True if the history was moved, False if there was none to move."""
    run = rundir.Run(run_dir)
    summary = str(run.file("summary"))
    s = run.summary
    h = s.get("channel_history")
    if not h:
        return False
    write_history(h, s["channel_y"], str(run.file("channel")))
    del s["channel_history"]
    s["channel_history_file"] = rundir.FILES["channel"]
    tmp = summary + ".tmp"
    with open(tmp, "w") as fh:   # the writer's layout: one key per line, sorted, lists inline
        fh.write("{\n" + ",\n".join(f"  {json.dumps(k)}: {json.dumps(v)}" for k, v in sorted(s.items()))
                 + "\n}\n")
    os.replace(tmp, summary)
    return True


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("run_dirs", nargs="+", help="channel run directories (or stored points)")
    args = ap.parse_args(argv)
    for d in args.run_dirs:
        if not rundir.Run(d).finished:
            print(f"channel_history_to_h5.py: {d}: no summary.json", file=sys.stderr)
            return 1
    for d in args.run_dirs:
        print(f"{d}: {'history moved to channel.h5' if convert(d) else 'no history in summary.json: left alone'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
