"""ESA's LISA orbit files as a reference for heliocentric runs (the LISA studies' comparisons).

ESA's three CReMA 2.0 orbit files (shipped in ``tqdyn/data/esa-lisa-orbits``,
:func:`tqdyn.readers.oem.esa_lisa_orbit_files`), TDB, read as Sun-centred
states with their "EME2000" axes taken as ICRF, as the built-in scenarios
read them (docs/lisa-orbits.md; :func:`tqdyn.astro.oem_states.to_heliocentric`
without the frame bias).  SI units; times in TDB seconds since a run's epoch.
"""

from __future__ import annotations

import numpy as np

from ..astro.constants import DAY_S

__all__ = ["esa_orbits", "esa_records", "esa_states_on_grid"]

_CACHE: dict = {}


def esa_orbits():
    """ESA's three orbits (:class:`tqdyn.readers.oem.OemTrajectory`, satellites 1, 2, 3), Sun-centred, ICRF
    axes, TDB; read once per process (the result is shared: do not modify it)."""
    if "orbits" not in _CACHE:
        from ..astro.oem_states import to_heliocentric
        from ..readers.oem import esa_lisa_orbit_files, read_oem

        _CACHE["orbits"] = [to_heliocentric(read_oem(p), eme2000_frame_bias=False)
                            for p in esa_lisa_orbit_files("TDB")]
    return _CACHE["orbits"]


def esa_states_on_grid(traj) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """ESA's orbits interpolated (Hermite, as the files say) at the rows of a heliocentric trajectory ``traj``
    that lie inside the files' span: (row indices (M,), R (M, 3, 3) [m], V (M, 3, 3) [m/s])."""
    from ..astro.oem_states import states_at

    esa = esa_orbits()
    ep = traj.epoch.tdb
    hi, lo = traj.dd("t")
    t = hi + lo
    end = ((esa[0].stop[0] - ep[0]) + (esa[0].stop[1] - ep[1])) * DAY_S if esa[0].stop else np.inf
    rows = np.nonzero(t <= end)[0]
    st = [states_at(o, ep[0], ep[1] + t[rows] / DAY_S) for o in esa]
    return rows, np.stack([s[0] for s in st], 1), np.stack([s[1] for s in st], 1)


def esa_records(t_end_s: float, epoch_tdb) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """ESA's records from ``epoch_tdb`` (two-part TDB JD) to ``t_end_s`` [s] after it (1 s margin at each end):
    (t [s] (M,), R [m], V [m/s], A [m/s^2], each (M, 3, 3))."""
    esa = esa_orbits()
    td = ((esa[0].jd1 - epoch_tdb[0]) + (esa[0].jd2 - epoch_tdb[1])) * DAY_S
    sel = (td >= -1.0) & (td <= t_end_s + 1.0)
    return (td[sel], np.stack([o.r[sel] for o in esa], 1), np.stack([o.v[sel] for o in esa], 1),
            np.stack([o.a[sel] for o in esa], 1))
