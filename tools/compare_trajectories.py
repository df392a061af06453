"""Compare the HDF5 files of two output folders (see builtin_outputs.sh):
every dataset bit for bit, every attribute by value.

    python tools/compare_trajectories.py DIR_A DIR_B [--ignore-attr NAME ...]

Prints one line per file (identical, or the first differences with their
largest absolute difference) and exits 1 if any file differs.
"""

import argparse
import pathlib
import sys

import h5py
import numpy as np


def _items(h5):
    out = {}
    h5.visititems(lambda name, obj: out.__setitem__(name, obj))
    return out


def compare(a, b, ignore_attrs=()):
    diffs = []
    with h5py.File(a, "r") as fa, h5py.File(b, "r") as fb:
        for obj_a, obj_b, where in [(fa, fb, "/")]:
            ka = {k for k in obj_a.attrs if k not in ignore_attrs}
            kb = {k for k in obj_b.attrs if k not in ignore_attrs}
            if ka != kb:
                diffs.append(f"root attributes differ: {sorted(ka ^ kb)}")
            for k in sorted(ka & kb):
                va, vb = obj_a.attrs[k], obj_b.attrs[k]
                if not np.array_equal(np.asarray(va), np.asarray(vb)):
                    diffs.append(f"attribute {k!r}: {str(va)[:60]!r} != {str(vb)[:60]!r}")
        ia, ib = _items(fa), _items(fb)
        if set(ia) != set(ib):
            diffs.append(f"objects differ: {sorted(set(ia) ^ set(ib))}")
        for name in sorted(set(ia) & set(ib)):
            oa, ob = ia[name], ib[name]
            for k in set(oa.attrs) | set(ob.attrs):
                if k in ignore_attrs:
                    continue
                if k not in oa.attrs or k not in ob.attrs or not np.array_equal(np.asarray(oa.attrs[k]),
                                                                                np.asarray(ob.attrs[k])):
                    diffs.append(f"{name}: attribute {k!r} differs")
            if isinstance(oa, h5py.Dataset):
                xa, xb = oa[()], ob[()]
                if xa.shape != xb.shape:
                    diffs.append(f"{name}: shape {xa.shape} != {xb.shape}")
                elif xa.tobytes() != xb.tobytes():
                    d = np.nanmax(np.abs(xa.astype(float) - xb.astype(float))) if xa.dtype.kind == "f" else "?"
                    diffs.append(f"{name}: values differ (max |diff| {d})")
    return diffs


def main():
    p = argparse.ArgumentParser()
    p.add_argument("a")
    p.add_argument("b")
    p.add_argument("--ignore-attr", action="append", default=[])
    args = p.parse_args()
    bad = 0
    for fa in sorted(pathlib.Path(args.a).glob("*.h5")):
        fb = pathlib.Path(args.b) / fa.name
        if not fb.exists():
            print(f"{fa.name}: missing in {args.b}")
            bad += 1
            continue
        d = compare(fa, fb, args.ignore_attr)
        print(f"{fa.name}: " + ("identical" if not d else "DIFFERENT\n    " + "\n    ".join(d[:8])))
        bad += bool(d)
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
