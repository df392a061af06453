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

Coupled runs (``constellation.pointing`` set: attitude, test masses, drag-free and suspension
control): the parameters are the initial states and the common self-gravity of each satellite's
test masses (group ``"self_gravity_common"``, ``spacecraft.self_gravity_common`` [m/s^2 in S]),
with partials by the variational equations of the full coupled dynamics (:mod:`.coupled`,
:mod:`.coupled_variational`; central differences of dd runs inside ``with coupled.method("differences")``);
the point-mass acceleration groups are refused there, and ``"self_gravity_common"`` on
point-mass runs.

Refused in one line: coupled runs with free test masses or not three satellites, GNSS and SLR on
heliocentric runs, an interval off the run's step grid, an arc beyond the ephemeris' span, a named
station that never sees a satellite over the arc, a tracking kind without any visible measurement.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from scipy import linalg, sparse

from .._choices import did_you_mean
from ..astro.ephemeris import ephemeris_named
from ..scenario import load_scenario
from . import coupled, estimator
from .parameters import OrbitParameters, parameter_names, state_names
from .registry import TYPES, unit_text
from .tracking import (BIAS_TYPES, COUPLED_GROUPS, DEFAULT_SIGMA, GROUPS, HELIOCENTRIC_KINDS, KIND_TYPES,
                       MEASUREMENT_TYPES, STATION_KINDS, TRACKING_KINDS, Measurements, Tracking, bias_design, bias_keys,
                       bias_type, evaluate, fail, is_heliocentric, jacobian, match, row_order)
from .variational import Partials, propagate_dd, propagate_with_partials

__all__ = ["DEFAULT_SIGMA", "GROUPS", "MEASUREMENT_TYPES", "TRACKING_KINDS", "Measurements", "Tracking",
           "build_problem", "compute", "covariance", "estimated_groups", "fit", "measurement_biases",
           "nominal_parameters", "residual_rows", "schedule", "simulate", "with_measurements"]

#: Largest step [s] of the float64 variational equations on geocentric runs (DP87 on TianQin's
#: 3.6-day orbit: the partials agree with dd differences to ~1e-10 at 600 s).
_PARTIALS_STEP_GEOCENTRIC = 600.0
#: Standard deviation [m] of the simulated receiver clock bias per epoch (eliminated by the fit).
CLOCK_SIGMA_M = 1000.0
#: The measurement types whose rows carry a receiver clock bias per epoch and satellite.
CLOCK_TYPES = tuple(n for n, x in TYPES.items() if x.receiver_clock)


def _scenario(scenario, tracking: Tracking | None = None):
    """The loaded scenario, checked for orbit determination with the tracking plan."""
    scen = load_scenario(scenario) if isinstance(scenario, str) else scenario
    if _coupled(scen):
        coupled.check_scenario(scen)
    if scen.integrator.mode != "fixed":
        fail(f'scenario {scen.name!r}: integrator.mode = {scen.integrator.mode!r}; allowed: "fixed"')
    if tracking is None:
        return scen
    for g in tracking.estimated(_coupled(scen)) + tracking.consider:
        if _coupled(scen) and g not in COUPLED_GROUPS:
            fail(f"tracking: group {g!r} is not allowed for the coupled scenario {scen.name!r}; allowed: "
                 f"{', '.join(COUPLED_GROUPS)}")
        if not _coupled(scen) and g == "self_gravity_common":
            fail(f"tracking: group {g!r} needs a coupled scenario (constellation.pointing set); "
                 f"{scen.name!r} is point-mass; allowed: {', '.join(x for x in GROUPS if x != g)}")
    _check_kinds(scen, tracking.kinds)
    if "isr" in tracking.kinds and len(scen.satellites) != 3:
        fail(f"tracking.kinds: 'isr' needs three satellites; scenario {scen.name!r} has {len(scen.satellites)}")
    step = float(scen.integrator.step_s)
    if abs(tracking.interval_s / step - round(tracking.interval_s / step)) > 1e-9:
        fail(f"tracking.interval_s: {tracking.interval_s} s is not a multiple of integrator.step = {step} s")
    eph = ephemeris_named(scen.forces.ephemeris)
    jd_end = scen.epoch.tdb[0] + scen.epoch.tdb[1] + (tracking.arc_s + 86400.0) / 86400.0
    if jd_end > eph.span_jd[1]:
        fail(f"tracking.arc_s: {tracking.arc_s} s from the epoch ends beyond the span of the ephemeris "
             f"{eph.name} (JD {eph.span_jd[1]}, less one day for light times); allowed: at most "
              f"{(eph.span_jd[1] - 1.0 - scen.epoch.tdb[0] - scen.epoch.tdb[1]) * 86400.0:.0f} s")
    return scen


