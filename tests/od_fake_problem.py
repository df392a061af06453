"""A stand-in for ``tqdyn.od.problem`` with its interface (Tracking, Measurements, schedule, compute,
simulate, build_problem, covariance, fit, residual_rows) and a linear model, for the tests of the
orbit-determination files, command line and figure (tests/test_od_files.py, tests/test_od_cli.py,
tests/test_od_figure.py).

Model: per satellite k (scenario name S) two parameters, ``S/x`` [m] and ``S/s_x`` [m/s^2]; a range
of satellite k at time t is h = x + s_x t^2 / 2 [m], a range rate h = s_x t [m/s].  Truth: x = 1 m,
s_x = 1e-9 m/s^2 for every satellite; noise: the rows' sigmas times standard normals of ``seed``.
A station named ``Nowhere`` is refused as below the horizon for the whole arc.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass

import numpy as np
import pytest

from tqdyn.od.estimator import Parameters, Problem, covariance_analysis, estimate

TRACKING_KINDS = ("gnss", "slr", "isr", "dsn")
MEASUREMENT_TYPES = ("gnss_pseudorange", "slr_range", "isr_range", "dsn_range", "dsn_range_rate")
BIAS_TYPES = ("slr_range", "isr_range", "dsn_range", "dsn_range_rate")
GROUPS = {"state": ("x",), "s_frame": ("s_x",), "bias": ()}
HORIZON_MESSAGE = ("tracking.stations: 'Nowhere' is below the 20 deg elevation mask for the whole arc; "
                   "allowed: a station that sees a satellite")
_ROWS = {"gnss": [("gnss_pseudorange", "G07", 3.0)], "slr": [("slr_range", "Yarragadee", 0.01)],
         "isr": [("isr_range", None, 0.5)], "dsn": [("dsn_range", "DSS-14", 1.0), ("dsn_range_rate", "DSS-14", 1e-3)]}
TRUTH = (1.0, 1e-9)


@dataclass(frozen=True)
class Tracking:
    kinds: tuple
    arc_s: float
    interval_s: float = 600.0
    sigma: dict | None = None
    stations: tuple | None = None
    estimate: tuple = ("state", "s_frame")
    consider: tuple = ()
    a_priori_sigma: dict | None = None


@dataclass
class Measurements:
    t: np.ndarray
    type: np.ndarray
    sat: np.ndarray
    peer: np.ndarray
    value: np.ndarray
    sigma: np.ndarray
    tau_down: np.ndarray | None = None


def schedule(scenario, tracking) -> Measurements:
    if "Nowhere" in (tracking.stations or ()):
        raise ValueError(HORIZON_MESSAGE)
    n = len(scenario.satellites)
    rows = []
    for t in np.arange(0.0, tracking.arc_s + 1e-9, tracking.interval_s):
        for k in range(n):
            for kind in tracking.kinds:
                for typ, peer, sig in _ROWS[kind]:
                    rows.append((t, typ, k, str((k + 1) % n) if peer is None else peer, 0.0, sig))
    cols = list(zip(*rows))
    meas = Measurements(np.array(cols[0]), np.array(cols[1]), np.array(cols[2], dtype=np.int64), np.array(cols[3]),
                        np.array(cols[4]), np.array(cols[5]))
    _light_times(meas)
    return meas


def names(scenario) -> list:
    return [f"{s.name}/{p}" for s in scenario.satellites for p in ("x", "s_x")]


def design(scenario, meas) -> np.ndarray:
    """H (m, 2 n_sat) of the linear model."""
    m, n = len(meas.t), len(scenario.satellites)
    h = np.zeros((m, 2 * n))
    rate = np.asarray(meas.type) == "dsn_range_rate"
    idx = np.arange(m)
    sat = np.asarray(meas.sat)
    h[idx, 2 * sat] = np.where(rate, 0.0, 1.0)
    h[idx, 2 * sat + 1] = np.where(rate, meas.t, 0.5 * meas.t ** 2)
    return h


def compute(scenario, parameters, meas):
    jac = design(scenario, meas)
    return jac @ np.asarray(parameters, np.float64), jac, names(scenario)


def simulate(scenario, tracking, truth=None, seed=0, *, bias=None) -> Measurements:
    """Simulated values; bias {measurement type: value} added to the rows of that type."""
    meas = schedule(scenario, tracking)
    q = np.tile(TRUTH, len(scenario.satellites))
    meas.value = design(scenario, meas) @ q + meas.sigma * np.random.default_rng(seed).standard_normal(len(meas.t))
    for typ, v in (bias or {}).items():
        meas.value[meas.type == typ] += v
    _light_times(meas)
    return meas


def _light_times(meas) -> None:
    """The two-way rows' downlink light times, consistent with their ranges (half the round trip,
    value / c; a range rate: its range row's), as a reader of the TDM takes them."""
    tau = np.full(len(meas.t), np.nan)
    rng = np.isin(meas.type, ["slr_range", "dsn_range"])
    tau[rng] = meas.value[rng] / 299792458.0
    key = {(t, k): x for t, k, x in zip(meas.t[meas.type == "dsn_range"], meas.sat[meas.type == "dsn_range"],
                                        tau[meas.type == "dsn_range"])}
    rate = np.flatnonzero(meas.type == "dsn_range_rate")
    tau[rate] = [key.get((meas.t[i], meas.sat[i]), 0.0) for i in rate]
    meas.tau_down = tau


def _select(scenario, groups, what):
    allowed = {"state": "x", "s_frame": "s_x"}
    bad = [g for g in groups if g not in allowed]
    if bad:
        raise ValueError(f"tracking.{what}: {bad[0]!r} is not a parameter group; allowed: state, s_frame")
    comp = {allowed[g] for g in groups}
    return [i for i, nm in enumerate(names(scenario)) if nm.rsplit("/", 1)[1] in comp]


def estimated_groups(scenario, tracking) -> tuple:
    return tracking.estimate


def build_problem(scenario, meas, tracking, a_priori=None) -> Problem:
    jac = design(scenario, meas)
    est = _select(scenario, tracking.estimate, "estimate")
    con = _select(scenario, tracking.consider, "consider")
    nm = names(scenario)
    cols = est + con
    consider = (Parameters(tuple(nm[i] for i in con), np.tile(TRUTH, len(scenario.satellites))[con] * 0,
                           np.full(len(con), 1e-10)) if con else None)
    y = None if np.all(meas.value == 0) else meas.value
    return Problem(lambda q: (jac[:, cols] @ q, jac[:, cols]), Parameters(tuple(nm[i] for i in est), np.zeros(len(est))),
                   y=y, sigma=meas.sigma, consider=consider, groups=tuple(meas.type))


def covariance(scenario, tracking):
    return covariance_analysis(build_problem(scenario, schedule(scenario, tracking), tracking))


def residual_rows(meas) -> np.ndarray:
    """The fit's rows are the measurement rows (no clock elimination)."""
    return np.arange(len(meas.t), dtype=np.int64)


def fit(scenario, meas, tracking, **estimate_options):
    return estimate(build_problem(scenario, meas, tracking), **estimate_options)


@pytest.fixture(autouse=True)
def fake_problem(monkeypatch):
    """Put this stand-in in place of ``tqdyn.od.problem`` for every test of a module that imports
    this fixture."""
    import tqdyn.od

    stand_in = sys.modules[__name__]
    monkeypatch.setitem(sys.modules, "tqdyn.od.problem", stand_in)
    monkeypatch.setattr(tqdyn.od, "problem", stand_in, raising=False)
    return stand_in
