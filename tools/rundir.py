"""What every tool reads of a run directory or a sweep's store, in one place.

The file names come from the C++ declaration (include/sheardiff/io/run_files.hpp) and the
summary.json keys from theirs (include/sheardiff/io/summary_keys.hpp), so the run, the run
directory's rules and these tools cannot disagree on them: reading a key the code does not
declare raises KeyError naming it, where a misspelt key would otherwise read as absent. HDF5 files are opened in
single-writer/multiple-reader mode, so a trajectory can be read while its run writes it (the
run flushes it every two seconds).

    import rundir
    run = rundir.Run("runs/quick")
    run.summary        # summary.json as a Summary (a dict; {} for an unfinished run)
    run.config         # config.toml as a dict ({} if absent)
    with run.open("trajectory") as f: ...   # or "analysis", "channel"

    store = rundir.Store("results/n1000_k1e4_steady")   # or a sweep folder
    store.points()     # its finished points, each a Run
    store.rows()       # sweep.csv as dicts; store.fits: fits.json
"""
import json
import math
import pathlib
import re
import tomllib

_INCLUDE = pathlib.Path(__file__).resolve().parent.parent / "include/sheardiff/io"
_HEADER = _INCLUDE / "run_files.hpp"
# kAnalysisFile -> "analysis.h5", ..., read from the header's `inline constexpr const char* kX = "...";`
NAMES = dict(re.findall(r'constexpr const char\*\s+(k\w+)\s*=\s*"([^"]+)"', _HEADER.read_text()))
FILES = {
    "config": NAMES["kConfigFile"],
    "trajectory": NAMES["kTrajectoryFile"],
    "analysis": NAMES["kAnalysisFile"],
    "channel": NAMES["kChannelFile"],
    "summary": NAMES["kSummaryFile"],
    "checkpoint": NAMES["kCheckpointFile"],
}
# A sweep's store (results/NAME) or folder: points/NAME/ run directories, the collected table
# and fits (include/sheardiff/sweep/sweep.hpp, docs/sweeps.md).
POINTS, SWEEP_CSV, FITS = "points", "sweep.csv", "fits.json"

# Every summary.json key, from `inline constexpr const char* name = "name";`.
SUMMARY_KEYS = frozenset(re.findall(r'constexpr const char\*\s+\w+\s*=\s*"([^"]+)"',
                                    (_INCLUDE / "summary_keys.hpp").read_text()))


class Summary(dict):
    """A run's summary.json. Reading a key that is not declared raises KeyError; a declared key
    the run did not write reads as absent, as in a dict."""

    @staticmethod
    def _declared(key):
        if key not in SUMMARY_KEYS:
            raise KeyError(f"{key!r} is not a summary.json key (include/sheardiff/io/summary_keys.hpp)")
        return key

    def __getitem__(self, key):
        return super().__getitem__(self._declared(key))

    def get(self, key, default=None):
        return super().get(self._declared(key), default)

    def __contains__(self, key):
        return super().__contains__(self._declared(key))


def key(name):
    """name if it is a summary.json key (a sweep.csv column of a point's summary), else KeyError."""
    return Summary._declared(name)


def open_h5(path):
    """An HDF5 file for reading, also while its run still writes it: trajectories are written in
    HDF5's single-writer/multiple-reader mode, read here in that mode (a frame appears once the
    run has flushed it, every two seconds). Files of the older format open as plain files."""
    import h5py

    try:
        return h5py.File(path, "r", libver="latest", swmr=True)
    except OSError:
        return h5py.File(path, "r", locking=False)


def read_json(path):
    return json.loads(pathlib.Path(path).read_text())


def read_summary(path):
    """A summary.json file as a Summary."""
    return Summary(read_json(path))


class Run:
    """A run directory (finished or not)."""

    def __init__(self, path):
        self.path = pathlib.Path(path)

    def file(self, kind):
        return self.path / FILES[kind]

    def has(self, kind):
        return self.file(kind).is_file()

    def open(self, kind):
        return open_h5(self.file(kind))

    @property
    def finished(self):
        return self.has("summary")

    @property
    def summary(self):
        return read_summary(self.file("summary")) if self.has("summary") else Summary()

    @property
    def config(self):
        return tomllib.loads(self.file("config").read_text()) if self.has("config") else {}


