"""Export a tqdyn trajectory as CCSDS OEM files (one per satellite): the job
behind ``tqdyn export RUN.h5 --format oem OUT.oem``.

Mission-analysis tools (GMAT, Orekit, STK) read OEM 2.0.  The files carry
the trajectory's own system -- heliocentric runs: ``CENTER_NAME = SUN``,
``REF_FRAME = ICRF``, ``TIME_SYSTEM = TDB``; geocentric runs: ``EARTH``,
``GCRF``, ``TT`` -- with the epochs TDB(epoch) + t or TT(epoch) + t (1 ns
digits), positions and velocities of every output row (16 significant
digits in km, km/s: the dd values rounded), Hermite interpolation of degree
7 (:mod:`tqdyn.formats.oem`).  The CCSDS standard allows one object per
OEM file, so a constellation gives one file per satellite:
``OUT-<satellite name>.oem`` beside ``OUT.oem`` (``OUT.oem`` itself for a
single satellite).  Everything is checked before the first file is written;
each file is written atomically.
"""

from __future__ import annotations

import pathlib

from ..astro.timescales import tdb_after, tt_jd
from ..formats import trajectory as _io
from ..formats.atomic import check_output
from ..formats.oem import OemSegment, write_oem_files

__all__ = ["export_oem"]


def export_oem(run_file, out_file) -> list[pathlib.Path]:
    """Write the satellites of the trajectory ``run_file`` as OEM files named
    after ``out_file`` (see the module docstring); returns the paths.
    Raises FileNotFoundError / ValueError (one line) / OutputError."""
    out = pathlib.Path(out_file)
    if out.suffix.lower() != ".oem":
        raise ValueError(f"OUT: {str(out)!r} does not end in .oem; allowed: a file name ending in .oem")
    traj = _io.read_trajectory(run_file)
    ref = traj.reference
    if ref.central_body == "sun":
        jd, make = tdb_after, OemSegment.heliocentric
    elif ref.time_scale == "TT":
        jd, make = tt_jd, OemSegment.geocentric
    else:
        raise ValueError(f"{run_file}: a format-version-1 trajectory (t labelled TDB); allowed: files of tqdyn 0.2")
    jd1, jd2 = jd(traj.epoch, *traj.dd("t"))
    r, v = traj["sat/r"], traj["sat/v"]  # (N, n_sat, 3) [m, m/s]: hi + lo, 16 digits as written
    names = traj.satellite_names  # the scenario's [[satellites]] names (Sat1, ... if absent)
    segs = [make(name, jd1, jd2, r[:, k], v[:, k],
                 comments=(f"tqdyn trajectory {pathlib.Path(run_file).name}, satellite {k + 1} of {len(names)}",))
            for k, name in enumerate(names)]
    pattern = out.name if len(names) == 1 else f"{out.stem}-{{object_name}}.oem"
    for name in names:
        check_output(out.parent / pattern.format(object_name=name), "OUT", {"RUN.h5": run_file})
    return write_oem_files(out.parent if str(out.parent) else ".", segs, name=pattern)