def _coupled(scen) -> bool:
    return scen.constellation.pointing != "none"


def estimated_groups(scenario, tracking: Tracking) -> tuple:
    """The parameter groups the plan estimates on the scenario: its ``estimate``, or by default
    state and ``s_frame`` (point-mass runs) or state and ``self_gravity_common`` (coupled runs)."""
    return tracking.estimated(_coupled(_scenario(scenario)))


def _parameter_names(scen) -> list[str]:
    """Names of the columns of :func:`compute` after the states."""
    return coupled.parameter_names(scen) if _coupled(scen) else parameter_names(scen)


def _check_kinds(scen, kinds) -> None:
    if is_heliocentric(scen):
        for k in kinds:
            if k not in HELIOCENTRIC_KINDS:
                fail(f"tracking.kinds: {k!r} is not allowed for the heliocentric scenario {scen.name!r}; "
                     f"allowed: {', '.join(HELIOCENTRIC_KINDS)}")


def nominal_parameters(scenario) -> OrbitParameters:
    """The scenario's own parameter values: initial states (n_sat, 6, 2) dd [m, m/s] and
    ``[accelerations]`` (n_sat, 12) [m/s^2]; coupled runs also ``self_gravity_common``
    (n_sat, 3) [m/s^2 in S]."""
    scen = _scenario(scenario)
    _, y = propagate_dd(scen, None, [0.0])
    return OrbitParameters(accelerations=scen.accelerations.values(len(scen.satellites)), y0=y[0],
                           self_gravity_common=coupled.nominal_common(scen) if _coupled(scen) else None)


def _values(par: OrbitParameters) -> np.ndarray:
    """All parameter values in the column order of :func:`compute`: states then accelerations
    (coupled runs: then the common self-gravity)."""
    y0 = par.y0_dd()
    p = par.accelerations if par.self_gravity_common is None else par.self_gravity_common
    return np.concatenate([(y0[..., 0] + y0[..., 1]).ravel(), np.asarray(p, np.float64).ravel()])


