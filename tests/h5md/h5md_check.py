#!/usr/bin/python3
"""An H5MD 1.1 conformance checker written from the specification (H5MD 1.1.0 and its units
module 1.0), independent of sheardiff's own reader: h5py and numpy only.

    /usr/bin/python3 tests/h5md/h5md_check.py FILE.h5 [FILE.h5 ...] [--require-units]

Prints one line per violation and exits 1 if there is any, else prints "ok" per file. Checked:
the h5md metadata (version, author, creator, modules), every particle group (box with
dimension, boundary and edges of a valid shape; position, image, velocity, species, ...
shapes; step and time of box/edges and image hard-linked to position's), every time-dependent
element (explicit or fixed step/time storage, monotonic, as long as value), the observables
tree (elements or subgroups of elements only), connectivity elements (integer tuples with a
particles_group object reference into /particles, indices in range or the fill value) and,
with --require-units, a well-formed `unit` attribute on every value and time dataset.
"""
import argparse
import re
import sys

import h5py
import numpy as np

UNIT_FACTOR = re.compile(r"^(?:[0-9]+(?:\.[0-9]+)?(?:[+-][0-9]+)?|[A-Za-z_]+(?:[+-]?[1-9][0-9]*)?)$")


class Checker:
    def __init__(self, f, require_units):
        self.f = f
        self.require_units = require_units
        self.errors = []

    def err(self, where, what):
        self.errors.append(f"{where}: {what}")

    # -- helpers -----------------------------------------------------------------------------
    @staticmethod
    def is_int(ds):
        return ds.dtype.kind in "iu" or h5py.check_enum_dtype(ds.dtype) is not None

    @staticmethod
    def is_number(ds):
        return ds.dtype.kind in "iuf" or h5py.check_enum_dtype(ds.dtype) is not None

    def string_attr(self, obj, name, where, scalar=True):
        if name not in obj.attrs:
            self.err(where, f"attribute '{name}' missing")
            return None
        a = obj.attrs.get_id(name)
        if a.get_type().get_class() != h5py.h5t.STRING:
            self.err(where, f"attribute '{name}' is not a string")
            return None
        if scalar and a.shape != ():
            self.err(where, f"attribute '{name}' is not scalar")
        v = obj.attrs[name]
        dec = lambda x: x.decode() if isinstance(x, bytes) else str(x)  # noqa: E731
        return dec(v) if scalar else [dec(x) for x in np.atleast_1d(v)]

    def int_pair_attr(self, obj, name, where):
        if name not in obj.attrs:
            self.err(where, f"attribute '{name}' missing")
            return None
        v = np.asarray(obj.attrs[name])
        if v.dtype.kind not in "iu" or v.shape != (2,):
            self.err(where, f"attribute '{name}' must be Integer[2], is {v.dtype}{list(v.shape)}")
            return None
        return tuple(int(x) for x in v)

    def check_unit(self, ds, where):
        if "unit" not in ds.attrs:
            if self.require_units:
                self.err(where, "no 'unit' attribute")
            return
        u = self.string_attr(ds, "unit", where)
        if u is None:
            return
        factors = u.split(" ")
        symbols = [re.sub(r"[+-]?[0-9]+$", "", x) for x in factors]
        if not all(UNIT_FACTOR.match(x) for x in factors):
            self.err(where, f"unit '{u}' is not a sequence of unit factors")
        numbers = [k for k, x in enumerate(factors) if re.match(r"^[0-9]", x)]
        if len(numbers) > 1 or (numbers and numbers[0] != 0):
            self.err(where, f"unit '{u}': at most one number, and first")
        names = [s for s in symbols if s and not s[0].isdigit()]
        if len(names) != len(set(names)):
            self.err(where, f"unit '{u}' repeats a symbol")

    # -- elements ----------------------------------------------------------------------------
    def axis(self, g, name, where, integer):
        """step or time of a time-dependent element: explicit [variable] or fixed scalar."""
        ds = g[name]
        if not isinstance(ds, h5py.Dataset):
            self.err(where, f"'{name}' is not a dataset")
            return None
        if (integer and not self.is_int(ds)) or (not integer and not self.is_number(ds)):
            self.err(where, f"'{name}' has type {ds.dtype}")
        if ds.shape == ():
            return ("fixed", None)
        if len(ds.shape) != 1:
            self.err(where, f"'{name}' must be [variable] or scalar, is {list(ds.shape)}")
            return None
        v = ds[()]
        if len(v) > 1 and np.any(np.diff(v) <= 0) and name == "step":
            self.err(where, "step not monotonically increasing")
        if len(v) > 1 and np.any(np.diff(v) < 0) and name == "time":
            self.err(where, "time not monotonically increasing")
        return ("explicit", len(v))

    def element(self, obj, where, inner_rank=None):
        """A time-dependent group or a time-independent dataset; returns the value dataset
        and whether it is time-dependent."""
        if isinstance(obj, h5py.Dataset):
            self.check_unit(obj, where)
            if inner_rank is not None and obj.ndim != inner_rank:
                self.err(where, f"rank {obj.ndim}, expected {inner_rank}")
            return obj, False
        for need in ("step", "value"):
            if need not in obj:
                self.err(where, f"time-dependent element without '{need}'")
                return None, True
        value = obj["value"]
        if not isinstance(value, h5py.Dataset) or value.ndim < 1:
            self.err(where, "'value' must be a dataset of rank >= 1")
            return None, True
        if value.maxshape[0] is not None:
            self.err(where, "'value' first dimension is not variable (unlimited)")
        if inner_rank is not None and value.ndim != inner_rank + 1:
            self.err(where, f"'value' rank {value.ndim}, expected {inner_rank + 1}")
        self.check_unit(value, where + "/value")
        s = self.axis(obj, "step", where, True)
        if s and s[0] == "explicit" and s[1] != value.shape[0]:
            self.err(where, f"step has {s[1]} rows, value {value.shape[0]}")
        if "time" in obj:
            t = self.axis(obj, "time", where, False)
            if t and t[0] == "explicit" and t[1] != value.shape[0]:
                self.err(where, f"time has {t[1]} rows, value {value.shape[0]}")
            if s and t and s[0] != t[0]:
                self.err(where, "step and time use different storage modes")
            self.check_unit(obj["time"], where + "/time")
        return value, True

    def same_object(self, a, b):
        return h5py.h5o.get_info(a.id).addr == h5py.h5o.get_info(b.id).addr

    def linked(self, elem, position, where):
        for axis in ("step", "time"):
            if axis in position and (axis not in elem or not self.same_object(elem[axis], position[axis])):
                self.err(where, f"'{axis}' is not a hard link to position's")

    # -- groups ------------------------------------------------------------------------------
    def h5md(self):
        if "h5md" not in self.f:
            self.err("/h5md", "missing (the only mandatory group)")
            return
        g = self.f["h5md"]
        v = self.int_pair_attr(g, "version", "/h5md")
        if v and v != (1, 1):
            self.err("/h5md", f"version {v}, this checker reads 1.1")
        for sub, attrs in (("author", ["name"]), ("creator", ["name", "version"])):
            if sub not in g:
                self.err(f"/h5md/{sub}", "missing")
                continue
            for a in attrs:
                val = self.string_attr(g[sub], a, f"/h5md/{sub}")
                if val is not None and not val.strip():
                    self.err(f"/h5md/{sub}", f"empty '{a}'")
        if "modules" in g:
            for name, m in g["modules"].items():
                self.int_pair_attr(m, "version", f"/h5md/modules/{name}")
                if name == "units":
                    self.string_attr(m, "system", "/h5md/modules/units")
        elif self.require_units:
            self.err("/h5md/modules/units", "missing")

    def particles(self):
        if "particles" not in self.f:
            return {}
        sizes = {}
        for name, g in self.f["particles"].items():
            where = f"/particles/{name}"
            if not isinstance(g, h5py.Group):
                self.err(where, "particle subsets must be groups")
                continue
            sizes[g.name] = self.particle_group(g, where)
        return sizes

    def particle_group(self, g, where):
        if "box" not in g:
            self.err(where, "no 'box' group")
            return None
        box = g["box"]
        dim = box.attrs.get("dimension")
        if dim is None or np.asarray(dim).shape != () or np.asarray(dim).dtype.kind not in "iu":
            self.err(where + "/box", "'dimension' must be a scalar Integer")
            return None
        dim = int(dim)
        bnd = self.string_attr(box, "boundary", where + "/box", scalar=False)
        if bnd is not None:
            if len(bnd) != dim or any(b not in ("periodic", "none") for b in bnd):
                self.err(where + "/box", f"boundary {bnd}: {dim} of 'periodic'/'none'")
        position = g.get("position")
        if "edges" in box:
            value, timed = self.element(box["edges"], where + "/box/edges")
            if value is not None:
                shape = value.shape[1:] if timed else value.shape
                if shape not in ((dim,), (dim, dim)):
                    self.err(where + "/box/edges", f"shape {list(shape)}: [D] or [D][D], D = {dim}")
                if timed and isinstance(position, h5py.Group):
                    self.linked(box["edges"], position, where + "/box/edges")
        elif bnd and "periodic" in bnd:
            self.err(where + "/box", "periodic boundary without 'edges'")
        n = None
        if position is not None:
            value, timed = self.element(position, where + "/position")
            if value is not None:
                if value.ndim != (3 if timed else 2) or value.shape[-1] != dim:
                    self.err(where + "/position", f"shape {list(value.shape)}: [variable][N][{dim}]")
                n = value.shape[-2] if value.ndim >= 2 else None
        for name, obj in g.items():
            if name in ("box", "position"):
                continue
            ew = f"{where}/{name}"
            value, timed = self.element(obj, ew)
            if value is None:
                continue
            shape = value.shape[1:] if timed else value.shape
            if n is not None and (not shape or shape[0] != n):
                self.err(ew, f"shape {list(value.shape)}: particle index must be dimension {2 if timed else 1}")
            if name in ("image", "velocity", "force") and len(shape) != 2 or (
                    name in ("image", "velocity", "force") and shape[-1] != dim):
                self.err(ew, f"shape {list(value.shape)}: vectors of dimension {dim}")
            if name in ("species", "id") and not self.is_int(value):
                self.err(ew, f"type {value.dtype}: Enumeration or Integer")
            if name == "image":
                if position is None:
                    self.err(ew, "image without position")
                elif timed:
                    self.linked(obj, position, ew)
        return n

    def observables(self, g, where):
        for name, obj in g.items():
            ew = f"{where}/{name}"
            if isinstance(obj, h5py.Group) and "value" not in obj and "step" not in obj:
                self.observables(obj, ew)  # a subgroup of observables
            else:
                self.element(obj, ew)

    def connectivity(self, sizes):
        if "connectivity" not in self.f:
            return
        for name, obj in self.f["connectivity"].items():
            ew = f"/connectivity/{name}"
            value, timed = self.element(obj, ew)
            if value is None:
                continue
            if not self.is_int(value) or value.ndim != (3 if timed else 2):
                self.err(ew, f"tuples must be Integer[{'variable,' if timed else ''}N,T], are {value.dtype}{list(value.shape)}")
                continue
            ref = obj.attrs.get("particles_group")
            if not isinstance(ref, h5py.Reference) or not ref:
                self.err(ew, "'particles_group' is not an object reference")
                continue
            target = self.f[ref]
            if target.name not in sizes:
                self.err(ew, f"particles_group refers to {target.name}, not a group in /particles")
                continue
            fill = value.fillvalue
            v = value[()]
            used = v[np.all(v != fill, axis=-1)] if fill is not None else v
            n = sizes[target.name]
            if n is not None and used.size and (used.min() < 0 or used.max() >= n):
                self.err(ew, f"indices outside [0, {n}) that are not the fill value {fill}")
            if timed and "position" in target:
                self.linked(obj, target["position"], ew)
            for extra, ds in obj.items():  # per-tuple data beside the tuples
                if extra in ("step", "time", "value") or not isinstance(ds, h5py.Dataset):
                    continue
                if ds.shape[:2] != value.shape[:2]:
                    self.err(f"{ew}/{extra}", f"shape {list(ds.shape)} does not follow value's {list(value.shape[:2])}")
                self.check_unit(ds, f"{ew}/{extra}")

    def run(self):
        self.h5md()
        sizes = self.particles()
        if "observables" in self.f:
            self.observables(self.f["observables"], "/observables")
        self.connectivity(sizes)
        return self.errors


def check_file(path, require_units=False):
    with h5py.File(path, "r") as f:
        return Checker(f, require_units).run()


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("files", nargs="+")
    ap.add_argument("--require-units", action="store_true")
    args = ap.parse_args()
    bad = 0
    for path in args.files:
        try:
            errors = check_file(path, args.require_units)
        except OSError as e:
            errors = [f"cannot open: {e}"]
        for e in errors:
            print(f"{path}: {e}")
        if not errors:
            print(f"{path}: ok")
        bad += bool(errors)
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
