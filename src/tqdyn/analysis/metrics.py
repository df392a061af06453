"""Metrics of tqdyn trajectories: breathing angles, orbit deviations, the
secular along-track drift, the flight-axis check, range ASDs against the
requirement and the control maxima.

Conventions: SI units (m, s, m/s^2, rad), GCRS for inertial vectors, S /
OA_l frames for control quantities as stored in the trajectory
(:data:`tqdyn.formats.trajectory.FIELDS`), time in TT seconds since the
scenario epoch.  Ranges are formed and differenced in double-double before
any float64 rounding (:mod:`tqdyn.lightpath`, :mod:`tqdyn.analysis.spectra`);
the ASDs use the default Kaiser-window Welch estimate of the second dd
difference (:func:`tqdyn.analysis.spectra.range_asd`) and are compared with
the requirement 0.3 pm/Hz^1/2 sqrt(1 + (7 mHz/f)^4) from max(0.1 mHz, 26
Welch bins) to the Nyquist frequency (the lowest ~26 bins are biased, see
the spectra module).

Orbit deviations: |r_run(t) - r_ref(t)| per satellite on the rows both runs
share, and its components along the reference's along-track direction
t_hat = h_hat x r_hat (h_hat = r x v / |r x v|).  The secular along-track
drift that a small acceleration f (radial f_r, along-track f_t) causes on a
near-circular orbit of mean motion n is, from the averaged Hill
(Clohessy-Wiltshire) equations with zero initial relative state,

    delta_t(T) = -3 int_0^T (T - s) f_t(s) ds - (2 / n) int_0^T f_r(s) ds,

(:func:`secular_along_track_drift`); for a constant f_t it is -3/2 f_t T^2
(a forward push makes the satellite fall behind).  The report evaluates it
with the stored drag-free acceleration G_i to explain the drag-free orbit's
deviation from the gravity orbit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..astro.constants import GM_EARTH_EGM2008
from ..constellation import geometry
from ..constellation.indices import Link
from ..lightpath import light_travel_times
from . import spectra

__all__ = [
    "BREATHING_BAND_DEG",
    "AsdResult",
    "Deviation",
    "breathing_angles_of",
    "flight_axis_check",
    "orbit_deviation",
    "range_asd_in_band",
    "secular_along_track_drift",
]

#: Constellation-stability requirement on the breathing angles [deg]: 60 +- 0.1.
BREATHING_BAND_DEG = (59.9, 60.1)

_RELIABLE_BINS = 26  # lowest reliable Welch bin of the default Kaiser window (spectra module)


def _t(traj) -> np.ndarray:
    hi, lo = traj.dd("t")
    return hi + lo


def _dd(traj, name):
    return traj.dd(name)


def breathing_angles_of(traj) -> np.ndarray:
    """Breathing angles alpha_i (N, 3) [rad] of a trajectory, from its dd
    satellite positions (:func:`tqdyn.constellation.geometry.breathing_angles`;
    the same for coupled and pure-gravity runs)."""
    alpha, _, _ = geometry.breathing_angles(geometry.arms(traj.dd("sat/r")))
    return alpha


def _common_rows(t_a, t_b):
    common, ia, ib = np.intersect1d(np.round(t_a, 6), np.round(t_b, 6), return_indices=True)
    return common, ia, ib


@dataclass(frozen=True)
class Deviation:
    """Orbit deviation of a run from a reference on their common rows.

    t : (M,) [s]; d : (M, n_sat, 3) [m] GCRS, r_run - r_ref (formed from the
    dd parts); norm : (M, n_sat) [m]; radial, along, cross : (M, n_sat) [m],
    components along the reference's r_hat, t_hat = h_hat x r_hat, h_hat."""

    t: np.ndarray
    d: np.ndarray
    norm: np.ndarray
    radial: np.ndarray
    along: np.ndarray
    cross: np.ndarray


