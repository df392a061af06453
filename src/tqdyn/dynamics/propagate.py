"""Propagation driver: initial states, chunked compiled DP87 loop, outputs.

The fixed-step loop runs entirely in compiled code, one chunk of steps at a
time.  Before each chunk the time-only inputs of the force model are
computed for every stage time of the chunk (t_n + c_i h, known in advance)
and handed to the loop as one array, so no Python runs per step.  The
adaptive mode drives the same compiled step from Python (step-size control
needs the stage times of the step being tried) and samples the solution on
the output grid with the Hermite dense output of
:mod:`tqdyn.integrators.hermite`.

Time is kept as an integer step count times the exact step (a dd pair) --
never as a large bare float64.  All states are GCRS, geocentric, SI.

This module computes; it writes nothing.  Outputs go to a ``sink`` callable
(the CLI connects it to the HDF5 writer), progress to a ``progress``
callable.
"""

from __future__ import annotations

import time as _time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Callable, Mapping

import mpmath
import numpy as np
from numba import njit

from ..astro import elements as _el
from . import rhs as _dyn
from ..astro.constants import C_LIGHT, R_EARTH_EGM2008
from .rhs import point_masses, system_rhs
from ..forces.model import ForceModel, build_force_model
from ..numerics import dp87
from ..numerics import hermite
from ..numerics.dd import add, ld, mul, mp_from_dd, st
from ..astro.timescales import Epoch

__all__ = ["initial_state", "propagate", "RunResult", "PRECISIONS", "evaluate_rhs", "warm_up",
           "two_body_energy", "check_inputs", "Checkpoint", "System", "build_system", "self_gravity_oa"]

PRECISIONS = ("dd", "float64")
_DEFAULT_CHUNK = 4096  # steps per compiled call: ~1 s of work, bounds memory of time-only inputs


@dataclass(frozen=True)
class System:
    """What is propagated: the mode of :mod:`tqdyn.dynamics` and its parameters.

    cpar : (dynamics.CP_LEN,) float64 constellation parameters (mode, pointing
    law, control switch, spacecraft geometry, self-gravity);
    coupled : attitude/control diagnostics are produced (pointing != "none");
    free_tms : the six TMs are propagated as bodies 3..8.
    """

    cpar: np.ndarray
    coupled: bool
    free_tms: bool
    ephemeris: object = None

    def with_inputs(self, model: ForceModel):
        """The force model, extended by the system's own time-only inputs
        (the Moon's and Sun's states for the jerk of the local pointing
        laws) when it needs any; see :class:`_SystemInputs`."""
        if self.ephemeris is None or isinstance(model, _SystemInputs):
            return model
        return _SystemInputs(model, self)


class _SystemInputs:
    """A force model whose time-only inputs are followed by the coupled
    system's: geocentric GCRS position [m] and velocity [m/s] of the Moon and
    the Sun (TDB), :data:`tqdyn.dynamics.N_SYSTEM_TDAT` columns starting at
    the force model's ``n_tdat`` (= ``cpar[CP_TD]``).  Everything else is the
    force model's."""

    def __init__(self, model: ForceModel, system: System):
        self._model = model
        self._system = system
        self.n_tdat = model.n_tdat + _dyn.N_SYSTEM_TDAT

    def __getattr__(self, name):
        return getattr(self._model, name)

    @property
    def time_dependent(self) -> bool:
        return True

    def precompute(self, epoch, t_hi, t_lo) -> np.ndarray:
        from ..astro.timescales import tdb_jd

        base = self._model.precompute(epoch, t_hi, t_lo)
        jd1, jd2 = tdb_jd(epoch, t_hi, t_lo)
        pos, vel = self._system.ephemeris.geocentric_states(_dyn.SYSTEM_TDAT_BODIES, jd1, jd2, velocity=True)
        extra = np.concatenate([pos, vel], axis=-1).reshape(np.shape(t_hi) + (_dyn.N_SYSTEM_TDAT,))
        return np.concatenate([base, extra], axis=-1)


def self_gravity_oa(scenario) -> np.ndarray:
    """DC self-gravity of the scenario's TMs, (3, 2, 3) [m/s^2] in OA_l."""
    from ..constellation.spacecraft import TABLE_IV_SELF_GRAVITY

    oa, _ = scenario.spacecraft.self_gravity_values()
    return np.broadcast_to(TABLE_IV_SELF_GRAVITY, (3, 2, 3)).copy() if oa is None else oa


