"""Pointing-law comparison along a trajectory: the paper's Fig. 5.

For every reception time of a trajectory's grid the incoming-beam directions
of the three satellites are computed under the approximate laws ``global``,
``taylor1`` and ``taylor2`` (:mod:`tqdyn.constellation.pointing`) and
compared with the ``iterative`` law (the light-travel-time equation solved
in double-double on the Hermite dense output of the emitters' stored
positions, velocities and accelerations: :func:`tqdyn.lightpath.light_travel_times`
of the satellite centres).

Three error measures per law, all in rad (docs/design.md, Traps: the Taylor errors of
the two beams of one satellite are nearly equal and opposite, so they almost
cancel in X_S and add up in the beam angle theta -- report all three):

* ``per_beam`` (M, 3, 2): angle between the law's beam and the iterative
  beam, per satellite i and MOSA l (MOSA 1 receives from k, MOSA 2 from j);
* ``x_s`` (M, 3): angle between the satellite's X_S axis (bisector of its two
  beams) under the law and under the iterative law;
* ``theta`` (M, 3): |theta_law - theta_iterative|, theta the angle between
  the two beams (twice the MOSA angle).

Also ``tau_error`` (M, 3, 2) [s]: |L/c - tau_iterative| (L the instantaneous
arm length), the cost of the approximation tau ~ L/c the global and Taylor
laws use (~2e-6 s for TianQin, not the paper's 1e-7 s).

Units SI (rad, s); frame GCRS; time TT seconds since the scenario epoch.
The satellites' accelerations that enter ``taylor2`` and the Hermite
interpolation are their *total* accelerations (gravity plus, when the run's
drag-free control is on, the drag-free acceleration G_i).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..constellation import pointing as _pointing
from ..lightpath import light_travel_times

__all__ = ["APPROXIMATE_LAWS", "LawComparison", "PointingStudy", "compare_pointing_laws", "pointing_study_of"]

#: The laws compared with the iterative reference.
APPROXIMATE_LAWS = ("global", "taylor1", "taylor2")


@dataclass(frozen=True)
class LawComparison:
    """Errors of one pointing law against the iterative law, over time.

    law : name; per_beam : (M, 3, 2) [rad] (satellite, MOSA); x_s : (M, 3)
    [rad]; theta : (M, 3) [rad] (see the module docstring).
    """

    law: str
    per_beam: np.ndarray
    x_s: np.ndarray
    theta: np.ndarray

    @property
    def max_per_beam(self) -> float:
        """Largest per-beam error over time, satellites and MOSAs [rad]."""
        return float(np.max(self.per_beam))

    @property
    def max_x_s(self) -> float:
        """Largest X_S error over time and satellites [rad]."""
        return float(np.max(self.x_s))

    @property
    def max_theta(self) -> float:
        """Largest beam-angle (theta) error over time and satellites [rad]."""
        return float(np.max(self.theta))

    def maxima(self) -> dict[str, float]:
        """{"per_beam", "x_s", "theta"}: the three maxima [rad]."""
        return {"per_beam": self.max_per_beam, "x_s": self.max_x_s, "theta": self.max_theta}


@dataclass(frozen=True)
class PointingStudy:
    """All law comparisons on one time series.

    t : (M,) float64 reception times [s, TT since the epoch]; laws : law
    name -> :class:`LawComparison`; tau_error : (M, 3, 2) [s], |L/c -
    tau_iterative|; ltt_residual : largest residual of the light-time equation of the iterative
    light-travel-time solution [s] (its convergence).
    """

    t: np.ndarray
    laws: dict
    tau_error: np.ndarray
    ltt_residual: float

    def maxima(self) -> dict[str, dict[str, float]]:
        """law -> {"per_beam", "x_s", "theta"} maxima [rad]."""
        return {name: c.maxima() for name, c in self.laws.items()}


def _pair(x, name):
    if isinstance(x, tuple):
        hi, lo = (np.asarray(p, np.float64) for p in x)
    else:
        arr = np.asarray(x, np.float64)
        hi, lo = arr, np.zeros_like(arr)
    if hi.shape != lo.shape:
        raise ValueError(f"{name}: hi shape {hi.shape} differs from lo shape {lo.shape}")
    return hi, lo


def compare_pointing_laws(t, R, V, A, *, laws=APPROXIMATE_LAWS, stride: int = 1,
                          tol: float = 1e-20) -> PointingStudy:
    """Compare approximate pointing laws with the iterative law along a trajectory.

    Parameters
    ----------
    t : (N,) grid times [s, TT since the epoch], dd as a (hi, lo) tuple or
        float64; uniformly or non-uniformly spaced, increasing, at least 4 rows.
    R, V : (N, 3, 3) satellite positions [m] and velocities [m/s], GCRS, dd
        (hi, lo) tuples (or float64).
    A : (N, 3, 3) float64 total accelerations [m/s^2], GCRS.
    laws : approximate laws to compare (subset of :data:`APPROXIMATE_LAWS`).
    stride : evaluate every ``stride``-th grid time (the interpolation always
        uses the whole grid); the first row is skipped (its emission time lies
        before the grid).
    tol : convergence threshold of the iterative light travel time [s]
        (Newton correction of :func:`tqdyn.lightpath.light_travel_times`).

    Returns :class:`PointingStudy` with M = len(range(1, N, stride)) times.
    """
    for law in laws:
        if law not in APPROXIMATE_LAWS:
            raise ValueError(f"laws: {law!r} is not an approximate pointing law; allowed: "
                             f"{', '.join(APPROXIMATE_LAWS)}")
    if isinstance(stride, bool) or not isinstance(stride, (int, np.integer)) or stride < 1:
        raise ValueError(f"stride: {stride!r} is not an integer >= 1")
    th, tl = _pair(t, "t")
    rh, rl = _pair(R, "R")
    vh, vl = _pair(V, "V")
    acc = np.asarray(A, np.float64)
    n = th.shape[0]
    if th.ndim != 1 or n < 2:
        raise ValueError(f"t: {th.shape} is not a time axis of at least 2 rows (the dense output interpolates "
                         "between rows)")
    for name, arr in (("R", rh), ("V", vh), ("A", acc)):
        if arr.shape != (n, 3, 3):
            raise ValueError(f"{name}: shape {arr.shape}; allowed: ({n}, 3, 3) (time, satellite, component)")
    lt = light_travel_times((th, tl), (rh, rl), (vh, vl), acc, tol=tol)
    sel = slice(1, None, int(stride))
    ts = (th[sel], tl[sel])
    Rs, Vs, As = (rh[sel], rl[sel]), (vh[sel], vl[sel]), acc[sel]
    it = _pointing.beam_directions("iterative", Rs, light_times=lt.select(sel))
    f_it = _pointing.pointing_frames(it.n)
    out = {}
    approx_tau = None
    for law in laws:
        b = _pointing.beam_directions(law, Rs, Vs, As)
        f = _pointing.pointing_frames(b.n)
        out[law] = LawComparison(law=law, per_beam=_pointing.angle_between(b.n, it.n),
                                 x_s=_pointing.angle_between(f.X_S, f_it.X_S),
                                 theta=np.abs(f.theta - f_it.theta))
        approx_tau = b.tau
    if approx_tau is None:
        approx_tau = _pointing.beam_directions("global", Rs).tau
    return PointingStudy(t=ts[0] + ts[1], laws=out, tau_error=np.abs(approx_tau - it.tau),
                         ltt_residual=float(np.nanmax(np.abs(it.last_step))))


def pointing_study_of(trajectory, *, laws=APPROXIMATE_LAWS, stride: int = 1, max_rows: int | None = None,
                      tol: float = 1e-20) -> PointingStudy:
    """:func:`compare_pointing_laws` on a trajectory object.

    ``trajectory`` is duck-typed like :class:`tqdyn.formats.trajectory.Trajectory`
    (``trajectory.dd(name)``, ``trajectory[name]``, ``name in trajectory``,
    ``trajectory.attrs``).  Uses ``t``, ``sat/r``, ``sat/v`` and the total
    acceleration ``sat/a_gravity`` (+ ``sat/a_dragfree`` when the root
    attribute ``control`` is "on": the drag-free acceleration then acts on
    the orbit).  The grid must be fine enough for the quintic Hermite
    interpolation (the 50 s integrator grid: ``run.output_every = 1``).
    ``max_rows``: use only the first ``max_rows`` rows (None: all).
    """
    for f in ("t", "sat/r", "sat/v", "sat/a_gravity"):
        if f not in trajectory:
            raise ValueError(f"trajectory: has no field {f!r} (the pointing study needs t, sat/r, sat/v, "
                             "sat/a_gravity)")
    n_sat = getattr(trajectory, "n_sat", 3)
    if n_sat != 3:
        raise ValueError(f"trajectory: n_sat = {n_sat}; the pointing study needs the 3 satellites")
    rows = slice(None) if max_rows is None else slice(0, int(max_rows))
    acc = np.asarray(trajectory["sat/a_gravity"], np.float64)
    if getattr(trajectory, "attrs", {}).get("control") == "on" and "sat/a_dragfree" in trajectory:
        acc = acc + np.asarray(trajectory["sat/a_dragfree"], np.float64)

    def dd(name):
        hi, lo = trajectory.dd(name)
        return hi[rows], lo[rows]

    return compare_pointing_laws(dd("t"), dd("sat/r"), dd("sat/v"), acc[rows], laws=laws, stride=stride, tol=tol)
