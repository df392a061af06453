"""Tracking plans and measurement rows of orbit determination (:mod:`.problem` puts them
together): the tracking kinds and measurement types, the :class:`Tracking` plan, the
:class:`Measurements` table, and the measurement models of :mod:`.measurements_gnss`,
:mod:`.measurements_slr`, :mod:`.measurements_isr`, :mod:`.measurements_dsn` evaluated on a grid
of states (every computable row with its partials with respect to the satellites' position and
velocity at the time tag, chained with the full-system state transition matrix and
sensitivities by :func:`jacobian`).  Time tags t [s since the epoch, the run's time scale: TT
geocentric, TDB heliocentric]; states [m, m/s] in the run's frame.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._choices import allowed, shown, unknown
from ..astro.ephemeris import ephemeris_named, planetary_gm
from ..constellation.indices import LINK_EMITTER, LINK_RECEIVER
from ..dynamics.empirical import PARAMETER_NAMES
from .measurements_dsn import DEEP_SPACE_STATIONS, DSN_DOPPLER_SIGMA_M_S, DSN_RANGE_SIGMA_M, dsn_tracking
from .measurements_gnss import BEIDOU_MEO, GNSS_SIGMA_M, GPS, pseudorange
from .measurements_isr import ISR_ABSOLUTE_SIGMA_M, isr_range
from .measurements_slr import ILRS_STATIONS, SLR_SIGMA_M, slr_range
from .parameters import STATE_NAMES

__all__ = ["BIAS_TYPES", "COUPLED_GROUPS", "DEFAULT_ESTIMATE", "DEFAULT_ESTIMATE_COUPLED", "DEFAULT_SIGMA", "GROUPS",
           "KIND_TYPES", "MEASUREMENT_TYPES", "TRACKING_KINDS", "Measurements", "Tracking", "bias_design", "bias_keys",
           "bias_type", "evaluate", "jacobian", "match", "row_order"]

TRACKING_KINDS = ("gnss", "slr", "isr", "dsn")
MEASUREMENT_TYPES = ("gnss_pseudorange", "slr_range", "isr_range", "dsn_range", "dsn_range_rate")
#: Measurement types of each tracking kind.
KIND_TYPES = {"gnss": ("gnss_pseudorange",), "slr": ("slr_range",), "isr": ("isr_range",),
              "dsn": ("dsn_range", "dsn_range_rate")}
#: Default noise per measurement type [m, m/s for dsn_range_rate] (the models' defaults).
DEFAULT_SIGMA = {"gnss_pseudorange": GNSS_SIGMA_M, "slr_range": SLR_SIGMA_M, "isr_range": ISR_ABSOLUTE_SIGMA_M,
                 "dsn_range": DSN_RANGE_SIGMA_M, "dsn_range_rate": DSN_DOPPLER_SIGMA_M_S}
#: Parameter groups: name -> the per-satellite parameter names it holds ("self_gravity_common":
#: the rows of ``spacecraft.self_gravity_common`` of a coupled run, :mod:`.coupled`; "bias": the
#: measurement biases, per station or link rather than per satellite, :func:`bias_design`).
GROUPS = {"state": STATE_NAMES, "s_frame": PARAMETER_NAMES[0:3], "rtn": PARAMETER_NAMES[3:6],
          "rtn_cos": PARAMETER_NAMES[6:9], "rtn_sin": PARAMETER_NAMES[9:12],
          "self_gravity_common": ("sgc_x", "sgc_y", "sgc_z"), "bias": ()}
#: The groups of a coupled run (the others but "bias" are those of point-mass runs).
COUPLED_GROUPS = ("state", "self_gravity_common", "bias")
#: Measurement types with a constant bias parameter (group "bias", :func:`bias_design`): one per
#: ground station and type (SLR and deep-space: the station's range calibration, its frequency
#: offset) and one per one-way inter-satellite link (the ranging offsets of its two ends).
#: GNSS pseudoranges have none: a bias common to a receiver's pseudoranges is its clock.
#: Where the SLR and deep-space stations are listed.
STATIONS_DOC = "docs/orbit-determination.md#measurement-models"
BIAS_TYPES = ("slr_range", "isr_range", "dsn_range", "dsn_range_rate")
#: The groups estimated when a plan names none: point-mass runs, coupled runs.
DEFAULT_ESTIMATE = ("state", "s_frame")
DEFAULT_ESTIMATE_COUPLED = ("state", "self_gravity_common")
HELIOCENTRIC_KINDS = ("dsn", "isr")


def fail(msg: str):
    raise ValueError(" ".join(msg.split()))


@dataclass(frozen=True)
class Tracking:
    """A tracking plan (module docstring).

    kinds: subset of :data:`TRACKING_KINDS`; arc_s [s] from the epoch; interval_s [s] sampling
    interval, a multiple of ``integrator.step``; sigma: {measurement type: sigma [m or m/s]}
    overriding :data:`DEFAULT_SIGMA`; stations: SLR (:data:`~tqdyn.od.measurements_slr.ILRS_STATIONS`)
    and deep-space (:data:`~tqdyn.od.measurements_dsn.DEEP_SPACE_STATIONS`) station names (None:
    all of them); estimate, consider: parameter groups (:data:`GROUPS`; estimate None: the
    run's defaults, :meth:`estimated`); a_priori_sigma: {group:
    sigma} a priori sigmas per group (``"state"``: (sigma_r [m], sigma_v [m/s]); the acceleration
    groups: [m/s^2]), needed for every considered group; gnss_mode: the GNSS reception mode of
    :func:`~tqdyn.od.measurements_gnss.gnss_visibility`; gnss_orbits: the GNSS transmitters, a tuple
    of constellations with ``states(t)`` and ``ids`` (:class:`~tqdyn.od.gnss_sp3.SP3Constellation`,
    whose ids name the peers; distinct ids), None: the nominal Walker constellations
    :data:`~tqdyn.od.measurements_gnss.GPS` (peers "G01"..) and
    :data:`~tqdyn.od.measurements_gnss.BEIDOU_MEO` ("C01"..)."""

    kinds: tuple
    arc_s: float
    interval_s: float = 600.0
    sigma: dict | None = None
    stations: tuple | None = None
    estimate: tuple | None = None
    consider: tuple = ()
    a_priori_sigma: dict | None = None
    gnss_mode: str = "sidelobes"
    gnss_orbits: tuple | None = None

    def __post_init__(self):
        kinds = (self.kinds,) if isinstance(self.kinds, str) else tuple(self.kinds)
        for k in kinds:
            if k not in TRACKING_KINDS:
                fail(unknown("tracking.kinds", k, TRACKING_KINDS))
        if not kinds or len(set(kinds)) != len(kinds):
            fail(f"tracking.kinds: {kinds!r}; allowed: distinct kinds of {', '.join(TRACKING_KINDS)}")
        object.__setattr__(self, "kinds", kinds)
        for name in ("arc_s", "interval_s"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                fail(f"tracking.{name}: {v!r} s; allowed: a finite number > 0")
        if self.interval_s > self.arc_s:
            fail(f"tracking.interval_s: {self.interval_s} s is longer than the arc ({self.arc_s} s)")
        for key, v in (self.sigma or {}).items():
            if key not in MEASUREMENT_TYPES:
                fail(unknown("tracking.sigma", key, MEASUREMENT_TYPES))
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                fail(f"tracking.sigma[{key!r}] = {v!r}; allowed: a finite number > 0 (m or m/s)")
        for name in ("estimate", "consider"):
            if getattr(self, name) is None and name == "estimate":
                continue
            groups = (getattr(self, name),) if isinstance(getattr(self, name), str) else tuple(getattr(self, name))
            for g in groups:
                if g not in GROUPS:
                    fail(unknown(f"tracking.{name}", g, GROUPS))
            object.__setattr__(self, name, groups)
        if self.estimate is not None and not self.estimate:
            fail(f"tracking.estimate: empty; allowed: groups of {', '.join(GROUPS)}")
        both = set(self.estimate or ()) & set(self.consider)
        if both:
            fail(f"tracking.consider: {sorted(both)[0]!r} is also estimated; a group is estimated or considered")
        for g, v in (self.a_priori_sigma or {}).items():
            if g not in GROUPS:
                fail(unknown("tracking.a_priori_sigma", g, GROUPS))
            if g == "bias" and isinstance(v, dict):
                for typ, x in v.items():
                    if typ not in BIAS_TYPES:
                        fail(unknown("tracking.a_priori_sigma['bias']", typ, BIAS_TYPES))
                    if not (isinstance(x, (int, float)) and math.isfinite(x) and x > 0):
                        fail(f"tracking.a_priori_sigma['bias'][{typ!r}] = {x!r}; allowed: a finite number > 0 "
                             f"(m, m/s for dsn_range_rate)")
                continue
            vals = np.atleast_1d(np.asarray(v, np.float64))
            if vals.shape != ((2,) if g == "state" else (1,)) or not np.all(vals > 0):
                fail(f"tracking.a_priori_sigma[{g!r}] = {v!r}; allowed: "
                     + ("(sigma_r m, sigma_v m/s) > 0" if g == "state" else
                        "a number > 0 (m, m/s for dsn_range_rate) or {type: number}" if g == "bias" else
                        "a number > 0 (m/s^2)"))
        for g in self.consider:
            if g not in (self.a_priori_sigma or {}):
                fail(f"tracking.consider: {g!r} has no a priori sigma; give tracking.a_priori_sigma[{g!r}]")
        if self.stations is not None:
            st = (self.stations,) if isinstance(self.stations, str) else tuple(self.stations)
            for s in st:
                if s not in ILRS_STATIONS and s not in DEEP_SPACE_STATIONS:
                    fail(unknown("tracking.stations", s, [*ILRS_STATIONS, *DEEP_SPACE_STATIONS], STATIONS_DOC,
                                 noun="stations"))
            object.__setattr__(self, "stations", st)
        if self.gnss_orbits is not None:
            orbits = tuple(self.gnss_orbits) if isinstance(self.gnss_orbits, (list, tuple)) else (self.gnss_orbits,)
            seen: set = set()
            for o in orbits:
                if not (callable(getattr(o, "states", None)) and getattr(o, "ids", None)):
                    fail(f"tracking.gnss_orbits: {o!r} is not allowed; allowed: constellations with states(t) and ids")
                dup = seen & set(o.ids)
                if dup:
                    fail(f"tracking.gnss_orbits: satellite {sorted(dup)[0]!r} is in two of them; allowed: "
                         "distinct satellites (tqdyn.od.gnss_sp3.sp3_constellations joins the files of the same "
                         "satellites)")
                seen |= set(o.ids)
            if not orbits:
                fail("tracking.gnss_orbits: empty; allowed: None (the nominal constellations) or constellations")
            object.__setattr__(self, "gnss_orbits", orbits)

    def estimated(self, coupled: bool) -> tuple:
        """The estimated groups: ``estimate``, or when None :data:`DEFAULT_ESTIMATE` (coupled runs:
        :data:`DEFAULT_ESTIMATE_COUPLED`) without the considered groups."""
        if self.estimate is not None:
            return self.estimate
        return tuple(g for g in (DEFAULT_ESTIMATE_COUPLED if coupled else DEFAULT_ESTIMATE) if g not in self.consider)

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
            fail(f"tracking.stations: {shown(list(self.stations))} has no {'SLR' if kind == 'slr' else 'deep-space'} "
                 f"station (tracking {kind!r}); allowed: {allowed(cat, STATIONS_DOC, noun='stations')}")
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



def is_heliocentric(scen) -> bool:
    return scen.reference.central_body == "sun"


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


def _gnss_sources(tracking: Tracking):
    """(constellation, id prefix or None: the constellation's own ids) of the plan's GNSS transmitters."""
    if tracking.gnss_orbits is None:
        return ((GPS, "G"), (BEIDOU_MEO, "C"))
    return tuple((o, None) for o in tracking.gnss_orbits)


def evaluate(scen, tracking: Tracking, t, states, types, stations=None) -> list[_Rows]:
    """Every computable measurement of ``types`` at t (n,) [s] from states (n, n_sat, 6)
    [m, m/s]; stations: {kind: names} overriding the tracking plan's."""
    stations = stations or {}
    helio = is_heliocentric(scen)
    out = []
    n_sat = states.shape[1]
    r, v = states[..., :3], states[..., 3:]
    if "gnss_pseudorange" in types:
        for b in range(n_sat):
            for const, prefix in _gnss_sources(tracking):
                o = pseudorange(t, r[:, b], v[:, b], const, mode=tracking.gnss_mode)
                ids = list(const.ids) if prefix is None else [f"{prefix}{k + 1:02d}" for k in range(o.value.shape[1])]
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


def bias_keys(meas: "Measurements", satellite_names) -> list[str]:
    """The name of the bias parameter of each measurement row: ``"bias/<type>/<station>"`` (SLR,
    deep-space), ``"bias/isr_range/<emitter>-><receiver>"`` (satellite names); "" for a type
    without a bias (:data:`BIAS_TYPES`)."""
    out = []
    for mtype, sat, peer in zip(meas.type.tolist(), meas.sat.tolist(), meas.peer.tolist()):
        if mtype not in BIAS_TYPES:
            out.append("")
        elif mtype == "isr_range":
            out.append(f"bias/{mtype}/{satellite_names[int(peer)]}->{satellite_names[int(sat)]}")
        else:
            out.append(f"bias/{mtype}/{peer}")
    return out


def bias_type(name: str) -> str:
    """The measurement type of a bias parameter's name (:func:`bias_keys`)."""
    return name.split("/")[1]


def bias_design(meas: "Measurements", satellite_names) -> tuple[list[str], np.ndarray]:
    """The bias parameters of the measurement rows and their partials: names (nb) in the order of
    first appearance (:func:`bias_keys`) and B (m, nb), 1 where a row carries the bias [unit of the
    row per unit of the bias]."""
    keys = bias_keys(meas, satellite_names)
    names = list(dict.fromkeys(k for k in keys if k))
    col = {n: j for j, n in enumerate(names)}
    B = np.zeros((len(keys), len(names)))
    for i, k in enumerate(keys):
        if k:
            B[i, col[k]] = 1.0
    return names, B


def row_order(t, types, sat, peer) -> np.ndarray:
    """Row order: time, type (MEASUREMENT_TYPES order), satellite, peer."""
    code = np.array([MEASUREMENT_TYPES.index(x) for x in types], np.int64)
    return np.lexsort((np.asarray(peer, str), sat, code, t))


def match(scen, tracking, t_grid, states, meas: Measurements):
    """(rows index table): for each measurement, its computed value, partials and emitter."""
    types = tuple(sorted(set(meas.type), key=MEASUREMENT_TYPES.index))
    stations = {}
    for kind, mtypes in (("slr", ("slr_range",)), ("dsn", ("dsn_range", "dsn_range_rate"))):
        sel = np.isin(meas.type, mtypes)
        if sel.any():
            stations[kind] = list(dict.fromkeys(meas.peer[sel]))
    rows = evaluate(scen, tracking, t_grid, states, types, stations)
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
            fail(f"measurements: row {k} ({key[0]}, t = {meas.t[k]} s, sat {key[2]}, peer {key[3]!r}) "
                 f"has no model; allowed: the rows of schedule()")
        value[k], d[k], sat2[k] = rows[i].value[j], rows[i].d[j], rows[i].sat2[j]
    return ti, value, d, sat2


def jacobian(scen, p, ti, d, sat, sat2) -> np.ndarray:
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