def build_system(scenario, model: ForceModel | None = None) -> System:
    """The :class:`System` of a scenario (point masses unless
    ``constellation.pointing`` names a law).  ``model``: the scenario's force
    model (built if None), whose time-only inputs the system's follow."""
    from ..constellation._kinematics_jit import LAW_CODES
    from ..constellation.spacecraft import Spacecraft
    from ..astro.ephemeris import planetary_gm
    from ..forces.model import _ephemeris

    c = scenario.constellation
    if not c.coupled:
        return System(_dyn.make_cpar(_dyn.MODE_POINT_MASS), False, False)
    sc = scenario.spacecraft
    craft = Spacecraft(d_tm=float(sc.d_tm_m), d_p=float(sc.d_p_m), tm_axis=sc.tm_axis)
    _, common = sc.self_gravity_values()
    mode = _dyn.MODE_FREE_TM if c.free_tms else _dyn.MODE_COUPLED
    # jerk model of the local laws: the Moon / Sun tidal terms and J2 that the force model has
    f = scenario.forces
    law = LAW_CODES[c.pointing]
    bodies = [b for b in _dyn.SYSTEM_TDAT_BODIES if b in f.third_bodies] if law else []
    eph = _ephemeris(f.ephemeris) if bodies else None
    gms = planetary_gm() if bodies else {}
    j2k = 1.5 * _J2_EGM2008 * float(f.gm_earth) * R_EARTH_EGM2008 ** 2 if law and f.earth_degree >= 2 else 0.0
    if eph is not None and model is None:
        model = build_force_model(f)
    cpar = _dyn.make_cpar(mode, law=law, control=c.control == "on",
                          gm=float(f.gm_earth), c=C_LIGHT, d_p=craft.d_p,
                          theta_nom=craft.theta_nominal, r0_nom=craft.nominal_housing_centers,
                          sg_oa=self_gravity_oa(scenario), sg_s=common,
                          gm_moon=gms.get("moon", 0.0), gm_sun=gms.get("sun", 0.0), j2k=j2k,
                          tdat_offset=model.n_tdat if eph is not None else -1)
    return System(cpar, True, c.free_tms, eph)


#: J2 = -sqrt(5) C20 of EGM2008 (tide-free), for the jerk model only (it enters
#: omega_dot of the local laws at ~1e-19 rad/s^2: 5 digits are plenty).
_J2_EGM2008 = 1.08263e-3


def initial_state(scenario, model: ForceModel | None = None, system: System | None = None) -> np.ndarray:
    """Initial GCRS states as a dd array (n_body, 6, 2): rows x, y, z [m],
    vx, vy, vz [m/s].  Satellites: exact elements converted in mpmath and
    rounded once to dd.  With free TMs (bodies 3 + 2 i + l) the TMs start
    at their EH centers with the EH centers' velocities (from the nominal
    attitude at t = 0, which needs the force model)."""
    gm = scenario.forces.gm_earth
    rows = []
    for sat in scenario.satellites:
        r, v = _el.elements_to_state(sat.a_m, sat.e, _el.deg(sat.i_deg), _el.deg(sat.raan_deg),
                                     _el.deg(sat.argp_deg), _el.deg(sat.nu_deg), gm)
        rows.append(_el.state_to_dd(r, v))
    y = np.stack(rows)
    system = build_system(scenario, model) if system is None else system
    if not system.free_tms:
        return y
    model = system.with_inputs(build_force_model(scenario.forces) if model is None else model)
    cpar = system.cpar.copy()
    cpar[_dyn.CP_MODE] = _dyn.MODE_COUPLED
    tdat = (model.precompute(Epoch.from_utc(scenario.epoch_utc), np.zeros(1), np.zeros(1))[0]
            if model.time_dependent else np.zeros(0))
    _, aux = evaluate_rhs(y, tdat, model, cpar, with_aux=True)
    v = _dyn.aux_views(aux)
    tm = np.zeros((6, 6, 2))
    tm[:, 0:3, 0] = v["tm_r_hi"].reshape(6, 3)
    tm[:, 0:3, 1] = v["tm_r_lo"].reshape(6, 3)
    tm[:, 3:6, 0] = v["tm_v_hi"].reshape(6, 3)
    tm[:, 3:6, 1] = v["tm_v_lo"].reshape(6, 3)
    return np.concatenate([y, tm])