# sweep.csv's status of a point whose window passed the stationarity test (src/sweep/collect.cpp).
STATIONARY = "done"
# The finished points that reached the steady state but whose window then failed the
# stationarity test; `sheardiff fit --include-not-stationary` fits them too. "done, not steady"
# (the run ended before the steady-state test passed) is not among them: it has no window.
NOT_STATIONARY = ("done, not stationary", "done, drifting (mu_top - mu_bottom)")


def is_stationary(row):
    return row["status"] == STATIONARY


def mean_sem(values):
    """(mean, standard error of the mean from the values' scatter) of the finite values; the
    error is None below two values, both are None for none."""
    v = [x for x in values if x is not None and math.isfinite(x)]
    if not v:
        return None, None
    m = sum(v) / len(v)
    if len(v) < 2:
        return m, None
    return m, math.sqrt(sum((x - m) ** 2 for x in v) / (len(v) - 1) / len(v))


class Store:
    """A sweep's results store (results/NAME) or sweep folder, finished or not."""

    def __init__(self, path):
        self.path = pathlib.Path(path)

    def points(self, finished=True):
        """Its point run directories (points/NAME/), sorted by name; only the finished ones
        unless finished=False."""
        runs = [Run(p) for p in sorted((self.path / POINTS).glob("*")) if p.is_dir()]
        return [r for r in runs if r.finished or not finished]

    def has_table(self):
        return (self.path / SWEEP_CSV).is_file() and (self.path / FITS).is_file()

    def rows(self, done=False):
        """sweep.csv as a list of dicts (cells as text); only the finished points if done."""
        import csv

        with open(self.path / SWEEP_CSV, newline="") as f:
            rows = list(csv.DictReader(f))
        return [r for r in rows if r["status"].startswith("done")] if done else rows

    def fitted_rows(self):
        """The rows whose measurements the fits used: the stationary ones, and the flagged ones
        too when the fit was made with `sheardiff fit --include-not-stationary`."""
        with_flagged = self.fits.get("includes_not_stationary")
        return [r for r in self.rows()
                if is_stationary(r) or (with_flagged and r["status"] in NOT_STATIONARY)]

    @property
    def fits(self):
        return read_json(self.path / FITS)


def unwrapped_positions(group, frames=slice(None)):
    """The unwrapped positions (frames x N x 2, or x 3 for spheres) of an H5MD particle group:
    stored under Lees-Edwards, else position + image . edges (the pressure cell and the channel
    store no copy)."""
    if "unwrapped_position" in group:
        return group["unwrapped_position/value"][frames]
    pos = group["position/value"][frames]
    img = group["image/value"][frames].astype(float)
    edges = group["box/edges/value"][frames]
    return pos + img @ edges  # the rows of edges are the box vectors


def read_trajectory(path):
    """The whole trajectory of an H5MD file (a run's trajectory.h5, finished or running) as numpy
    arrays, for the exporters: position, image (frames x N x dimension), velocity (or None),
    edges (frames x dimension x dimension: rows are the box vectors, the Lees-Edwards tilt in
    edges[:, 1, 0]), periodic_y,
    diameter, species, motion (N), step, time (frames) and the scalar observables by name."""
    import h5py
    import numpy as np

    with open_h5(path) as f:
        groups = list(f["particles"])
        g = f["particles"]["suspension" if "suspension" in groups else groups[0]]
        t = {"position": g["position/value"][()]}
        n = t["position"].shape[1]
        edges = g["box/edges/value"][()]
        if edges.ndim == 2:  # a cuboid box (files before the triclinic layout)
            edges = np.stack([np.diag(e) for e in edges])
        t["edges"] = edges
        boundary = [b.decode() if isinstance(b, bytes) else str(b) for b in g["box"].attrs["boundary"]]
        t["periodic_y"] = boundary[1] == "periodic"
        t["image"] = g["image/value"][()] if "image" in g else np.zeros(t["position"].shape, np.int64)
        t["velocity"] = g["velocity/value"][()] if "velocity" in g else None
        t["diameter"] = g["diameter"][()]
        t["species"] = g["species"][()] if "species" in g else np.zeros(n, int)
        t["motion"] = g["motion"][()] if "motion" in g else np.zeros(n, int)
        t["step"] = g["position/step"][()]
        t["time"] = g["position/time"][()]
        t["observables"] = {k: f["observables"][k]["value"][()] for k in f.get("observables", {})
                            if isinstance(f["observables"][k], h5py.Group) and "step" in f["observables"][k]}
    return t
