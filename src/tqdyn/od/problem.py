"""Orbit determination of a point-mass scenario from a tracking plan: the measurement models
(:mod:`.measurements_gnss`, :mod:`.measurements_slr`, :mod:`.measurements_isr`,
:mod:`.measurements_dsn`) chained with the variational equations (:mod:`.variational`) into an
:class:`tqdyn.od.estimator.Problem`.

Tracking plan (:class:`Tracking`): the kinds of tracking (:data:`TRACKING_KINDS`), an arc
[0, arc_s] from the scenario's epoch sampled every ``interval_s`` (a multiple of the run's
``integrator.step``), per-type noise, stations, and the parameter groups (:data:`GROUPS`) that are
estimated or considered.  Measurement types (:data:`MEASUREMENT_TYPES`): GNSS pseudoranges (GPS and
BeiDou MEO transmitters), two-way SLR ranges, absolute inter-satellite ranges (the six links),
two-way deep-space range and range rate.

Measurements (:class:`Measurements`): one row per scalar measurement, ordered by time then type,
satellite and peer; time tags t [s since the epoch, the run's time scale: TT geocentric, TDB
heliocentric] on the sampling grid, which are the models' own time tags (GNSS and ISR: reception at
the satellite; SLR and DSN: the bounce time at the satellite).

Parameters: ``"<satellite>/<name>"``: the initial state components x, y, z [m], vx, vy, vz [m/s]
at the epoch (the run's frame: GCRS geocentric, Sun-centred BCRS axes heliocentric) and the 12
acceleration parameters [m/s^2] of :data:`~tqdyn.dynamics.empirical.PARAMETER_NAMES` (the S-frame
constant = the DC self-gravity of a drag-free orbit; RTN constant; once-per-rev).

Partials.  A measurement z of satellite a (and, for a link, its emitter b) at time t depends on
the states y_a(t), y_b(t); with the full-system state transition matrix Phi(t) = dy(t)/dy(0)
(6 n x 6 n) and sensitivities Psi(t) = dy(t)/dp (6 n x 12 n),

    dz/d(y(0), p) = sum over a, b of  [dz/dr_s, dz/dv_s] [Phi_s(t) | Psi_s(t)],

Phi_s, Psi_s the satellite's six rows: the coupling of the satellites (the S frame, the
self-gravity toward the centre) is kept.

GNSS receiver clock.  Each pseudorange carries the receiver's clock bias c dt [m] of its epoch, a
nuisance parameter per satellite and epoch with no a priori information.  It is eliminated
analytically: the whitened rows of one epoch (n_k pseudoranges, weights w = 1/sigma) are projected
onto the orthogonal complement of w with an orthonormal basis Q (n_k x (n_k - 1)):
y' = s0 Q^T diag(w) y, H' = s0 Q^T diag(w) H, sigma' = s0 (s0 the epoch's smallest sigma; equal
sigmas give y' = Q^T y).  The least-squares estimate and covariance of the other parameters are
exactly those of a fit that estimates every clock bias; an epoch with one pseudorange carries no
information and is dropped.  (Position fixes are not used.)  The post-fit residuals of these rows
are those of the projected measurements.

Refused in one line: coupled runs (attitude or control), GNSS and SLR on heliocentric runs, an
interval off the run's step grid, an arc beyond the ephemeris' span, a named station that never
sees a satellite over the arc, a tracking kind without any visible measurement.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import linalg, sparse

from ..astro.ephemeris import ephemeris_named, planetary_gm
from ..constellation.indices import LINK_EMITTER, LINK_RECEIVER
from ..dynamics.empirical import N_PAR, PARAMETER_NAMES
from ..scenario import load_scenario
from . import estimator
from .measurements_dsn import DEEP_SPACE_STATIONS, DSN_DOPPLER_SIGMA_M_S, DSN_RANGE_SIGMA_M, dsn_tracking
from .measurements_gnss import BEIDOU_MEO, GNSS_SIGMA_M, GPS, pseudorange
from .measurements_isr import ISR_ABSOLUTE_SIGMA_M, isr_range
from .measurements_slr import ILRS_STATIONS, SLR_SIGMA_M, slr_range
from .parameters import STATE_NAMES, OrbitParameters, parameter_names, state_names
from .variational import Partials, propagate_dd, propagate_with_partials

__all__ = ["DEFAULT_SIGMA", "GROUPS", "MEASUREMENT_TYPES", "TRACKING_KINDS", "Measurements", "Tracking",
           "build_problem", "compute", "covariance", "fit", "nominal_parameters", "schedule", "simulate"]

TRACKING_KINDS = ("gnss", "slr", "isr", "dsn")
MEASUREMENT_TYPES = ("gnss_pseudorange", "slr_range", "isr_range", "dsn_range", "dsn_range_rate")
#: Measurement types of each tracking kind.
KIND_TYPES = {"gnss": ("gnss_pseudorange",), "slr": ("slr_range",), "isr": ("isr_range",),
              "dsn": ("dsn_range", "dsn_range_rate")}
#: Default noise per measurement type [m, m/s for dsn_range_rate] (the models' defaults).
DEFAULT_SIGMA = {"gnss_pseudorange": GNSS_SIGMA_M, "slr_range": SLR_SIGMA_M, "isr_range": ISR_ABSOLUTE_SIGMA_M,
                 "dsn_range": DSN_RANGE_SIGMA_M, "dsn_range_rate": DSN_DOPPLER_SIGMA_M_S}
#: Parameter groups: name -> the per-satellite parameter names it holds.
GROUPS = {"state": STATE_NAMES, "s_frame": PARAMETER_NAMES[0:3], "rtn": PARAMETER_NAMES[3:6],
          "rtn_cos": PARAMETER_NAMES[6:9], "rtn_sin": PARAMETER_NAMES[9:12]}
_HELIO_KINDS = ("dsn", "isr")
#: Largest step [s] of the float64 variational equations on geocentric runs (DP87 on TianQin's
#: 3.6-day orbit: the partials agree with dd differences to ~1e-10 at 600 s).
_PARTIALS_STEP_GEOCENTRIC = 600.0
#: Standard deviation [m] of the simulated receiver clock bias per epoch (eliminated by the fit).
CLOCK_SIGMA_M = 1000.0


def _fail(msg: str):
    raise ValueError(" ".join(msg.split()))


@dataclass(frozen=True)
class Tracking:
    """A tracking plan (module docstring).

    kinds: subset of :data:`TRACKING_KINDS`; arc_s [s] from the epoch; interval_s [s] sampling
    interval, a multiple of ``integrator.step``; sigma: {measurement type: sigma [m or m/s]}
    overriding :data:`DEFAULT_SIGMA`; stations: SLR (:data:`~tqdyn.od.measurements_slr.ILRS_STATIONS`)
    and deep-space (:data:`~tqdyn.od.measurements_dsn.DEEP_SPACE_STATIONS`) station names (None:
    all of them); estimate, consider: parameter groups (:data:`GROUPS`); a_priori_sigma: {group:
    sigma} a priori sigmas per group (``"state"``: (sigma_r [m], sigma_v [m/s]); the acceleration
    groups: [m/s^2]), needed for every considered group; gnss_mode: the GNSS reception mode of
    :func:`~tqdyn.od.measurements_gnss.gnss_visibility`."""

    kinds: tuple
    arc_s: float
    interval_s: float = 600.0
    sigma: dict | None = None
    stations: tuple | None = None
    estimate: tuple = ("state", "s_frame")
    consider: tuple = ()
    a_priori_sigma: dict | None = None
    gnss_mode: str = "sidelobes"

    def __post_init__(self):
        kinds = (self.kinds,) if isinstance(self.kinds, str) else tuple(self.kinds)
        for k in kinds:
            if k not in TRACKING_KINDS:
                _fail(f"tracking.kinds: {k!r} is not allowed; allowed: {', '.join(TRACKING_KINDS)}")
        if not kinds or len(set(kinds)) != len(kinds):
            _fail(f"tracking.kinds: {kinds!r}; allowed: distinct kinds of {', '.join(TRACKING_KINDS)}")
        object.__setattr__(self, "kinds", kinds)
        for name in ("arc_s", "interval_s"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                _fail(f"tracking.{name}: {v!r} s; allowed: a finite number > 0")
        if self.interval_s > self.arc_s:
            _fail(f"tracking.interval_s: {self.interval_s} s is longer than the arc ({self.arc_s} s)")
        for key, v in (self.sigma or {}).items():
            if key not in MEASUREMENT_TYPES:
                _fail(f"tracking.sigma: {key!r} is not allowed; allowed: {', '.join(MEASUREMENT_TYPES)}")
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                _fail(f"tracking.sigma[{key!r}] = {v!r}; allowed: a finite number > 0 (m or m/s)")
        for name in ("estimate", "consider"):
            groups = (getattr(self, name),) if isinstance(getattr(self, name), str) else tuple(getattr(self, name))
            for g in groups:
                if g not in GROUPS:
                    _fail(f"tracking.{name}: {g!r} is not allowed; allowed: {', '.join(GROUPS)}")
            object.__setattr__(self, name, groups)
        if not self.estimate:
            _fail(f"tracking.estimate: empty; allowed: groups of {', '.join(GROUPS)}")
        both = set(self.estimate) & set(self.consider)
        if both:
            _fail(f"tracking.consider: {sorted(both)[0]!r} is also estimated; a group is estimated or considered")
        for g, v in (self.a_priori_sigma or {}).items():
            if g not in GROUPS:
                _fail(f"tracking.a_priori_sigma: {g!r} is not allowed; allowed: {', '.join(GROUPS)}")
            vals = np.atleast_1d(np.asarray(v, np.float64))
            if vals.shape != ((2,) if g == "state" else (1,)) or not np.all(vals > 0):
                _fail(f"tracking.a_priori_sigma[{g!r}] = {v!r}; allowed: "
                      + ("(sigma_r m, sigma_v m/s) > 0" if g == "state" else "a number > 0 (m/s^2)"))
        for g in self.consider:
            if g not in (self.a_priori_sigma or {}):
                _fail(f"tracking.consider: {g!r} has no a priori sigma; give tracking.a_priori_sigma[{g!r}]")
        if self.stations is not None:
            st = (self.stations,) if isinstance(self.stations, str) else tuple(self.stations)
            for s in st:
                if s not in ILRS_STATIONS and s not in DEEP_SPACE_STATIONS:
                    _fail(f"tracking.stations: {s!r} is not allowed; allowed: SLR "
                          f"{', '.join(ILRS_STATIONS)}; deep-space {', '.join(DEEP_SPACE_STATIONS)}")
            object.__setattr__(self, "stations", st)

    @property
    def types(self) -> tuple:
        """The measurement types of the plan, in :data:`MEASUREMENT_TYPES` order."""
        return tuple(t for t in MEASUREMENT_TYPES for k in self.kinds if t in KIND_TYPES[k])

    def sigma_of(self, mtype: str) -> float:
        """Noise sigma of a measurement type [m or m/s]."""
        return float((self.sigma or {}).get(mtype, DEFAULT_SIGMA[mtype]))

    def times(self) -> np.ndarray:
        """(n,) sampling times [s since the epoch]: 0, interval, ..., <= arc_s."""
        n = int(math.floor(self.arc_s / self.interval_s * (1 + 1e-12)))
        return np.arange(n + 1) * float(self.interval_s)

    def station_names(self, kind: str):
        """Station names of an SLR or DSN kind (None: the model's defaults)."""
        if self.stations is None:
            return None
        cat = ILRS_STATIONS if kind == "slr" else DEEP_SPACE_STATIONS
        names = [s for s in self.stations if s in cat]
        if not names:
            _fail(f"tracking.stations: none of {list(self.stations)} is a{'n SLR' if kind == 'slr' else ' deep-space'} "
                  f"station (tracking kind {kind!r}); allowed: {', '.join(cat)}")
        return names


@dataclass
class Measurements:
    """Scalar measurements, one row each, ordered by time (module docstring).

    t (m,) [s since the epoch, the run's time scale]; type (m,) str of :data:`MEASUREMENT_TYPES`;
    sat (m,) int satellite index; peer (m,) str: station name, GNSS id ("G07", "C12") or the
    emitting satellite's index; value (m,) [m or m/s] (NaN before simulation); sigma (m,)."""

    t: np.ndarray
    type: np.ndarray
    sat: np.ndarray
    peer: np.ndarray
    value: np.ndarray
    sigma: np.ndarray

    def __len__(self) -> int:
        return int(self.t.size)

    def select(self, mask) -> "Measurements":
        """The rows where mask is true (or the given row indices)."""
        return Measurements(*(np.asarray(a)[mask] for a in (self.t, self.type, self.sat, self.peer, self.value,
                                                              self.sigma)))


# ---------------------------------------------------------------------------------------------
# scenario checks


def _is_helio(scen) -> bool:
    return scen.reference.central_body == "sun"


def _scenario(scenario, tracking: Tracking | None = None):
    """The loaded scenario, checked for orbit determination with the tracking plan."""
    scen = load_scenario(scenario) if isinstance(scenario, str) else scenario
    if scen.constellation.pointing != "none":
        _fail(f"scenario {scen.name!r}: constellation.pointing = {scen.constellation.pointing!r} is a coupled "
              f"(attitude) run; orbit determination needs point-mass satellites (allowed: \"none\", "
              f"e.g. tianqin-gravity, lisa-gravity, lisa-esa)")
    if scen.integrator.mode != "fixed":
        _fail(f'scenario {scen.name!r}: integrator.mode = {scen.integrator.mode!r}; allowed: "fixed"')
    if tracking is None:
        return scen
    if _is_helio(scen):
        for k in tracking.kinds:
            if k not in _HELIO_KINDS:
                _fail(f"tracking.kinds: {k!r} is not allowed for the heliocentric scenario {scen.name!r}; "
                      f"allowed: {', '.join(_HELIO_KINDS)}")
    if "isr" in tracking.kinds and len(scen.satellites) != 3:
        _fail(f"tracking.kinds: 'isr' needs three satellites; scenario {scen.name!r} has {len(scen.satellites)}")
    step = float(scen.integrator.step_s)
    if abs(tracking.interval_s / step - round(tracking.interval_s / step)) > 1e-9:
        _fail(f"tracking.interval_s: {tracking.interval_s} s is not a multiple of integrator.step = {step} s")
    eph = ephemeris_named(scen.forces.ephemeris)
    jd_end = scen.epoch.tdb[0] + scen.epoch.tdb[1] + (tracking.arc_s + 86400.0) / 86400.0
    if jd_end > eph.span_jd[1]:
        _fail(f"tracking.arc_s: {tracking.arc_s} s from the epoch ends beyond the span of the ephemeris "
              f"{eph.name} (JD {eph.span_jd[1]}, less one day for light times); allowed: at most "
              f"{(eph.span_jd[1] - 1.0 - scen.epoch.tdb[0] - scen.epoch.tdb[1]) * 86400.0:.0f} s")
    return scen


def nominal_parameters(scenario) -> OrbitParameters:
    """The scenario's own parameter values: initial states (n_sat, 6, 2) dd [m, m/s] and
    ``[accelerations]`` (n_sat, 12) [m/s^2]."""
    scen = _scenario(scenario)
    _, y = propagate_dd(scen, None, [0.0])
    return OrbitParameters(accelerations=scen.accelerations.values(len(scen.satellites)), y0=y[0])


def _values(par: OrbitParameters) -> np.ndarray:
    """All parameter values in the column order of :func:`compute`: states then accelerations."""
    y0 = par.y0_dd()
    return np.concatenate([(y0[..., 0] + y0[..., 1]).ravel(), np.asarray(par.accelerations, np.float64).ravel()])


def _with_values(nominal: OrbitParameters, index: np.ndarray, q: np.ndarray) -> OrbitParameters:
    """nominal with the parameters at column indices ``index`` (of :func:`compute`) set to q
    (state components: the dd nominal plus the float64 difference, so q = nominal is exact)."""
    y0 = nominal.y0_dd().copy()
    acc = np.array(nominal.accelerations, np.float64)
    n_state = y0.shape[0] * 6
    base = _values(nominal)
    for j, v in zip(index, q):
        if j < n_state:
            y0[j // 6, j % 6, 0] += v - base[j]
        else:
            acc.flat[j - n_state] = v
    return OrbitParameters(accelerations=acc, y0=y0)


def _partials_step(scen, t) -> float:
    """The largest multiple of integrator.step dividing every t [s], at most 600 s geocentric
    (the run's step heliocentric)."""
    run = float(scen.integrator.step_s)
    k = np.rint(np.asarray(t) / run).astype(np.int64)
    g = int(np.gcd.reduce(k[k > 0])) if np.any(k > 0) else 1
    cap = run if _is_helio(scen) else max(run, _PARTIALS_STEP_GEOCENTRIC)
    return run * max(d for d in range(1, g + 1) if g % d == 0 and d * run <= cap)


# ---------------------------------------------------------------------------------------------
# the models on a grid of states


@dataclass
class _Rows:
    """Computed measurements of one type on a time grid: row arrays (r,)."""

    type: str
    t_idx: np.ndarray
    sat: np.ndarray
    peer: np.ndarray
    value: np.ndarray
    visible: np.ndarray
    d: np.ndarray        # (r, 2, 6): partials wrt the satellite's and the emitter's (r, v)
    sat2: np.ndarray     # (r,) emitter index (ISR) or -1


def _flat(mtype, b, names, obs_value, d_r, d_v, visible):
    """Rows of an (N, S) observable of satellite b toward peers ``names``."""
    n, s = obs_value.shape
    d = np.zeros((n * s, 2, 6))
    d[:, 0, :3] = d_r.reshape(-1, 3)
    d[:, 0, 3:] = d_v.reshape(-1, 3)
    return _Rows(mtype, np.repeat(np.arange(n), s), np.full(n * s, b), np.tile(np.asarray(names, object), n),
                 obs_value.ravel(), visible.ravel(), d, np.full(n * s, -1))


def _evaluate(scen, tracking: Tracking, t, states, types, stations=None) -> list[_Rows]:
    """Every computable measurement of ``types`` at t (n,) [s] from states (n, n_sat, 6)
    [m, m/s]; stations: {kind: names} overriding the tracking plan's."""
    stations = stations or {}
    helio = _is_helio(scen)
    out = []
    n_sat = states.shape[1]
    r, v = states[..., :3], states[..., 3:]
    if "gnss_pseudorange" in types:
        for b in range(n_sat):
            for const, prefix in ((GPS, "G"), (BEIDOU_MEO, "C")):
                o = pseudorange(t, r[:, b], v[:, b], const, mode=tracking.gnss_mode)
                ids = [f"{prefix}{k + 1:02d}" for k in range(o.value.shape[1])]
                out.append(_flat("gnss_pseudorange", b, ids, o.value, o.d_r, o.d_v, o.visible))
    if "slr_range" in types:
        names = stations.get("slr", tracking.station_names("slr"))
        for b in range(n_sat):
            o = slr_range(scen.epoch, t, r[:, b], v[:, b], names)
            out.append(_flat("slr_range", b, o.extra["stations"], o.value, o.d_r, o.d_v, o.visible))
    if "dsn_range" in types or "dsn_range_rate" in types:
        names = stations.get("dsn", tracking.station_names("dsn"))
        eph = ephemeris_named(scen.forces.ephemeris)
        for b in range(n_sat):
            rng, rate = dsn_tracking(scen.epoch, t, r[:, b], v[:, b], names, heliocentric=helio, ephemeris=eph)
            for mtype, o in (("dsn_range", rng), ("dsn_range_rate", rate)):
                if mtype in types:
                    out.append(_flat(mtype, b, o.extra["stations"], o.value, o.d_r, o.d_v, o.visible))
    if "isr_range" in types:
        gm = planetary_gm()["sun"] if helio else float(scen.forces.gm_earth)
        o = isr_range(t, r, v, gm=gm)
        n, nl = o.value.shape
        d = np.concatenate([o.d_r, o.d_v], axis=-1).reshape(n * nl, 2, 6)
        rec, emi = np.asarray(LINK_RECEIVER), np.asarray(LINK_EMITTER)
        out.append(_Rows("isr_range", np.repeat(np.arange(n), nl), np.tile(rec, n),
                         np.tile(np.array([str(e) for e in emi], object), n), o.value.ravel(),
                         o.visible.ravel(), d, np.tile(emi, n)))
    return out


def _order(t, types, sat, peer) -> np.ndarray:
    """Row order: time, type (MEASUREMENT_TYPES order), satellite, peer."""
    code = np.array([MEASUREMENT_TYPES.index(x) for x in types], np.int64)
    return np.lexsort((np.asarray(peer, str), sat, code, t))


def _measurements(scen, tracking: Tracking, t, states) -> tuple[Measurements, np.ndarray]:
    """The visible measurements on the grid (values computed from ``states``) and their
    computed values."""
    rows = [x for x in _evaluate(scen, tracking, t, states, tracking.types) if x.visible.any()]
    for kind in tracking.kinds:
        if not any(x.type in KIND_TYPES[kind] for x in rows):
            _fail(f"tracking.kinds: {kind!r} gives no visible measurement on the arc of {tracking.arc_s} s "
                  f"of scenario {scen.name!r}")
    if tracking.stations is not None:
        seen = {p for x in rows if x.type in ("slr_range", "dsn_range") for p in x.peer[x.visible]}
        for kind in ("slr", "dsn"):
            if kind in tracking.kinds:
                for s in tracking.station_names(kind):
                    if s not in seen:
                        _fail(f"tracking.stations: {s!r} is below its elevation mask for the whole arc "
                              f"({tracking.arc_s} s) of every satellite; leave it out")
    cols = [np.concatenate(a) for a in zip(*[(t[x.t_idx][x.visible], np.full(x.visible.sum(), x.type, object),
                                               x.sat[x.visible], x.peer[x.visible], x.value[x.visible])
                                              for x in rows])]
    tt, ty, sat, peer, val = cols
    k = _order(tt, ty, sat, peer)
    sigma = np.array([tracking.sigma_of(x) for x in ty[k]])
    meas = Measurements(tt[k], ty[k].astype(str), sat[k].astype(np.int64), peer[k].astype(str),
                        np.full(k.size, np.nan), sigma)
    return meas, val[k]


def schedule(scenario, tracking: Tracking) -> Measurements:
    """The visible measurements of the tracking plan on its arc (nominal orbit), values NaN."""
    scen = _scenario(scenario, tracking)
    t, y = propagate_dd(scen, None, tracking.times())
    return _measurements(scen, tracking, t, y[..., 0] + y[..., 1])[0]


def simulate(scenario, tracking: Tracking, truth: OrbitParameters | None = None, seed: int = 0, *,
             noise: bool = True) -> Measurements:
    """Simulated measurements: the models on the dd propagation with the ``truth`` parameter
    values (None: the scenario's), visibility from that run, plus white noise of each row's
    sigma and, on GNSS pseudoranges, a receiver clock bias per satellite and epoch (normal,
    :data:`CLOCK_SIGMA_M`), both from ``numpy.random.default_rng(seed)`` (noise False: neither)."""
    scen = _scenario(scenario, tracking)
    t, y = propagate_dd(scen, truth, tracking.times())
    meas, value = _measurements(scen, tracking, t, y[..., 0] + y[..., 1])
    if noise:
        rng = np.random.default_rng(seed)
        value = value + meas.sigma * rng.standard_normal(len(meas))
        clock = CLOCK_SIGMA_M * rng.standard_normal((t.size, len(scen.satellites)))
        g = meas.type == "gnss_pseudorange"
        ti = np.rint(meas.t / tracking.interval_s).astype(np.int64)
        value[g] += clock[ti[g], meas.sat[g]]
    meas.value = value
    return meas


# ---------------------------------------------------------------------------------------------
# partials


def _match(scen, tracking, t_grid, states, meas: Measurements):
    """(rows index table): for each measurement, its computed value, partials and emitter."""
    types = tuple(sorted(set(meas.type), key=MEASUREMENT_TYPES.index))
    stations = {}
    for kind, mtypes in (("slr", ("slr_range",)), ("dsn", ("dsn_range", "dsn_range_rate"))):
        sel = np.isin(meas.type, mtypes)
        if sel.any():
            stations[kind] = list(dict.fromkeys(meas.peer[sel]))
    rows = _evaluate(scen, tracking, t_grid, states, types, stations)
    index = {}
    for i, x in enumerate(rows):
        for j, key in enumerate(zip(x.t_idx.tolist(), x.sat.tolist(), x.peer.tolist())):
            index[(x.type,) + key] = (i, j)
    ti = np.searchsorted(t_grid, meas.t - 1e-6)
    m = len(meas)
    value = np.empty(m)
    d = np.empty((m, 2, 6))
    sat2 = np.empty(m, np.int64)
    for k, key in enumerate(zip(meas.type.tolist(), ti.tolist(), meas.sat.tolist(), meas.peer.tolist())):
        try:
            i, j = index[key]
        except KeyError:
            _fail(f"measurements: row {k} ({key[0]}, t = {meas.t[k]} s, sat {key[2]}, peer {key[3]!r}) "
                  f"has no model; allowed: the rows of schedule()")
        value[k], d[k], sat2[k] = rows[i].value[j], rows[i].d[j], rows[i].sat2[j]
    return ti, value, d, sat2


def _jacobian(scen, p: Partials, ti, d, sat, sat2) -> np.ndarray:
    """H (m, 18 n_sat): rows d (m, 2, 6) chained with [Phi | Psi] of the full system."""
    F = np.concatenate([p.stm_full, p.sensitivities_full], axis=2)     # (n_t, 6n, 18n)
    H = np.zeros((ti.size, F.shape[2]))
    six = np.arange(6)
    for lo in range(0, ti.size, 4096):
        s = slice(lo, lo + 4096)
        H[s] = np.einsum("mk,mkp->mp", d[s, 0], F[ti[s, None], 6 * sat[s, None] + six])
        two = np.flatnonzero(sat2[s] >= 0) + lo
        if two.size:
            H[two] += np.einsum("mk,mkp->mp", d[two, 1], F[ti[two, None], 6 * sat2[two, None] + six])
    return H


def _compute(scen, tracking, parameters, meas):
    t_grid = np.unique(meas.t)
    p = propagate_with_partials(scen, parameters, t_grid, step=_partials_step(scen, t_grid))
    ti, h, d, sat2 = _match(scen, tracking, p.t, p.states, meas)
    H = _jacobian(scen, p, ti, d, meas.sat, sat2)
    return h, H, state_names(scen) + parameter_names(scen)


def compute(scenario, parameters: OrbitParameters | None, meas: Measurements, tracking: Tracking | None = None):
    """Computed measurements and their partials at the parameter values (None: the scenario's).

    Returns h (m,) [m or m/s] (GNSS: c tau without the receiver clock), H (m, 18 n_sat) and the
    column names: :func:`~tqdyn.od.parameters.state_names` then
    :func:`~tqdyn.od.parameters.parameter_names` of the scenario (every parameter; a problem
    selects its columns).  tracking: only its GNSS reception mode matters (default)."""
    scen = _scenario(scenario)
    tracking = tracking or Tracking(tuple(sorted({k for k in TRACKING_KINDS for x in set(meas.type)
                                                  if x in KIND_TYPES[k]})), max(float(meas.t.max()), 1.0),
                                    max(float(meas.t.max()), 1.0))
    return _compute(scen, tracking, parameters, meas)


# ---------------------------------------------------------------------------------------------
# the estimator's problem


def _clock_elimination(meas: Measurements):
    """Sparse transform T (m', m), sigmas (m',) and labels (m',) eliminating the GNSS receiver
    clock of each (epoch, satellite) (module docstring); other rows pass unchanged."""
    g = meas.type == "gnss_pseudorange"
    other = np.flatnonzero(~g)
    rows, cols, vals = [np.arange(other.size)], [other], [np.ones(other.size)]
    sig, lab = [meas.sigma[other]], [meas.type[other]]
    out = other.size
    gi = np.flatnonzero(g)
    if gi.size:
        key = np.stack([meas.t[gi], meas.sat[gi].astype(np.float64)], 1)
        _, inv, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
        order = np.argsort(inv.ravel(), kind="stable")
        for idx in np.split(gi[order], np.cumsum(counts)[:-1]):
            if idx.size < 2:
                continue
            w = 1.0 / meas.sigma[idx]
            s0 = float(meas.sigma[idx].min())
            M = s0 * linalg.null_space(w[None, :]).T * w[None, :]      # (n_k - 1, n_k)
            rows.append(out + np.repeat(np.arange(M.shape[0]), idx.size))
            cols.append(np.tile(idx, M.shape[0]))
            vals.append(M.ravel())
            sig.append(np.full(M.shape[0], s0))
            lab.append(np.full(M.shape[0], "gnss_pseudorange"))
            out += M.shape[0]
    T = sparse.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                          shape=(out, len(meas)))
    return T, np.concatenate(sig), tuple(str(x) for x in np.concatenate(lab))


def _parameter_sets(scen, tracking: Tracking, nominal: OrbitParameters, a_priori):
    """Estimated and considered :class:`~tqdyn.od.estimator.Parameters` and their column indices."""
    names = state_names(scen) + parameter_names(scen)
    base = _values(nominal)
    sats = [s.name for s in scen.satellites]
    sig = tracking.a_priori_sigma or {}
    out = []
    for groups in (tracking.estimate, tracking.consider):
        sel, sigma = [], []
        for g in groups:
            for s in sats:
                for j, pn in enumerate(GROUPS[g]):
                    sel.append(names.index(f"{s}/{pn}"))
                    a = np.atleast_1d(np.asarray(sig.get(g, np.inf), np.float64))
                    sigma.append(a[0] if (g != "state" or j < 3 or a.size == 1) else a[1])
        sel = np.array(sel, np.int64)
        values, sigma = base[sel].copy(), np.array(sigma)
        if a_priori is not None:
            for k, n in enumerate(a_priori.names):
                if n not in names:
                    _fail(f"a_priori: parameter {n!r} is not allowed; allowed: {names[0]!r} ... {names[-1]!r}")
                hit = np.flatnonzero(sel == names.index(n))
                if hit.size:
                    values[hit] = a_priori.values[k]
                    if a_priori.covariance is not None:
                        sigma[hit] = np.atleast_1d(a_priori.covariance)[k]
        cov = None if np.all(np.isinf(sigma)) else sigma
        out.append((estimator.Parameters(tuple(names[i] for i in sel), values, cov) if sel.size else None, sel))
    return out


def _problem(scen, meas: Measurements, tracking: Tracking, a_priori=None, partials: Partials | None = None):
    nominal = nominal_parameters(scen)
    (est, i_est), (con, i_con) = _parameter_sets(scen, tracking, nominal, a_priori)
    index = np.concatenate([i_est, i_con])
    T, sigma, labels = _clock_elimination(meas)
    cache = {}

    def evaluate(q):
        par = _with_values(nominal, index, q)
        if partials is not None and np.array_equal(q, _values(nominal)[index]):
            ti, h, d, sat2 = _match(scen, tracking, partials.t, partials.states, meas)
            H = _jacobian(scen, partials, ti, d, meas.sat, sat2)
        else:
            h, H, _ = _compute(scen, tracking, par, meas)
        return T @ h, np.asarray(T @ H[:, index])

    def model(q):
        q = np.asarray(q, np.float64)
        key = q.tobytes()
        if key not in cache:
            if len(cache) > 1:       # keep the first point (the shared nominal) and the last
                cache.pop(list(cache)[1])
            cache[key] = evaluate(q)
        return cache[key]

    y = None if np.all(np.isnan(meas.value)) else T @ meas.value
    return estimator.Problem(model, est, y=y, sigma=sigma, consider=con, groups=labels)


def build_problem(scenario, meas: Measurements, tracking: Tracking, a_priori=None) -> estimator.Problem:
    """The :class:`~tqdyn.od.estimator.Problem` of the measurements: parameters the tracking
    plan's groups (estimated, considered) at the scenario's values, a priori sigmas from
    ``tracking.a_priori_sigma`` and ``a_priori`` (an :class:`~tqdyn.od.estimator.Parameters` of
    some parameters: values and sigmas (n,) overriding them), GNSS clocks eliminated (module
    docstring), y None when every value is NaN (a schedule: covariance analysis), groups the
    measurement types."""
    scen = _scenario(scenario, tracking)
    return _problem(scen, meas, tracking, a_priori)


def covariance(scenario, tracking: Tracking, a_priori=None) -> estimator.Covariance:
    """Covariance analysis of the tracking plan (no data): one propagation with partials on
    the plan's grid gives both the schedule and the Jacobian."""
    scen = _scenario(scenario, tracking)
    t = tracking.times()
    p = propagate_with_partials(scen, None, t, step=_partials_step(scen, t))
    meas, _ = _measurements(scen, tracking, p.t, p.states)
    return estimator.covariance_analysis(_problem(scen, meas, tracking, a_priori, partials=p))


def fit(scenario, meas: Measurements, tracking: Tracking, a_priori=None, **estimate_options) -> estimator.Estimate:
    """Batch least-squares estimate of the plan's parameters from measurements
    (:func:`tqdyn.od.estimator.estimate` with ``estimate_options``)."""
    return estimator.estimate(build_problem(scenario, meas, tracking, a_priori), **estimate_options)