def _as_precision(y_dd: np.ndarray, precision: str) -> np.ndarray:
    """dd array -> array of the working precision (float64 drops the dd axis, rounding hi+lo)."""
    if precision == "dd":
        return np.array(y_dd, dtype=np.float64, order="C", copy=True)
    return np.ascontiguousarray(y_dd[..., 0] + y_dd[..., 1])


def _to_dd(y: np.ndarray, ndim_value: int) -> np.ndarray:
    """Working-precision array -> dd array (float64 gets lo = 0)."""
    if y.ndim == ndim_value + 1:
        return y
    return np.stack([y, np.zeros_like(y)], axis=-1)


# --------------------------------------------------------------------------
# compiled loops


@njit(cache=True)
def _one_step(y, comp, K, ystage, err, ha, nz, nnz, hb, nzb, nnzb, he, tdat_step, params, layout,
              cpar, aux0, aux, gw, fw):
    """One DP87 step in place: the 13 stages (K[0] = f(y) first, its
    diagnostics into aux0), then the compensated update of y.  tdat_step:
    (13, n_tdat) time-only inputs at the stage times.  Independent point
    masses call their right-hand side directly: passing the coupled system's
    work arrays 13 times per step costs ~4 us (their reference counts)."""
    if cpar[_dyn.CP_MODE] == _dyn.MODE_POINT_MASS:
        point_masses(y, tdat_step[0], params, layout, K[0])
        for i in range(1, 13):
            dp87.stage_state(y, K, ha, nz, nnz, i, ystage)
            point_masses(ystage, tdat_step[i], params, layout, K[i])
    else:
        system_rhs(y, tdat_step[0], params, layout, cpar, K[0], aux0, gw, fw)
        for i in range(1, 13):
            dp87.stage_state(y, K, ha, nz, nnz, i, ystage)
            system_rhs(ystage, tdat_step[i], params, layout, cpar, K[i], aux, gw, fw)
    dp87.combine(y, comp, K, hb, nzb, nnzb, he, err)


@njit(cache=True, nogil=True)
def _fixed_chunk(y, comp, K, ystage, err, ha, nz, nnz, hb, nzb, nnzb, he, tdat, params, layout,
                 cpar, aux, gw, fw, n_steps, out_y, out_a, out_aux):
    """n_steps fixed DP87 steps.  Before step n it records the state y_n in
    out_y[n] (n_body, 6[, 2]); after it, f(y_n)'s acceleration (stage 1) in
    out_a[n] (n_body, 3[, 2]) and its diagnostics in out_aux[n] (AUX_LEN,)
    (if out_aux has rows).  tdat: (n_steps, 13, n_tdat)."""
    for n in range(n_steps):
        out_y[n] = y
        aux0 = out_aux[n] if out_aux.shape[0] > 0 else aux
        _one_step(y, comp, K, ystage, err, ha, nz, nnz, hb, nzb, nnzb, he, tdat[n], params, layout,
                  cpar, aux0, aux, gw, fw)
        out_a[n] = K[0][:, 3:6]


@njit(cache=True)
def _grid_times(n0, m, h, c, t_out, t_nodes):
    """t_out[k] = (n0 + k) h (dd, exact for the usual decimal steps) and, if
    t_nodes has rows, the stage times t_nodes[k, i] = t_out[k] + c_i h.
    h: (2,) dd step [s]; c: (13,) nodes; t_out: (m, 2); t_nodes: (m or 0, 13, 2)."""
    hd = (h[0], h[1])
    for k in range(m):
        t = mul(hd, float(n0 + k))
        st(t_out, t, k)
        if t_nodes.shape[0] > 0:
            for i in range(c.shape[0]):
                st(t_nodes, add(t, mul(hd, c[i])), k, i)


@njit(cache=True)
def _scale_tableau(a, b, h, ha, hb):
    """ha = h * a, hb = h * b in the working precision (h: generic number)."""
    for i in range(a.shape[0]):
        st(hb, mul(ld(b, i), h), i)
        for j in range(a.shape[1]):
            st(ha, mul(ld(a, i, j), h), i, j)


def evaluate_rhs(y: np.ndarray, tdat_row: np.ndarray, model: ForceModel, cpar: np.ndarray | None = None,
                 with_aux: bool = False):
    """dy/dt at one instant, same layout and precision as ``y``.

    cpar: the system's parameters (:attr:`System.cpar`; default: point
    masses).  With ``with_aux`` returns (k, aux), aux the (AUX_LEN,)
    diagnostics of the coupled modes (see :func:`tqdyn.dynamics.aux_views`).
    """
    k = np.zeros_like(y)
    cpar = _dyn.make_cpar(_dyn.MODE_POINT_MASS) if cpar is None else cpar
    gw, fw, aux = _dyn.workspace(y)
    _rhs_at(y, tdat_row, model.params, model.layout, cpar, k, aux, gw, fw)
    return (k, aux) if with_aux else k


