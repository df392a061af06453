"""Tracking plans and measurement rows of orbit determination (:mod:`.problem` puts them
together): the tracking kinds and measurement types (those of :mod:`.registry`), the
:class:`Tracking` plan, the :class:`Measurements` table, and the registered measurement types
evaluated on a grid of states (every computable row with its partials with respect to the
satellites' position and velocity at the time tag, chained with the full-system state transition matrix and
sensitivities by :func:`jacobian`).  Time tags t [s since the epoch, the run's time scale: TT
geocentric, TDB heliocentric]; states [m, m/s] in the run's frame.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._choices import allowed, shown, unknown
from ..dynamics.empirical import PARAMETER_NAMES
from .measurement_type import Context, Rows, scenario_eop
from .parameters import STATE_NAMES
from .registry import BIAS_TYPES, KIND_TYPES, MEASUREMENT_TYPES, TRACKING_KINDS, TYPES, unit_text

__all__ = ["BIAS_TYPES", "COUPLED_GROUPS", "DEFAULT_ESTIMATE", "DEFAULT_ESTIMATE_COUPLED", "DEFAULT_SIGMA", "GROUPS",
           "KIND_TYPES", "MEASUREMENT_TYPES", "TRACKING_KINDS", "Measurements", "Tracking", "bias_design", "bias_keys",
           "bias_type", "evaluate", "jacobian", "match", "parameter_unit", "row_order"]

#: Default noise per measurement type [its unit] (the registry's, :mod:`.registry`).
DEFAULT_SIGMA = {n: x.sigma for n, x in TYPES.items()}
#: Parameter groups: name -> the per-satellite parameter names it holds ("self_gravity_common":
#: the rows of ``spacecraft.self_gravity_common`` of a coupled run, :mod:`.coupled`; "bias": the
#: measurement biases, per station or link rather than per satellite, :func:`bias_design`).
GROUPS = {"state": STATE_NAMES, "s_frame": PARAMETER_NAMES[0:3], "rtn": PARAMETER_NAMES[3:6],
          "rtn_cos": PARAMETER_NAMES[6:9], "rtn_sin": PARAMETER_NAMES[9:12],
          "self_gravity_common": ("sgc_x", "sgc_y", "sgc_z"), "bias": ()}
#: The groups of a coupled run (the others but "bias" are those of point-mass runs).
COUPLED_GROUPS = ("state", "self_gravity_common", "bias")
#: Where the stations are listed.
STATIONS_DOC = "docs/od-measurements.md#measurement-models"
#: Measurement types with a constant bias parameter (group "bias", :func:`bias_design`):
#: :data:`tqdyn.od.registry.BIAS_TYPES` (one per ground station and type, one per one-way link).
#: The groups estimated when a plan names none: point-mass runs, coupled runs.
DEFAULT_ESTIMATE = ("state", "s_frame")
DEFAULT_ESTIMATE_COUPLED = ("state", "self_gravity_common")
HELIOCENTRIC_KINDS = tuple(k for k in sorted(TRACKING_KINDS) if all(TYPES[n].heliocentric for n in KIND_TYPES[k]))
#: Tracking kinds with ground stations, and their station names.
STATION_KINDS = tuple(k for k in TRACKING_KINDS if TYPES[KIND_TYPES[k][0]].stations_label)


def fail(msg: str):
    raise ValueError(" ".join(msg.split()))


def check_consider(consider, a_priori, field: str = "tracking.consider",
                   how: str = "tracking.a_priori_sigma[{g!r}]") -> None:
    """Every considered group has an a priori sigma: ValueError (one line naming ``field``, and
    ``how`` to give it, ``{g}`` the group) otherwise."""
    for g in consider:
        if g not in a_priori:
            fail(f"{field}: {g!r} needs an a priori sigma; allowed: with {how.format(g=g)}")


@dataclass(frozen=True)
class Tracking:
    """A tracking plan (module docstring).

    kinds: subset of :data:`TRACKING_KINDS`; arc_s [s] from the epoch; interval_s [s] sampling
    interval, a multiple of ``integrator.step``; sigma: {measurement type: sigma [m or m/s]}
    overriding :data:`DEFAULT_SIGMA`; stations: station names of the station kinds
    (:data:`STATION_KINDS`: SLR :data:`~tqdyn.od.measurements_slr.ILRS_STATIONS`, deep-space
    :data:`~tqdyn.od.measurements_dsn.DEEP_SPACE_STATIONS`, TT&C the stations file of
    :mod:`~tqdyn.od.measurements_ttc`) (None:
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
                             f"({TYPES[typ].unit})")
                continue
            vals = np.atleast_1d(np.asarray(v, np.float64))
            if vals.shape != ((2,) if g == "state" else (1,)) or not np.all(vals > 0):
                fail(f"tracking.a_priori_sigma[{g!r}] = {v!r}; allowed: "
                     + ("(sigma_r m, sigma_v m/s) > 0" if g == "state" else
                        f"a number > 0 ({unit_text(BIAS_TYPES)}) or {{type: number}}" if g == "bias" else
                        "a number > 0 (m/s^2)"))
        check_consider(self.consider, self.a_priori_sigma or {})
        if self.stations is not None:
            st = (self.stations,) if isinstance(self.stations, str) else tuple(self.stations)
            every = [n for k in STATION_KINDS for n in station_catalogue(k)]
            for s in st:
                if s not in every:
                    fail(unknown("tracking.stations", s, every, STATIONS_DOC, noun="stations"))
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
        """Station names of a station kind (:data:`STATION_KINDS`; None: the model's defaults)."""
        if self.stations is None:
            return None
        cat = station_catalogue(kind)
        names = [s for s in self.stations if s in cat]
        if not names:
            fail(f"tracking.stations: {shown(list(self.stations))} has no {TYPES[KIND_TYPES[kind][0]].stations_label} "
                 f"station (tracking {kind!r}); allowed: {allowed(cat, STATIONS_DOC, noun='stations')}")
        return names