def _with_values(nominal: OrbitParameters, index: np.ndarray, q: np.ndarray) -> OrbitParameters:
    """nominal with the parameters at column indices ``index`` (of :func:`compute`) set to q
    (state components: the dd nominal plus the float64 difference, so q = nominal is exact)."""
    y0 = nominal.y0_dd().copy()
    acc = np.array(nominal.accelerations, np.float64)
    sg = None if nominal.self_gravity_common is None else np.array(nominal.self_gravity_common, np.float64)
    n_state = y0.shape[0] * 6
    base = _values(nominal)
    for j, v in zip(index, q):
        if j < n_state:
            y0[j // 6, j % 6, 0] += v - base[j]
        elif sg is not None:
            sg.flat[j - n_state] = v
        else:
            acc.flat[j - n_state] = v
    return OrbitParameters(accelerations=acc, y0=y0, self_gravity_common=sg)


def _partials_step(scen, t) -> float:
    """The largest multiple of integrator.step dividing every t [s], at most 600 s geocentric
    (the run's step heliocentric)."""
    run = float(scen.integrator.step_s)
    k = np.rint(np.asarray(t) / run).astype(np.int64)
    g = int(np.gcd.reduce(k[k > 0])) if np.any(k > 0) else 1
    cap = run if is_heliocentric(scen) else max(run, _PARTIALS_STEP_GEOCENTRIC)
    return run * max(d for d in range(1, g + 1) if g % d == 0 and d * run <= cap)


def _measurements(scen, tracking: Tracking, t, states) -> tuple[Measurements, np.ndarray]:
    """The visible measurements on the grid (values computed from ``states``) and their
    computed values."""
    rows = [x for x in evaluate(scen, tracking, t, states, tracking.types) if x.visible.any()]
    for kind in tracking.kinds:
        if not any(x.type in KIND_TYPES[kind] for x in rows):
            fail(f"tracking.kinds: {kind!r} gives no visible measurement on the arc of {tracking.arc_s} s "
                 f"of scenario {scen.name!r}")
    if tracking.stations is not None:
        seen = {p for x in rows if TYPES[x.type].stations_label for p in x.peer[x.visible]}
        for kind in STATION_KINDS:
            if kind in tracking.kinds:
                for s in tracking.station_names(kind):
                    if s not in seen:
                        fail(f"tracking.stations: {s!r} is below its elevation mask for the whole arc "
                             f"({tracking.arc_s} s) of every satellite; leave it out")
    cols = [np.concatenate(a) for a in zip(*[(t[x.t_idx][x.visible], np.full(x.visible.sum(), x.type, object),
                                               x.sat[x.visible], x.peer[x.visible], x.value[x.visible],
                                               np.full(x.visible.sum(), np.nan) if x.tau_down is None
                                               else x.tau_down[x.visible])
                                              for x in rows])]
    tt, ty, sat, peer, val, tau = cols
    k = row_order(tt, ty, sat, peer)
    sigma = np.array([tracking.sigma_of(x) for x in ty[k]])
    meas = Measurements(tt[k], ty[k].astype(str), sat[k].astype(np.int64), peer[k].astype(str),
                        np.full(k.size, np.nan), sigma, tau[k].astype(np.float64))
    return meas, val[k]


def schedule(scenario, tracking: Tracking) -> Measurements:
    """The visible measurements of the tracking plan on its arc (nominal orbit), values NaN."""
    scen = _scenario(scenario, tracking)
    t, y = propagate_dd(scen, None, tracking.times())
    return _measurements(scen, tracking, t, y[..., 0] + y[..., 1])[0]


def measurement_biases(scen, meas: Measurements, bias: dict) -> np.ndarray:
    """The bias (m,) [m or m/s] of each measurement row from ``bias`` {key: value}: a key is a
    measurement type of :data:`BIAS_TYPES` (every station or link of it), or a bias parameter's
    name with or without its ``"bias/"`` prefix (``"slr_range/Yarragadee"``,
    ``"isr_range/Sat2->Sat1"``: one of them; it overrides its type's value)."""
    keys = np.array(bias_keys(meas, [s.name for s in scen.satellites]), dtype=object)
    out = np.zeros(len(meas))
    known = sorted(set(keys.tolist()) - {""})
    for key in sorted(bias, key=lambda k: "/" in k):        # types first, single biases override them
        v = bias[key]
        if not (isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)):
            fail(f"bias[{key!r}] = {v!r}; allowed: a finite number ({unit_text(BIAS_TYPES)})")
        if key in BIAS_TYPES:
            out[meas.type == key] = v
            continue
        name = key if key.startswith("bias/") else f"bias/{key}"
        if name not in known:
            names = [n[5:] for n in known]  # "TYPE/PEER": a typo of one is suggested, not any of the same type
            example = f" as {names[0]!r}" if names else ""
            fail(f"bias: {key!r} is not a bias of these measurements{did_you_mean(key, names, cutoff=0.85)}; "
                 f"allowed: a type of {', '.join(BIAS_TYPES)}, or TYPE/PEER{example}")
        out[keys == name] = v
    return out