@njit(cache=True)
def _rhs_at(y, tdat_row, params, layout, cpar, k, aux, gw, fw):
    system_rhs(y, tdat_row, params, layout, cpar, k, aux, gw, fw)


def warm_up(precision: str = "dd") -> None:
    """Compile the fixed-step kernels for ``precision`` (numba JIT, a few
    seconds on first use in a process, then cached on disk) so that later
    timings measure the propagation alone.  One compiled kernel serves the
    point-mass and the coupled systems."""
    _check_precision(precision)
    tail = (2,) if precision == "dd" else ()
    y = np.zeros((1, 6) + tail)
    y[0, 0] = 1.0e7
    y[0, 4] = 6.0e3
    coef = dp87.step_coefficients(dp87.load_tableau(), 1, precision)
    model = ForceModel([])
    K = np.zeros((13,) + y.shape)
    cpar = _dyn.make_cpar(_dyn.MODE_POINT_MASS)
    gw, fw, aux = _dyn.workspace(y)
    _fixed_chunk(y, np.zeros_like(y), K, np.zeros_like(y), np.zeros((1, 6)), coef.ha, coef.nz, coef.nnz,
                 coef.hb, coef.nzb, coef.nnzb, coef.he, np.zeros((1, 13, 0)), model.params, model.layout,
                 cpar, aux, gw, fw, 1, np.empty((1,) + y.shape), np.empty((1, 1, 3) + tail),
                 np.empty((0, _dyn.AUX_LEN)))
    _grid_times(0, 1, np.array(coef.h), coef.c, np.empty((1, 2)), np.empty((0, 13, 2)))
    evaluate_rhs(y, np.zeros(0), model)


# --------------------------------------------------------------------------
# Python driver


@dataclass(frozen=True)
class Checkpoint:
    """State of a fixed-step run after ``n`` steps: y (working precision,
    (n_sat, 6[, 2])) and its Kahan compensation ``comp``.  Resuming from it
    reproduces the uninterrupted run bit for bit (every step depends only on
    y, comp and the step index)."""

    n: int
    y: np.ndarray
    comp: np.ndarray


@dataclass
class RunResult:
    """Outcome of a propagation.

    t_final: (2,) dd [s TDB since epoch]; y0, y_final: (n_sat, 6, 2) dd GCRS
    states [m, m/s] (float64 runs have lo = 0); n_steps: accepted steps;
    n_rejected: rejected steps (adaptive); n_rhs: right-hand-side
    evaluations; wall_s: wall time of the propagation [s];
    energy_rel_drift: (n_sat,) relative change of the two-body energy
    v^2/2 - GM/r (only for a pure monopole model, else None).
    """

    precision: str
    mode: str
    t_final: np.ndarray
    y0: np.ndarray
    y_final: np.ndarray
    n_steps: int
    n_rejected: int
    n_rhs: int
    wall_s: float
    energy_rel_drift: np.ndarray | None = None
    extra: dict = field(default_factory=dict)


def two_body_energy(y_dd: np.ndarray, gm) -> list:
    """Specific two-body energy v^2/2 - gm/|r| [J/kg] of each body, in mpmath
    (exact from the dd states).  y_dd: (n_body, 6, 2)."""
    vals = mp_from_dd(y_dd)
    out = []
    with mpmath.workdps(60):
        g = mpmath.mpf(str(gm))
        for row in vals:
            r = mpmath.sqrt(sum(x * x for x in row[:3]))
            out.append(sum(x * x for x in row[3:]) / 2 - g / r)
    return out


