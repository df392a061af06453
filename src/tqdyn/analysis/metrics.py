"""Metrics of tqdyn trajectories: arm lengths and their rates, breathing
angles, the design values and stability constraints of the three
constellations (:class:`ConstellationReference`), orbit deviations, the
secular along-track drift, the flight-axis check, range ASDs against the
requirement, the control maxima and the actuation per axis.

Conventions: SI units (m, s, m/s^2, rad), the file's inertial frame (GCRS
for geocentric, the Sun-centred BCRS for heliocentric runs) for inertial
vectors, S / OA_l frames for control quantities as stored in the trajectory
(:data:`tqdyn.formats.trajectory.FIELDS`), time in seconds since the
scenario epoch in the file's time scale (TT geocentric, TDB heliocentric).  Ranges are formed and differenced in double-double before
any float64 rounding (:mod:`tqdyn.lightpath`, :mod:`tqdyn.analysis.spectra`);
the ASDs use the default Kaiser-window Welch estimate of the second dd
difference (:func:`tqdyn.analysis.spectra.range_asd`) and are compared with
the requirement 0.3 pm/Hz^1/2 sqrt(1 + (7 mHz/f)^4) from max(0.1 mHz, 26
Welch bins) to the Nyquist frequency (the lowest ~26 bins are biased, see
the spectra module).

Orbit deviations: |r_run(t) - r_ref(t)| per satellite on the rows both runs
share, and its components along the reference's along-track direction
t_hat = h_hat x r_hat (h_hat = r x v / |r x v|).  The secular along-track
drift that a small acceleration causes on a near-circular orbit (the Hill
equations' model, :func:`tqdyn.constellation.estimates.secular_along_track_drift`,
re-exported here) explains, with the stored drag-free acceleration G_i, the
drag-free orbit's deviation from the gravity orbit in the report.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..constellation import geometry
from ..constellation.estimates import secular_along_track_drift
from ..constellation.indices import Link
from ..lightpath import light_travel_times
from . import spectra

__all__ = [
    "BREATHING_BAND_DEG",
    "LISA",
    "TAIJI",
    "TIANQIN",
    "AsdResult",
    "ConstellationReference",
    "Deviation",
    "actuation_values",
    "arm_lengths_of",
    "breathing_angles_of",
    "common_rows",
    "control_terms",
    "control_values",
    "dd_difference",
    "flight_axis_check",
    "is_uniform_grid",
    "link_of",
    "orbit_deviation",
    "range_asd_in_band",
    "sat_light_travel_times",
    "sat_positions",
    "secular_along_track_drift",
    "times_s",
]

#: Constellation-stability requirement on the breathing angles [deg]: 60 +- 0.1.
BREATHING_BAND_DEG = (59.9, 60.1)

_RELIABLE_BINS = 26  # lowest reliable Welch bin of the default Kaiser window (spectra module)


@dataclass(frozen=True)
class ConstellationReference:
    """The design values and stability constraints a report compares a
    constellation with.

    name : "TianQin", "LISA" or "Taiji"; arm_m [m] : the nominal arm length
    and ``arm_source`` where it comes from; arm_band_m : (min, max) [m] the
    arms must stay in, or None; breathing_band_deg : (min, max) [deg] of the
    breathing (corner) angles, or None; arm_rate_max : the largest |dL/dt|
    [m/s] allowed, or None; ``constraint_source`` where the bands come from.
    """

    name: str
    arm_m: float
    arm_source: str
    arm_band_m: tuple | None = None
    breathing_band_deg: tuple | None = None
    arm_rate_max: float | None = None
    constraint_source: str = ""

    def with_arm(self, arm_m: float, source: str) -> "ConstellationReference":
        """The same constraints with another nominal arm length [m] (e.g. the scenario's design)."""
        from dataclasses import replace

        return replace(self, arm_m=float(arm_m), arm_source=source)


#: TianQin: an equilateral triangle inscribed in a geocentric circular orbit of radius 1e5 km, so
#: L = sqrt(3) x 1e5 km; the breathing-angle requirement 60 +- 0.1 deg of the TianQin paper.
TIANQIN = ConstellationReference("TianQin", 3 ** 0.5 * 1e8, "sqrt(3) x 1e5 km: the triangle in TianQin's 1e5 km orbit",
                                 breathing_band_deg=BREATHING_BAND_DEG, constraint_source="the TianQin paper")
#: LISA: ESA's design arm 2.5e6 km and the stability constraints of ESA's trajectory design (Martens &
#: Joffre 2021, "Trajectory design for the ESA LISA mission", arXiv:2101.03040): corner angles 60 +- 1.0 deg,
#: arm-length rate <= 10 m/s, arms 2.5e6 km +- 2.5e5 km.
LISA = ConstellationReference("LISA", 2.5e9, "ESA's LISA design, 2.5e6 km", arm_band_m=(2.25e9, 2.75e9),
                              breathing_band_deg=(59.0, 61.0), arm_rate_max=10.0,
                              constraint_source="ESA's LISA trajectory design (Martens & Joffre 2021)")
#: Taiji: the design arm 3e6 km (no public stability constraints are used).
TAIJI = ConstellationReference("Taiji", 3.0e9, "Taiji's design, 3e6 km")


def arm_lengths_of(traj) -> tuple[np.ndarray, np.ndarray | None]:
    """Instantaneous arm lengths L_12, L_23, L_31 (N, 3) [m] of a
    three-satellite trajectory, from its dd satellite positions (no light
    time), and their rates dL/dt = (v_j - v_i) . n_ij (N, 3) [m/s] (None
    without ``sat/v``).  Any central body and frame (a length and its rate
    do not depend on the axes); t in the file's time scale."""
    _need_triangle(traj, "arm lengths")
    a = geometry.arms(traj.dd("sat/r"), traj.dd("sat/v") if "sat/v" in traj else None)
    rate = None if a.length_dot is None else a.length_dot[..., :3]
    return a.length[..., :3], rate


def times_s(traj) -> np.ndarray:
    """Row times (N,) [s since the file's epoch, in its time scale] of a
    trajectory, rounded to float64 (hi + lo): for plotting and for matching
    rows, never for differences that need the dd time."""
    hi, lo = traj.dd("t")
    return hi + lo


def sat_positions(traj) -> np.ndarray:
    """Satellite positions (N, n_sat, 3) [m] of a trajectory in its inertial frame, float64 (hi + lo of the dd
    field ``sat/r``; differences of positions are better formed from the dd pair, as
    :mod:`tqdyn.constellation.geometry` does)."""
    hi, lo = traj.dd("sat/r")
    return hi + lo


def _dd(traj, name):
    return traj.dd(name)


def breathing_angles_of(traj) -> np.ndarray:
    """Breathing angles alpha_i (N, 3) [rad] of a trajectory, from its dd
    satellite positions (:func:`tqdyn.constellation.geometry.breathing_angles`;
    the same for coupled and pure-gravity runs)."""
    _need_triangle(traj, "breathing angles")
    alpha, _, _ = geometry.breathing_angles(geometry.arms(traj.dd("sat/r")))
    return alpha


def _need_triangle(traj, what: str) -> None:
    """ValueError (one line) unless the trajectory holds the 3 satellites of a
    triangle: arms and breathing angles are defined for 3 (a point-mass run
    may have any number)."""
    n_sat = traj.dd("sat/r")[0].shape[1]
    if n_sat != 3:
        raise ValueError(f"trajectory: n_sat = {n_sat}; {what} are defined for the 3 satellites of a "
                         "triangular constellation; allowed: a trajectory of 3 satellites")


def common_rows(t_a, t_b):
    """(t, ia, ib): the times [s] two row grids share (matched to 1 us) and
    their row indices in each."""
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
    t, ia, ib = common_rows(times_s(run), times_s(ref))
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


def sat_light_travel_times(traj):
    """Light paths between satellite centres (c tau, six links)."""
    return light_travel_times(traj.dd("t"), traj.dd("sat/r"), traj.dd("sat/v"), _sat_acceleration(traj),
                              note="satellite centre of mass to satellite centre of mass")


def is_uniform_grid(t) -> bool:
    """True if the times ``t`` (N,) [s] are increasing with a constant step
    (to 1e-6 of the median step) and there are at least three."""
    if t.size < 3:
        return False
    d = np.diff(t)
    return bool(np.all(d > 0) and np.max(np.abs(d - np.median(d))) <= 1e-6 * np.median(d))


def link_of(pair, link: Link):
    """The (hi, lo) series (N,) of ``link`` from a dd pair of per-link arrays (N, 6)."""
    return pair[0][:, link.index], pair[1][:, link.index]


def dd_difference(a, b):
    """a - b of two dd pairs (hi, lo), in dd."""
    from ..numerics.dd import np_dd_add

    return np_dd_add(a[0], a[1], -b[0], -b[1])


def control_values(tr) -> dict:
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
    t = times_s(tr)
    day1 = t - t[0] <= 86400.0
    return {"max_A": float(nA.max()), "max_alpha": float(nW.max()), "max_G": float(nG.max()),
            "max_dA": float(dA.max()), "max_G_per_sat": nG.max(axis=0), "max_A_per_sat": nA.max(axis=(0, 2)),
            "max_A_day1": float(nA[day1].max()), "max_alpha_day1": float(nW[day1].max()),
            "max_G_day1": float(nG[day1].max())}


def actuation_values(tr) -> dict:
    """The actuation of a coupled run per axis (maxima over the run, m/s^2):

    ``A_axis`` (n_sat, 2, 3): max |A_l . x|, |A_l . y|, |A_l . z| of the TM
    suspension per satellite, TM l and axis of OA_l (x = X_OA_l the optical
    axis); ``A_sensitive`` (n_sat, 2): max |A_l . e_l| along TM l's sensitive
    axis e_l (from the file's spacecraft attributes, :attr:`Trajectory.spacecraft`:
    zero to round-off when the drag-free control follows the TM there);
    ``A_max`` (n_sat,): max |A_l| over both TMs; ``G_axis_S`` (n_sat, 3): max
    |G . X_S|, |G . Y_S|, |G . Z_S| of the drag-free acceleration in the body
    frame S (G stored in the inertial frame, turned with ``sat/T_S_I``);
    ``G_mean_S`` (n_sat, 3): its mean components in S; ``G_max`` (n_sat,):
    max |G|; ``alpha_max`` (n_sat,): max |alpha_l| [rad/s^2]."""
    A = tr["tm/a_suspension"]
    G = tr["sat/a_dragfree"]
    G_S = np.einsum("nsij,nsj->nsi", tr["sat/T_S_I"], G)
    craft = tr.spacecraft
    e = craft.sensitive_axes if craft is not None else np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    along = np.abs(np.einsum("nslk,lk->nsl", A, e))
    return {"A_axis": np.abs(A).max(axis=0), "A_sensitive": along.max(axis=0),
            "A_max": np.linalg.norm(A, axis=-1).max(axis=(0, 2)), "G_axis_S": np.abs(G_S).max(axis=0),
            "G_mean_S": G_S.mean(axis=0), "G_max": np.linalg.norm(G, axis=-1).max(axis=0),
            "alpha_max": np.linalg.norm(tr["tm/alpha_suspension"], axis=-1).max(axis=(0, 2))}


def control_terms(tr, d: float, gm: float) -> dict:
    """Max magnitudes [m/s^2] of the terms of g_l (:mod:`tqdyn.constellation.control`) along a coupled
    heliocentric run, its TMs at d [m] from the CoM on the optical axes (pivots at the CoM): the tide of a
    point mass ``gm`` [m^3/s^2] at the origin (first order in d), the centrifugal and Euler terms of S, their
    sum (``rigid``), and the MOSA terms (:func:`tqdyn.constellation.control.tm_relative_acceleration` term by
    term), with the beam opening angle's rates ``alpha_dot_max`` [rad/s], ``alpha_ddot_max`` [rad/s^2] by
    central differences of ``mosa/angle``; the two rows at each end are left out.  {} for runs of < 5 rows."""
    from ..constellation.control import mosa_angular_rates, tm_relative_acceleration

    t = times_s(tr)
    if t.size < 5:
        return {}
    r = sat_positions(tr)
    T = tr["sat/T_S_I"]
    w, wd = tr["sat/omega"], tr["sat/omega_dot"]
    th = 2.0 * tr["mosa/angle"][..., 0]
    ad = np.gradient(th, t, axis=0)
    add = np.gradient(ad, t, axis=0)
    u = np.array([np.cos(0.5 * th), np.sin(0.5 * th)])
    r0 = d * np.stack([np.stack([u[0], u[1], 0 * u[0]], -1), np.stack([u[0], -u[1], 0 * u[0]], -1)], -2)
    r0I = np.einsum("nsji,nslj->nsli", T, r0)
    rn = np.linalg.norm(r, axis=-1)[..., None, None]
    rh = (r / rn[..., 0])[:, :, None, :]
    tide = np.einsum("nsij,nslj->nsli", T, gm / rn ** 3 * (3 * np.sum(rh * r0I, -1, keepdims=True) * rh - r0I))
    wm, wmd = mosa_angular_rates(ad, add)
    zero, still = np.zeros_like(r0), np.zeros_like(w)
    cf = tm_relative_acceleration(zero, w, still, zero, zero, r0, zero)
    eu = tm_relative_acceleration(zero, still, wd, zero, zero, r0, zero)
    mosa = tm_relative_acceleration(zero, w, still, wm, wmd, zero, r0)
    sl = slice(2, -2)  # central differences only
    m = {k: float(np.linalg.norm(v[sl], axis=-1).max()) for k, v in
         (("tide", tide), ("centrifugal", cf), ("euler", eu), ("rigid", tide + cf + eu), ("mosa", mosa))}
    m["alpha_dot_max"] = float(np.abs(ad[sl]).max())
    m["alpha_ddot_max"] = float(np.abs(add[sl]).max())
    return m