def simulate(scenario, tracking: Tracking, truth: OrbitParameters | None = None, seed: int = 0, *,
             noise: bool = True, bias: dict | None = None) -> Measurements:
    """Simulated measurements: the models on the dd propagation with the ``truth`` parameter
    values (None: the scenario's), visibility from that run, plus white noise of each row's
    sigma and, on GNSS pseudoranges, a receiver clock bias per satellite and epoch (normal,
    :data:`CLOCK_SIGMA_M`), both from ``numpy.random.default_rng(seed)`` (noise False: neither),
    plus the constant measurement biases ``bias`` (:func:`measurement_biases`; None: none)."""
    scen = _scenario(scenario, tracking)
    t, y = propagate_dd(scen, truth, tracking.times())
    meas, value = _measurements(scen, tracking, t, y[..., 0] + y[..., 1])
    if bias:
        value = value + measurement_biases(scen, meas, bias)
    if noise:
        rng = np.random.default_rng(seed)
        value = value + meas.sigma * rng.standard_normal(len(meas))
        clock = CLOCK_SIGMA_M * rng.standard_normal((t.size, len(scen.satellites)))
        g = np.isin(meas.type, CLOCK_TYPES)
        ti = np.rint(meas.t / tracking.interval_s).astype(np.int64)
        value[g] += clock[ti[g], meas.sat[g]]
    meas.value = value
    return meas


def _compute(scen, tracking, parameters, meas):
    t_grid = np.unique(meas.t)
    p = _partials(scen, parameters, t_grid)
    ti, h, d, sat2 = match(scen, tracking, p.t, p.states, meas)
    H = jacobian(scen, p, ti, d, meas.sat, sat2)
    return h, H, state_names(scen) + _parameter_names(scen)


def _partials(scen, parameters, t) -> Partials:
    """States and partials at t [s]: the variational equations of point-mass runs or of coupled
    runs (:mod:`.coupled`: or central differences of dd runs, :func:`.coupled.method`)."""
    prop = coupled.propagate_with_partials if _coupled(scen) else propagate_with_partials
    return prop(scen, parameters, t, step=_partials_step(scen, t))


def compute(scenario, parameters: OrbitParameters | None, meas: Measurements, tracking: Tracking | None = None):
    """Computed measurements and their partials at the parameter values (None: the scenario's).

    Returns h (m,) [m or m/s] (GNSS: c tau without the receiver clock), H (m, 18 n_sat; coupled
    runs (m, 9 n_sat)) and the column names: :func:`~tqdyn.od.parameters.state_names` then
    :func:`~tqdyn.od.parameters.parameter_names` of the scenario (coupled runs:
    :func:`~tqdyn.od.coupled.parameter_names`; every parameter; a problem selects its columns).
    tracking: only its GNSS reception mode matters (default)."""
    scen = _scenario(scenario)
    if tracking is None:
        kinds = tuple(k for k in TRACKING_KINDS if any(x in KIND_TYPES[k] for x in set(meas.type.tolist())))
        tracking = Tracking(kinds or ("isr",), 1.0, 1.0)
    _check_kinds(scen, tracking.kinds)
    return _compute(scen, tracking, parameters, meas)


# ---------------------------------------------------------------------------------------------
# the estimator's problem


def _clock_elimination(meas: Measurements):
    """Sparse transform T (m', m), sigmas (m',) and labels (m',) eliminating the GNSS receiver
    clock of each (epoch, satellite) (module docstring); other rows pass unchanged."""
    g = np.isin(meas.type, CLOCK_TYPES)
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
            lab.append(np.full(M.shape[0], meas.type[idx[0]]))
            out += M.shape[0]
    T = sparse.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                          shape=(out, len(meas)))
    return T, np.concatenate(sig), tuple(str(x) for x in np.concatenate(lab))