def _rows(t, y, a, precision, every, n0, aux=None, system: System | None = None):
    """Output rows for global step indices n0.. whose index is a multiple of ``every``."""
    sel = (np.arange(n0, n0 + t.shape[0]) % every) == 0
    y_dd = _to_dd(y[sel], 3)
    a_f = a[sel][..., 0] if precision == "dd" else a[sel]
    rows = {
        "t": (t[sel, 0], t[sel, 1]),
        "sat/r": (y_dd[:, :3, 0:3, 0], y_dd[:, :3, 0:3, 1]),
        "sat/v": (y_dd[:, :3, 3:6, 0], y_dd[:, :3, 3:6, 1]),
        "sat/a_gravity": a_f,
    }
    if system is None or not system.coupled:
        return rows
    v = _dyn.aux_views(aux[sel])
    rows.update({
        "sat/a_gravity": v["a_gravity"],
        "sat/a_dragfree": v["a_dragfree"],
        "sat/T_S_I": v["T_S_I"],
        "sat/omega": v["omega"],
        "sat/omega_dot": v["omega_dot"],
        "sat/breathing_angle": v["breathing_angle"],
        "mosa/angle": 0.5 * v["theta"][..., None] * np.array([1.0, -1.0]),
        "tm/a": v["tm_a"],
        "tm/a_suspension": v["tm_a_suspension"],
        "tm/alpha_suspension": v["tm_alpha_suspension"],
    })
    if system.free_tms:
        tm = y_dd[:, 3:9].reshape(y_dd.shape[0], 3, 2, 6, 2)
        rows["tm/r"] = (tm[..., 0:3, 0], tm[..., 0:3, 1])
        rows["tm/v"] = (tm[..., 3:6, 0], tm[..., 3:6, 1])
        rows["tm/housing_offset"] = v["tm_housing_offset"]
    else:
        rows["tm/r"] = (v["tm_r_hi"], v["tm_r_lo"])
        rows["tm/v"] = (v["tm_v_hi"], v["tm_v_lo"])
    return rows


def _check_precision(precision):
    if precision not in PRECISIONS:
        raise ValueError(f"run.precision: {precision!r} is not allowed; allowed: {', '.join(PRECISIONS)}")


def propagate(scenario, *, precision: str | None = None, sink: Callable[[Mapping], None] | None = None,
              progress: Callable[[int], None] | None = None, chunk: int = _DEFAULT_CHUNK,
              y0: np.ndarray | None = None, model: ForceModel | None = None,
              start: Checkpoint | None = None, checkpoint: Callable[[Checkpoint], None] | None = None,
              checkpoint_every: int = 0) -> RunResult:
    """Propagate the scenario's satellites over ``scenario.run.duration_s``.

    precision: "dd" | "float64" (default: the scenario's run.precision).
    sink(rows): receives output rows every chunk -- a dict with "t" (hi, lo)
    (m,) [s TDB since epoch], "sat/r" and "sat/v" (hi, lo) (m, n_sat, 3)
    [m, m/s, GCRS], "sat/a_gravity" (m, n_sat, 3) float64 [m/s^2] -- on the
    output grid (every run.output_every-th step; the adaptive mode samples
    the fixed grid k * integrator.step_s by dense output).
    progress(n): called with the number of steps just completed (fixed) or
    the seconds of propagation time just covered (adaptive).
    y0: optional initial dd states (n_sat, 6, 2) instead of the scenario's elements.
    model: optional force model instead of the one built from scenario.forces.
    start: resume a fixed-step run from this checkpoint (its rows before
    start.n are not emitted again).  checkpoint(Checkpoint): called every
    ``checkpoint_every`` steps (fixed mode; 0 = never) after the rows up to
    that step went to the sink.
    """
    precision = precision or scenario.run.precision
    _check_precision(precision)
    model = build_force_model(scenario.forces) if model is None else model
    system = build_system(scenario, model)
    model = system.with_inputs(model)
    epoch = Epoch.from_utc(scenario.epoch_utc)
    tab = dp87.load_tableau(scenario.integrator.tableau)
    y0_dd = initial_state(scenario, model, system) if y0 is None else np.asarray(y0, np.float64)
    if scenario.integrator.mode == "adaptive":
        if start is not None or checkpoint_every:
            raise ValueError("integrator.mode: checkpoints and --resume need mode = \"fixed\"")
        result = _propagate_adaptive(scenario, precision, model, epoch, tab, y0_dd, sink, progress, system)
    else:
        result = _propagate_fixed(scenario, precision, model, epoch, tab, y0_dd, sink, progress, chunk,
                                  start, checkpoint, checkpoint_every, system)
    if [t.name for t in model.terms] == ["earth_monopole"] and not system.coupled:
        e0 = two_body_energy(result.y0, model.terms[0].gm)
        e1 = two_body_energy(result.y_final, model.terms[0].gm)
        with mpmath.workdps(60):
            result.energy_rel_drift = np.array([float((b - a) / abs(a)) for a, b in zip(e0, e1)])
    return result