def orbit_deviation(run, ref) -> Deviation | None:
    """:class:`Deviation` of trajectory ``run`` from trajectory ``ref`` (same
    epoch assumed: compare ``attrs["epoch_utc"]`` first); None if they share
    no time row or no satellite count."""
    if run.n_sat != ref.n_sat:
        return None
    t, ia, ib = _common_rows(_t(run), _t(ref))
    if t.size == 0:
        return None
    ah, al = run.dd("sat/r")
    bh, bl = ref.dd("sat/r")
    d = (ah[ia] - bh[ib]) + (al[ia] - bl[ib])
    r = bh[ib] + bl[ib]
    v = ref["sat/v"][ib]
    rh = r / np.linalg.norm(r, axis=-1, keepdims=True)
    h = np.cross(r, v)
    hh = h / np.linalg.norm(h, axis=-1, keepdims=True)
    th = np.cross(hh, rh)
    def dot(a, b):
        return np.einsum("...k,...k->...", a, b)

    return Deviation(t=t, d=d, norm=np.linalg.norm(d, axis=-1), radial=dot(d, rh), along=dot(d, th),
                     cross=dot(d, hh))


def secular_along_track_drift(t, r, v, f) -> np.ndarray:
    """Secular along-track drift [m] caused by a small acceleration f on a near-circular orbit.

    t : (N,) [s] increasing; r, v : (N, n_sat, 3) [m, m/s] GCRS (the
    perturbed orbit is fine: f is small); f : (N, n_sat, 3) [m/s^2] GCRS.
    Returns (N, n_sat): -3 int_0^t (t - s) f_t ds - (2/n) int_0^t f_r ds
    (module docstring), f_t = f . t_hat, f_r = f . r_hat, n = sqrt(GM / a^3)
    with a the mean |r| (GM: EGM2008), integrals by the trapezoidal rule.
    """
    from scipy.integrate import cumulative_trapezoid

    t = np.asarray(t, np.float64)
    r = np.asarray(r, np.float64)
    v = np.asarray(v, np.float64)
    f = np.asarray(f, np.float64)
    rn = np.linalg.norm(r, axis=-1, keepdims=True)
    rh = r / rn
    h = np.cross(r, v)
    th = np.cross(h / np.linalg.norm(h, axis=-1, keepdims=True), rh)
    ft = np.einsum("...k,...k->...", f, th)
    fr = np.einsum("...k,...k->...", f, rh)
    n = np.sqrt(float(GM_EARTH_EGM2008) / np.mean(rn[..., 0], axis=0) ** 3)  # (n_sat,)
    Ft = cumulative_trapezoid(ft, t, axis=0, initial=0.0)
    FFt = cumulative_trapezoid(Ft, t, axis=0, initial=0.0)
    Fr = cumulative_trapezoid(fr, t, axis=0, initial=0.0)
    return -3.0 * FFt - 2.0 / n * Fr


def flight_axis_check(traj) -> np.ndarray:
    """Y_S . v / |v| (N, 3) of a coupled trajectory: -1 when the flight
    direction is -Y_S (the convention of :data:`tqdyn.workflows.studies.FLIGHT_DIRECTION_S`)."""
    T = traj["sat/T_S_I"]
    v = traj["sat/v"]
    return np.einsum("nsk,nsk->ns", T[:, :, 1, :], v) / np.linalg.norm(v, axis=-1)


@dataclass(frozen=True)
class AsdResult:
    """A range ASD and its comparison with the requirement.

    f [Hz], asd [m/Hz^1/2] (M,); f_reliable : lowest reliable frequency
    (26 Welch bins) [Hz]; band : (f_lo, f_hi) compared [Hz]; max_ratio :
    largest ASD / requirement in the band (NaN if the band is empty);
    f_at_max [Hz]; f_above : highest band frequency where the ASD is at or
    above the requirement [Hz] (None if nowhere)."""

    f: np.ndarray
    asd: np.ndarray
    f_reliable: float
    band: tuple
    max_ratio: float
    f_at_max: float
    f_above: float | None = None

    def describe(self) -> str:
        """"<max ratio> at <f> Hz" (+ "; above the requirement up to <f> Hz")."""
        if not np.isfinite(self.max_ratio):
            return "n/a (run too short for the band)"
        text = f"{self.max_ratio:.3g} at {self.f_at_max:.3g} Hz"
        if self.f_above is not None:
            text += f"; >= 1 up to {self.f_above:.3g} Hz only"
        return text