def residual_rows(meas: Measurements) -> np.ndarray:
    """For each row of the fit (of :func:`fit`'s residuals, (m',)), the index of the first
    measurement row it is formed from, (m',) int: the row itself for every type but GNSS, the
    first pseudorange of its (epoch, satellite) for the clock-free combinations (module
    docstring; an epoch with one pseudorange forms no row).  Every row formed from a measurement
    has its time tag, type and satellite."""
    T = _clock_elimination(meas)[0].tocsr()
    if T.shape[0] == 0:
        return np.zeros(0, dtype=np.int64)
    return np.minimum.reduceat(T.indices, T.indptr[:-1]).astype(np.int64)


def _bias_sigma(value, name: str) -> float:
    """The a priori sigma of the bias ``name`` from ``tracking.a_priori_sigma["bias"]`` (a number,
    or {type: number}; absent: none, inf)."""
    if isinstance(value, dict):
        return float(value.get(bias_type(name), np.inf))
    return float(value)


def _parameter_sets(scen, tracking: Tracking, nominal: OrbitParameters, a_priori, bias_names=()):
    """Estimated and considered :class:`~tqdyn.od.estimator.Parameters` and their column indices
    (columns: the states, the scenario's parameters, then the biases ``bias_names``, nominal 0)."""
    names = state_names(scen) + _parameter_names(scen) + list(bias_names)
    base = np.concatenate([_values(nominal), np.zeros(len(bias_names))])
    sats = [s.name for s in scen.satellites]
    sig = tracking.a_priori_sigma or {}
    out = []
    for considered, groups in ((False, tracking.estimated(_coupled(scen))), (True, tracking.consider)):
        sel, sigma = [], []
        for g in groups:
            if g == "bias":
                sel += [names.index(n) for n in bias_names]
                sigma += [_bias_sigma(sig.get(g, np.inf), n) for n in bias_names]
                if considered and not np.all(np.isfinite(sigma[-len(bias_names):])):
                    typ = next(bias_type(n) for n in bias_names if not np.isfinite(_bias_sigma(sig[g], n)))
                    fail(f"tracking.a_priori_sigma['bias']: no sigma for {typ!r}, whose biases are considered; "
                         f"give one per type of {', '.join(sorted({bias_type(n) for n in bias_names}))}")
                continue
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
                    fail(f"a_priori: parameter {n!r} is not allowed; allowed: {names[0]!r} ... {names[-1]!r}")
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
    groups = tracking.estimated(_coupled(scen)) + tracking.consider
    bias_names, B = bias_design(meas, [s.name for s in scen.satellites]) if "bias" in groups else ([], None)
    if "bias" in groups and not bias_names:
        fail(f"tracking: group 'bias' but no measurement of {', '.join(BIAS_TYPES)}; leave it out")
    (est, i_est), (con, i_con) = _parameter_sets(scen, tracking, nominal, a_priori, bias_names)
    index = np.concatenate([i_est, i_con])
    values = _values(nominal)
    n_base = values.size
    base = np.concatenate([values, np.zeros(len(bias_names))])
    orbit = index < n_base
    T, sigma, labels = _clock_elimination(meas)
    cache = {}

    def evaluate(q):
        par = _with_values(nominal, index[orbit], q[orbit])
        if partials is not None and np.array_equal(q[orbit], base[index[orbit]]):
            ti, h, d, sat2 = match(scen, tracking, partials.t, partials.states, meas)
            H = jacobian(scen, partials, ti, d, meas.sat, sat2)
        else:
            h, H, _ = _compute(scen, tracking, par, meas)
        if B is not None:
            b = base[n_base:].copy()
            b[index[~orbit] - n_base] = q[~orbit]
            h, H = h + B @ b, np.hstack([H, B])
        return T @ h, np.asarray(T @ H[:, index])

    def model(q):
        q = np.asarray(q, np.float64)
        key = q.tobytes()
        if key not in cache:
            if len(cache) > 1:       # keep the first point (the shared nominal) and the last
                cache.pop(list(cache)[1])
            cache[key] = evaluate(q)
        return cache[key]

    model.transform = T
    y = None if np.all(np.isnan(meas.value)) else T @ meas.value
    return estimator.Problem(model, est, y=y, sigma=sigma, consider=con, groups=labels)