def check_inputs(scenario, model: ForceModel | None = None) -> ForceModel:
    """Build the scenario's force model and evaluate its time-only inputs at
    the first and last instants, so that data limits (a date outside the
    ephemeris, EOP or lunar-kernel span, a missing file, a degree above what
    a file holds) raise ValueError / FileNotFoundError before any
    propagation or output starts.  Returns the model."""
    model = build_force_model(scenario.forces) if model is None else model
    epoch = Epoch.from_utc(scenario.epoch_utc)
    t_end = float(scenario.run.duration_s)
    model.precompute(epoch, np.array([0.0, t_end]), np.zeros(2))
    return model


def _workspace(y0_dd, precision):
    """State y (a copy of y0 in the working precision), its compensation,
    the 13 stage derivatives, a stage state and the error estimate."""
    y = _as_precision(y0_dd, precision)
    return y, np.zeros_like(y), np.zeros((13,) + y.shape), np.zeros_like(y), np.zeros(y.shape[:2])


def _propagate_fixed(scenario, precision, model, epoch, tab, y0_dd, sink, progress, chunk,
                     start=None, checkpoint=None, checkpoint_every=0, system=None):
    coef = dp87.step_coefficients(tab, scenario.integrator.step_s, precision)
    n_total = scenario.n_steps
    every = scenario.run.output_every
    y, comp, K, ystage, err = _workspace(y0_dd, precision)
    n = 0
    if start is not None:
        if start.y.shape != y.shape or not 0 <= start.n <= n_total:
            raise ValueError(f"checkpoint: state shape {start.y.shape} at step {start.n} does not fit this run "
                             f"({y.shape}, {n_total} steps)")
        n = int(start.n)
        y[...] = start.y
        comp[...] = start.comp
    h = np.array(coef.h)
    nb = y.shape[0]
    acc_shape = (nb, 3) + y.shape[2:]
    cpar = system.cpar
    gw, fw, aux = _dyn.workspace(y)
    n_aux = _dyn.AUX_LEN if system.coupled else 0
    t_start = _time.perf_counter()
    extremes: dict = {}
    # chunk boundaries (fixed by chunk and checkpoint_every, so a resumed run
    # takes the same steps); the time-only inputs of the next chunk are
    # computed in a second thread while the compiled loop (nogil) runs.
    plan = []
    n_plan = n
    while n_plan < n_total:
        m = min(chunk, n_total - n_plan)
        if checkpoint_every:
            m = min(m, (n_plan // checkpoint_every + 1) * checkpoint_every - n_plan)
        plan.append((n_plan, m))
        n_plan += m

    def inputs(n0, m):
        t_out = np.empty((m, 2))
        t_nodes = np.empty((m if model.time_dependent else 0, 13, 2))
        _grid_times(n0, m, h, coef.c, t_out, t_nodes)
        tdat = (model.precompute(epoch, t_nodes[..., 0], t_nodes[..., 1]) if model.time_dependent
                else np.zeros((m, 13, 0)))
        return t_out, tdat

    with ThreadPoolExecutor(max_workers=1) as pool:
        pending = pool.submit(inputs, *plan[0]) if plan else None
        for idx, (n0, m) in enumerate(plan):
            t_out, tdat = pending.result()
            pending = pool.submit(inputs, *plan[idx + 1]) if idx + 1 < len(plan) else None
            out_y = np.empty((m,) + y.shape)
            out_a = np.empty((m,) + acc_shape)
            out_aux = np.empty((m if n_aux else 0, _dyn.AUX_LEN))
            _fixed_chunk(y, comp, K, ystage, err, coef.ha, coef.nz, coef.nnz, coef.hb, coef.nzb, coef.nnzb,
                         coef.he, tdat, model.params, model.layout, cpar, aux, gw, fw, m, out_y, out_a, out_aux)
            if sink is not None:
                sink(_rows(t_out, out_y, out_a, precision, every, n0, out_aux, system))
            if n_aux:
                _update_extremes(extremes, out_aux, system)
            n = n0 + m
            if progress is not None:
                progress(m)
            if checkpoint is not None and checkpoint_every and n % checkpoint_every == 0 and n < n_total:
                checkpoint(Checkpoint(n, y.copy(), comp.copy()))
    # the final state and its acceleration
    t_end = np.empty((1, 2))
    t_nodes = np.empty((1 if model.time_dependent else 0, 13, 2))
    _grid_times(n_total, 1, h, coef.c, t_end, t_nodes)
    tdat_end = (model.precompute(epoch, t_nodes[0, 0, 0], t_nodes[0, 0, 1]) if model.time_dependent
                else np.zeros(0))
    k_end, aux_end = evaluate_rhs(y, np.atleast_1d(tdat_end), model, cpar, with_aux=True)
    wall = _time.perf_counter() - t_start
    if sink is not None:
        sink(_rows(t_end, y[None], k_end[None, :, 3:6], precision, every, n_total, aux_end[None], system))
    return RunResult(precision=precision, mode="fixed", t_final=t_end[0], y0=y0_dd,
                     y_final=_to_dd(y, 2), n_steps=n_total, n_rejected=0,
                     n_rhs=13 * n_total + 1, wall_s=wall, extra=_format_extremes(extremes))


def _update_extremes(ext: dict, out_aux: np.ndarray, system: System) -> None:
    """Running maxima of the control quantities over the steps of a chunk."""
    v = _dyn.aux_views(out_aux)
    vals = {"G": np.linalg.norm(v["a_dragfree"], axis=-1).max(),
            "A": np.abs(v["tm_a_suspension"]).max(),
            "alpha": np.abs(v["tm_alpha_suspension"]).max()}
    if system.free_tms:
        vals["drift"] = np.linalg.norm(v["tm_housing_offset"], axis=-1).max()
    for key, val in vals.items():
        ext[key] = max(ext.get(key, 0.0), float(val))


def _format_extremes(ext: dict) -> dict:
    names = {"G": ("max |G_i| (drag-free)", "m/s^2"), "A": ("max |A_c,l| component (suspension)", "m/s^2"),
             "alpha": ("max |alpha_l| component (TM angular)", "rad/s^2"),
             "drift": ("max |TM - EH center| (free TMs)", "m")}
    return {names[k][0]: f"{v:.3e} {names[k][1]}" for k, v in ext.items()}


def _dd_of(x: Fraction) -> tuple[float, float]:
    """Exact rational -> dd pair."""
    hi = float(x)
    return hi, float(x - Fraction(hi))


def _node_tdat(model, epoch, times) -> np.ndarray:
    """Time-only inputs at exact times (list of Fractions, s TDB since epoch): (len, n_tdat)."""
    if not model.time_dependent:
        return np.zeros((len(times), 0))
    pairs = np.array([_dd_of(t) for t in times])
    return model.precompute(epoch, pairs[:, 0], pairs[:, 1])


#: max|r^(6)| (h/2)^6 / 6! bound of the quintic Hermite error, written as
#: |r| (w h)^6 / _QUINTIC_ERROR_DIVISOR for a motion of angular rate w.
_QUINTIC_ERROR_DIVISOR = 46080.0
#: Margin on that step (error ~ h^6: 0.75 -> 0.18 of the bound) for the
#: higher harmonics of eccentric motion near perigee, which the rate w does
#: not capture (measured: 3.9x the bound on e = 0.1 without it).
_DENSE_OUTPUT_SAFETY = 0.75


def _dense_output_max_step(y, a, rtol) -> float:
    """Largest step [s] whose quintic Hermite dense output stays within
    rtol * |r|: h <= safety * (46080 rtol)^(1/6) / w, with the angular rate
    w = max(sqrt(|a| / |r|), |v| / |r|) [rad/s] of the fastest body (for a
    Keplerian orbit sqrt(GM / r^3) and the rate of the radius vector)."""
    y_dd = _to_dd(y, 2)
    r = np.linalg.norm(y_dd[:, 0:3, 0], axis=1)
    v = np.linalg.norm(y_dd[:, 3:6, 0], axis=1)
    acc = np.linalg.norm(np.asarray(a)[..., 0] if np.ndim(a) == 3 else a, axis=1)
    w = float(np.max(np.maximum(np.sqrt(acc / r), v / r)))
    return _DENSE_OUTPUT_SAFETY * (_QUINTIC_ERROR_DIVISOR * rtol) ** (1.0 / 6.0) / w if w > 0 else np.inf


def _propagate_adaptive(scenario, precision, model, epoch, tab, y0_dd, sink, progress, system):
    """Embedded-error step-size control (7th-order estimate, local error
    per step <= rtol * |r| and rtol * |v| per body), output sampled on the
    grid k * integrator.step_s by quintic Hermite dense output.  Time is
    tracked as an exact rational (each step is an exact binary float)."""
    rtol = float(scenario.integrator.rtol)
    T = Fraction(scenario.run.duration_s)
    dt_out = Fraction(scenario.integrator.step_s)
    unit = dp87.step_coefficients(tab, 1, precision)  # h = 1: the bare tableau
    c_nodes = [Fraction(x) for x in unit.c]
    y, comp, K, ystage, err = _workspace(y0_dd, precision)
    ha = np.zeros_like(unit.ha)
    hb = np.zeros_like(unit.hb)
    z = np.array([0.0, 1.0])
    nb = y.shape[0]
    rows: list = []
    cpar = system.cpar
    gw, fw, aux = _dyn.workspace(y)

    def flush(force=False):
        if sink is not None and rows and (force or len(rows) >= _DEFAULT_CHUNK):
            t_arr = np.array([r[0] for r in rows])
            y_arr = np.stack([r[1] for r in rows])
            a_arr = np.stack([r[2] for r in rows])
            aux_arr = np.stack([r[3] for r in rows])
            sink(_rows(t_arr, y_arr, a_arr, precision, 1, 0, aux_arr, system))
            rows.clear()

    def emit(t_exact, y_row):
        k_row, aux_row = evaluate_rhs(y_row, _node_tdat(model, epoch, [t_exact])[0], model, cpar, with_aux=True)
        rows.append((_dd_of(t_exact), y_row.copy(), k_row[:, 3:6].copy(), aux_row))
        flush()

    t_start = _time.perf_counter()
    t = Fraction(0)
    k_out = 1
    emit(t, y)
    h_max = _dense_output_max_step(y, rows[0][2] if rows else evaluate_rhs(y, _node_tdat(model, epoch, [t])[0], model,
                                                                            cpar)[:, 3:6], rtol)
    h = min(float(min(dt_out, T)), h_max)
    n_acc = n_rej = n_rhs = 0
    while t < T:
        last = Fraction(h) >= T - t
        h_exact = T - t if last else Fraction(h)
        h_pair = np.array(_dd_of(h_exact))
        _scale_tableau(unit.ha, unit.hb, (h_pair[0], h_pair[1]) if precision == "dd" else h_pair[0], ha, hb)
        he = unit.he * float(h_exact)
        tdat = _node_tdat(model, epoch, [t + ci * h_exact for ci in c_nodes])
        y_try, comp_try = y.copy(), comp.copy()
        _one_step(y_try, comp_try, K, ystage, err, ha, unit.nz, unit.nnz, hb, unit.nzb, unit.nnzb, he,
                  tdat, model.params, model.layout, cpar, aux, aux, gw, fw)
        n_rhs += 13
        norm = dp87.error_norm(y_try, err, rtol)
        if norm <= 1.0:
            t_new = t + h_exact
            a0 = K[0][:, 3:6].copy()
            a1 = evaluate_rhs(y_try, _node_tdat(model, epoch, [t_new])[0], model, cpar)[:, 3:6]
            n_rhs += 1
            while k_out * dt_out <= t_new:
                t_k = k_out * dt_out
                if t_k == t_new:
                    y_k = y_try
                else:
                    s_pair = _dd_of((t_k - t) / h_exact)
                    y_k = np.empty_like(y)
                    s = (s_pair[0], s_pair[1]) if precision == "dd" else s_pair[0]
                    hh = (h_pair[0], h_pair[1]) if precision == "dd" else h_pair[0]
                    for b in range(nb):
                        nodes_r = np.stack([y[b, 0:3], y_try[b, 0:3]])
                        nodes_v = np.stack([y[b, 3:6], y_try[b, 3:6]])
                        nodes_a = np.stack([a0[b], a1[b]])
                        hermite.hermite_eval(z, nodes_r, nodes_v, nodes_a, hh, s, y_k[b, 0:3], y_k[b, 3:6])
                emit(t_k, y_k)
                k_out += 1
            if progress is not None:
                progress(float(h_exact))
            t, y, comp = t_new, y_try, comp_try
            n_acc += 1
            h_max = _dense_output_max_step(y, a1, rtol)
        else:
            n_rej += 1
        h = min(h * dp87.next_step_factor(norm), h_max)
    flush(force=True)
    wall = _time.perf_counter() - t_start
    return RunResult(precision=precision, mode="adaptive", t_final=np.array(_dd_of(t)), y0=y0_dd,
                     y_final=_to_dd(y, 2), n_steps=n_acc, n_rejected=n_rej, n_rhs=n_rhs, wall_s=wall)