@dataclass
class Measurements:
    """Scalar measurements, one row each, ordered by time (module docstring).

    t (m,) [s since the epoch, the run's time scale]; type (m,) str of :data:`MEASUREMENT_TYPES`;
    sat (m,) int satellite index; peer (m,) str: station name, GNSS id ("G07", "C12") or the
    emitting satellite's index; value (m,) [m or m/s] (NaN before simulation); sigma (m,);
    tau_down (m,) [s] or None: the downlink light time of two-way rows (from the bounce at the
    satellite, the time tag, to the reception at the station; NaN on other rows), which the TDM
    writer needs to tag the rows at reception (CCSDS ``TIMETAG_REF = RECEIVE``)."""

    t: np.ndarray
    type: np.ndarray
    sat: np.ndarray
    peer: np.ndarray
    value: np.ndarray
    sigma: np.ndarray
    tau_down: np.ndarray | None = None

    def __len__(self) -> int:
        return int(self.t.size)

    def select(self, mask) -> "Measurements":
        """The rows where mask is true (or the given row indices)."""
        return Measurements(*(np.asarray(a)[mask] for a in (self.t, self.type, self.sat, self.peer, self.value,
                                                              self.sigma)),
                            tau_down=None if self.tau_down is None else np.asarray(self.tau_down)[mask])



def station_catalogue(kind: str) -> tuple:
    """The station names a plan may give for a station kind (:data:`STATION_KINDS`)."""
    return TYPES[KIND_TYPES[kind][0]].station_catalogue()


def parameter_unit(name: str) -> str:
    """The unit of an estimated parameter from its name ``"<sat>/<component>"``: the initial state's
    x, y, z [m] and vx, vy, vz [m/s], the acceleration parameters and a coupled run's common
    self-gravity [m/s^2] (:data:`GROUPS`), the measurement biases ``"bias/<type>/..."`` [the type's
    unit, :mod:`.registry`]; "" otherwise."""
    if name.startswith("bias/"):
        return TYPES[name.split("/")[1]].unit
    last = name.rsplit("/", 1)[-1]
    if last in STATE_NAMES:
        return "m" if last in STATE_NAMES[:3] else "m/s"
    return "m/s^2" if any(last in v for g, v in GROUPS.items() if g != "state") else ""


def is_heliocentric(scen) -> bool:
    return scen.reference.central_body == "sun"


def evaluate(scen, tracking: Tracking, t, states, types, stations=None) -> list[Rows]:
    """Every computable measurement of ``types`` at t (n,) [s] from states (n, n_sat, 6)
    [m, m/s] (each type's :meth:`~tqdyn.od.measurement_type.MeasurementType.evaluate`, with the
    scenario's Earth orientation); stations: {kind: names} overriding the tracking plan's."""
    ctx = Context(scen, tracking, dict(stations or {}), **scenario_eop(scen))
    out = []
    for name in MEASUREMENT_TYPES:
        if name in types:
            out += TYPES[name].evaluate(ctx, t, states)
    return out


def bias_keys(meas: "Measurements", satellite_names) -> list[str]:
    """The name of the bias parameter of each measurement row: ``"bias/<type>/<station>"`` (the
    station types), ``"bias/<type>/<emitter>-><receiver>"`` (the link types; satellite names); ""
    for a type without a bias (:data:`BIAS_TYPES`)."""
    out = []
    for mtype, sat, peer in zip(meas.type.tolist(), meas.sat.tolist(), meas.peer.tolist()):
        conv = TYPES[mtype].bias
        if not conv:
            out.append("")
        elif conv == "link":
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
    for kind in STATION_KINDS:
        sel = np.isin(meas.type, KIND_TYPES[kind])
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