def build_problem(scenario, meas: Measurements, tracking: Tracking, a_priori=None) -> estimator.Problem:
    """The :class:`~tqdyn.od.estimator.Problem` of the measurements: parameters the tracking
    plan's groups (estimated, considered) at the scenario's values, a priori sigmas from
    ``tracking.a_priori_sigma`` and ``a_priori`` (an :class:`~tqdyn.od.estimator.Parameters` of
    some parameters: values and sigmas (n,) overriding them), GNSS clocks eliminated (module
    docstring), y None when every value is NaN (a schedule: covariance analysis), groups the
    measurement types.  ``problem.model.transform`` is the sparse (m', m) map of the measurement
    rows onto the problem's rows; the model keeps its value at the a priori point, so that
    :func:`with_measurements` problems share it."""
    scen = _scenario(scenario, tracking)
    return _problem(scen, meas, tracking, a_priori)


def with_measurements(problem: estimator.Problem, values) -> estimator.Problem:
    """The problem of :func:`build_problem` with other measurement values (m,) [m or m/s] of the
    same rows (e.g. another noise draw); the model, and its evaluation at the a priori point,
    are shared."""
    return dataclasses.replace(problem, y=problem.model.transform @ np.asarray(values, np.float64))


def covariance(scenario, tracking: Tracking, a_priori=None, partials: Partials | None = None,
               **options) -> estimator.Covariance:
    """Covariance analysis of the tracking plan (no data; options of
    :func:`tqdyn.od.estimator.covariance_analysis`): one propagation with partials on the plan's
    grid gives both the schedule and the Jacobian.  partials: a
    :func:`~tqdyn.od.variational.propagate_with_partials` of the scenario (its own parameter
    values) on a grid holding the plan's times, to share one propagation between plans."""
    scen = _scenario(scenario, tracking)
    t = tracking.times()
    if partials is None:
        p = _partials(scen, None, t)
    else:
        k = np.searchsorted(partials.t, t - 1e-6)
        if np.any(k >= partials.t.size) or np.any(np.abs(partials.t[np.minimum(k, partials.t.size - 1)] - t) > 1e-6):
            fail(f"partials: the grid ({partials.t.size} times to {partials.t[-1]} s) does not hold the plan's "
                 f"times (every {tracking.interval_s} s to {tracking.arc_s} s)")
        p = dataclasses.replace(partials, t=partials.t[k], states=partials.states[k],
                                states_dd=partials.states_dd[k], stm=partials.stm[k],
                                sensitivities=partials.sensitivities[k], stm_full=partials.stm_full[k],
                                sensitivities_full=partials.sensitivities_full[k])
    meas, _ = _measurements(scen, tracking, p.t, p.states)
    return estimator.covariance_analysis(_problem(scen, meas, tracking, a_priori, partials=p), **options)


def fit(scenario, meas: Measurements, tracking: Tracking, a_priori=None, **estimate_options) -> estimator.Estimate:
    """Batch least-squares estimate of the plan's parameters from measurements
    (:func:`tqdyn.od.estimator.estimate` with ``estimate_options``)."""
    if len(meas) and np.all(np.isnan(meas.value)):
        fail("measurements: every value is NaN (a schedule); simulate or read measurements, "
             "or use covariance() for a prediction without data")
    return estimator.estimate(build_problem(scenario, meas, tracking, a_priori), **estimate_options)