def range_asd_in_band(t, hi, lo=None) -> AsdResult:
    """ASD of a dd range series [m] (:func:`tqdyn.analysis.spectra.range_asd`,
    second dd difference) and its largest ratio to the requirement over
    [max(0.1 mHz, 26 Welch bins), min(1 Hz, Nyquist)].  Rows with NaN (a
    light path's first row) are dropped from the start; t (N,) [s] uniform."""
    t = np.asarray(t, np.float64)
    hi = np.asarray(hi, np.float64)
    lo = np.zeros_like(hi) if lo is None else np.asarray(lo, np.float64)
    ok = np.isfinite(hi) & np.isfinite(lo)
    first = int(np.argmax(ok))
    t, hi, lo = t[first:], hi[first:], lo[first:]
    if not np.all(np.isfinite(hi)):
        raise ValueError("range: NaN values after the first finite row")
    f, a = spectra.range_asd(t, hi, lo)
    dt = float(np.median(np.diff(t)))
    nperseg, _ = spectra.default_segments(hi.size - 2)
    f_rel = _RELIABLE_BINS / (nperseg * dt)
    f_lo = max(1e-4, f_rel)
    f_hi = min(1.0, 0.5 / dt)
    if f_lo >= f_hi or not np.any((f >= f_lo) & (f <= f_hi)):
        return AsdResult(f, a, f_rel, (f_lo, f_hi), float("nan"), float("nan"))
    ratio, fmax = spectra.band_limited_max_ratio(f, a, dt, band=(f_lo, f_hi))
    sel = (f >= f_lo) & (f <= f_hi)
    over = f[sel][a[sel] >= spectra.requirement_asd(f[sel])]
    return AsdResult(f, a, f_rel, (f_lo, f_hi), ratio, fmax, float(over.max()) if over.size else None)


def _sat_acceleration(traj) -> np.ndarray:
    """Total acceleration of the satellites [m/s^2] GCRS: gravity + G_i when the drag-free control acts."""
    acc = np.asarray(traj["sat/a_gravity"], np.float64)
    if traj.attrs.get("control") == "on" and "sat/a_dragfree" in traj:
        acc = acc + traj["sat/a_dragfree"]
    return acc


def _sat_light_path(traj):
    """Light paths between satellite centres (c tau, six links)."""
    return light_travel_times(traj.dd("t"), traj.dd("sat/r"), traj.dd("sat/v"), _sat_acceleration(traj),
                              note="satellite centre of mass to satellite centre of mass")


def _uniform(t) -> bool:
    if t.size < 3:
        return False
    d = np.diff(t)
    return bool(np.all(d > 0) and np.max(np.abs(d - np.median(d))) <= 1e-6 * np.median(d))


def _link_dd(pair, link: Link):
    return pair[0][:, link.index], pair[1][:, link.index]


def _diff_dd(a, b):
    from ..numerics.dd import np_dd_add

    return np_dd_add(a[0], a[1], -b[0], -b[1])


def _control_values(tr) -> dict:
    """Maxima of the control magnitudes of a coupled run: |A| (TM suspension,
    m/s^2), |alpha| (rad/s^2), |G| (m/s^2), |A_1 - A_2| (the two TMs' actuation
    compared in S) over the run and over its first day (``*_day1``)."""
    A = tr["tm/a_suspension"]
    W = tr["tm/alpha_suspension"]
    G = tr["sat/a_dragfree"]
    # OA_l is S turned by the MOSA angle phi about Z_S: X_OA = (cos, sin, 0), Y_OA = (-sin, cos, 0) in S
    ang = tr["mosa/angle"]
    c, s = np.cos(ang), np.sin(ang)
    A_S = np.stack([A[..., 0] * c - A[..., 1] * s, A[..., 0] * s + A[..., 1] * c, A[..., 2]], -1)
    dA = np.linalg.norm(A_S[:, :, 0] - A_S[:, :, 1], axis=-1)
    nA, nW, nG = (np.linalg.norm(x, axis=-1) for x in (A, W, G))
    t = _t(tr)
    day1 = t - t[0] <= 86400.0
    return {"max_A": float(nA.max()), "max_alpha": float(nW.max()), "max_G": float(nG.max()),
            "max_dA": float(dA.max()), "max_G_per_sat": nG.max(axis=0), "max_A_per_sat": nA.max(axis=(0, 2)),
            "max_A_day1": float(nA[day1].max()), "max_alpha_day1": float(nW[day1].max()),
            "max_G_day1": float(nG[day1].max())}
