"""What a propagation produces: typed output rows, checkpoints and the run result.

:class:`Rows` is one block of output rows on the output grid, one typed
attribute per output quantity.  The trajectory file maps each attribute to
its field (``sat_r`` -> ``sat/r``: :func:`tqdyn.formats.trajectory.row_fields`);
nothing here knows about files.  Double-double quantities are (hi, lo) pairs
of float64 arrays (value = hi + lo exactly); frames as in the attribute list
(the inertial frame is the force model's, GCRS for the geocentric model).
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields

import numpy as np

from ..constellation.indices import MOSA_SIGN
from . import layout as _lay

__all__ = ["Rows", "Checkpoint", "NonFiniteStateError", "RunResult", "check_finite_states", "row_names"]

DD = tuple  # (hi, lo) pair of float64 arrays of equal shape


@dataclass(frozen=True)
class Rows:
    """A block of m output rows (m >= 1) of a propagation.

    Always present:

    t : (hi, lo) (m,) -- s since the epoch, in the run's time scale;
    sat_r, sat_v : (hi, lo) (m, n_sat, 3) -- m, m/s, inertial frame;
    sat_a_gravity : (m, n_sat, 3) -- m/s^2, inertial, all gravitational terms
        (point masses: the whole acceleration).

    n_sat is the number of satellites: any (>= 1) for independent point
    masses, 3 for the coupled constellation.

    Coupled constellation (``None`` otherwise; n_sat = 3):

    sat_a_dragfree : (m, 3, 3) -- m/s^2, inertial, the drag-free acceleration G_i;
    sat_T_S_I : (m, 3, 3, 3) -- rotation inertial -> S (rows X_S, Y_S, Z_S);
    sat_omega, sat_omega_dot : (m, 3, 3) -- rad/s, rad/s^2, in S;
    sat_breathing_angle : (m, 3) -- rad;
    mosa_angle : (m, 3, 2) -- rad, X_OA_l from X_S about Z_S (MOSA_SIGN * theta / 2);
    tm_r, tm_v : (hi, lo) (m, 3, 2, 3) -- m, m/s, inertial: the TMs (free-TM
        mode) or their housing centres;
    tm_a : (m, 3, 2, 3) -- m/s^2, inertial, TM total acceleration;
    tm_a_suspension, tm_alpha_suspension : (m, 3, 2, 3) -- m/s^2, rad/s^2, in OA_l;
    tm_housing_offset : (m, 3, 2, 3) -- m, inertial, TM minus housing centre
        (free-TM mode only).
    """

    t: DD
    sat_r: DD
    sat_v: DD
    sat_a_gravity: np.ndarray
    sat_a_dragfree: np.ndarray | None = None
    sat_T_S_I: np.ndarray | None = None
    sat_omega: np.ndarray | None = None
    sat_omega_dot: np.ndarray | None = None
    sat_breathing_angle: np.ndarray | None = None
    mosa_angle: np.ndarray | None = None
    tm_r: DD | None = None
    tm_v: DD | None = None
    tm_a: np.ndarray | None = None
    tm_a_suspension: np.ndarray | None = None
    tm_alpha_suspension: np.ndarray | None = None
    tm_housing_offset: np.ndarray | None = None

    def __len__(self) -> int:
        return int(np.shape(self.t[0])[0])

    def items(self):
        """(name, value) of the quantities present, in declaration order."""
        return [(f.name, getattr(self, f.name)) for f in fields(self) if getattr(self, f.name) is not None]

    @classmethod
    def concatenate(cls, blocks) -> "Rows":
        """One :class:`Rows` of the blocks' rows in order (the same quantities in every block)."""
        blocks = list(blocks)
        if not blocks:
            raise ValueError("Rows.concatenate: no blocks")
        out = {}
        for name, first in blocks[0].items():
            parts = [getattr(b, name) for b in blocks]
            if isinstance(first, tuple):
                out[name] = (np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts]))
            else:
                out[name] = np.concatenate(parts)
        return cls(**out)


_POINT_MASS_ROWS = ("t", "sat_r", "sat_v", "sat_a_gravity")
_COUPLED_ROWS = _POINT_MASS_ROWS + ("sat_a_dragfree", "sat_T_S_I", "sat_omega", "sat_omega_dot",
                                    "sat_breathing_angle", "mosa_angle", "tm_r", "tm_v", "tm_a",
                                    "tm_a_suspension", "tm_alpha_suspension")


def row_names(coupled: bool, free_tms: bool = False) -> tuple[str, ...]:
    """Names of the :class:`Rows` attributes a system produces, in declaration order."""
    if not coupled:
        return _POINT_MASS_ROWS
    return _COUPLED_ROWS + (("tm_housing_offset",) if free_tms else ())


class NonFiniteStateError(ValueError):
    """A propagation stopped because a state is no longer finite (inf or NaN: a force or acceleration
    out of range).  step: the step index whose state is not finite (0 the initial state); t [s since
    the epoch, the run's time scale]; body: the index of the body in the state (satellites first, then
    the test masses of the free-TM mode); the message names them (and the satellite, once
    :func:`tqdyn.dynamics.propagate` knows the names)."""

    def __init__(self, step: int, t: float, body: int, name: str | None = None, time_scale: str = ""):
        self.step, self.t, self.body = int(step), float(t), int(body)
        who = repr(name) if name else f"body {self.body}"
        scale = f" {time_scale}" if time_scale else ""
        super().__init__(f"propagation: the state of {who} is not finite at step {self.step} (t = {self.t:.9g} s"
                         f"{scale} after the epoch): a force, acceleration or initial state is out of range")


def check_finite_states(n0: int, t: np.ndarray, y: np.ndarray) -> None:
    """Raise :class:`NonFiniteStateError` at the first of the steps n0, n0 + 1, ... whose state is
    not finite.  t: (m, 2) dd times [s]; y: (m, n_body, 6[, 2]) states.  Cheap for finite rows (one
    sum of the block; the rows are searched only when it is not finite)."""
    with np.errstate(over="ignore", invalid="ignore"):
        if np.isfinite(np.sum(y)):
            return
    ok = np.isfinite(y.reshape(y.shape[0], y.shape[1], -1)).all(axis=2)          # (m, n_body)
    if ok.all():  # a finite block whose sum overflowed
        return
    k, b = np.argwhere(~ok)[0]
    t = np.asarray(t, np.float64).reshape(-1, 2)
    raise NonFiniteStateError(n0 + int(k), float(t[k, 0] + t[k, 1]), int(b))


def to_dd(y: np.ndarray, ndim_value: int) -> np.ndarray:
    """Working-precision array -> dd array (float64 gets lo = 0)."""
    if y.ndim == ndim_value + 1:
        return y
    return np.stack([y, np.zeros_like(y)], axis=-1)


def select_rows(t, y, a, precision, every, n0, aux=None, system=None) -> Rows:
    """The output rows among a chunk's steps n0, n0 + 1, ...: those whose
    global step index is a multiple of ``every``.  t: (m, 2) dd times; y:
    (m, n_body, 6[, 2]) states; a: (m, n_body, 3[, 2]) accelerations; aux:
    (m, AUX_LEN) diagnostics of the coupled modes; system: the
    :class:`~tqdyn.dynamics.system.System` (None: point masses)."""
    sel = (np.arange(n0, n0 + t.shape[0]) % every) == 0
    y_dd = to_dd(y[sel], 3)
    a_f = a[sel][..., 0] if precision == "dd" else a[sel]
    coupled = system is not None and system.coupled
    ns = 3 if coupled else y_dd.shape[1]  # point masses: every body is a satellite; coupled: bodies 0..2
    base = dict(t=(t[sel, 0], t[sel, 1]), sat_r=(y_dd[:, :ns, 0:3, 0], y_dd[:, :ns, 0:3, 1]),
                sat_v=(y_dd[:, :ns, 3:6, 0], y_dd[:, :ns, 3:6, 1]))
    if not coupled:
        return Rows(sat_a_gravity=a_f, **base)
    v = _lay.aux_views(aux[sel])
    if system.free_tms:
        tm = y_dd[:, 3:9].reshape(y_dd.shape[0], 3, 2, 6, 2)
        tm_r, tm_v = (tm[..., 0:3, 0], tm[..., 0:3, 1]), (tm[..., 3:6, 0], tm[..., 3:6, 1])
        offset = v["tm_housing_offset"]
    else:
        tm_r, tm_v = (v["tm_r_hi"], v["tm_r_lo"]), (v["tm_v_hi"], v["tm_v_lo"])
        offset = None
    return Rows(sat_a_gravity=v["a_gravity"], sat_a_dragfree=v["a_dragfree"], sat_T_S_I=v["T_S_I"],
                sat_omega=v["omega"], sat_omega_dot=v["omega_dot"], sat_breathing_angle=v["breathing_angle"],
                mosa_angle=0.5 * v["theta"][..., None] * MOSA_SIGN, tm_r=tm_r, tm_v=tm_v, tm_a=v["tm_a"],
                tm_a_suspension=v["tm_a_suspension"], tm_alpha_suspension=v["tm_alpha_suspension"],
                tm_housing_offset=offset, **base)


@dataclass(frozen=True)
class Checkpoint:
    """State of a fixed-step run after ``n`` steps: y (working precision,
    (n_body, 6[, 2]): the satellites, then the TMs in the free-TM mode) and
    its Kahan compensation ``comp``; ``table``: the multistep integrator's
    table as one flat float64 array (accelerations, sums, compensations and
    the last diagnostics, :mod:`tqdyn.dynamics.multistep`; None for DP87).
    Resuming from it reproduces the uninterrupted run bit for bit (every
    step depends only on y, comp, the table and the step index)."""

    n: int
    y: np.ndarray
    comp: np.ndarray
    table: np.ndarray | None = None


@dataclass
class RunResult:
    """Outcome of a propagation.

    t_final: (2,) dd [s since the epoch, in the reference system's time
    scale]; y0, y_final: (n_body, 6, 2) dd states [m, m/s] in the reference
    system (float64 runs have lo = 0); n_steps: accepted steps;
    n_rejected: rejected steps (adaptive); n_rhs: right-hand-side
    evaluations; wall_s: wall time of the propagation [s];
    energy_rel_drift: (n_sat,) relative change of the two-body energy
    v^2/2 - GM/r (only for a pure monopole model, else None);
    reference: the :class:`~tqdyn.astro.reference.ReferenceSystem` of the
    states and times (the force model's); cpu_inputs_s, cpu_loop_s: CPU
    time [s] of the time-only inputs (their thread) and of the compiled loop
    (fixed mode; 0 otherwise) -- on two cores the wall time cannot be below
    half their sum; cpu_process_s: CPU time [s] of the whole process during
    :func:`~tqdyn.dynamics.propagate` (all threads, the BLAS library's too).
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
    reference: object = None
    cpu_inputs_s: float = 0.0
    cpu_loop_s: float = 0.0
    cpu_process_s: float = 0.0


def update_extremes(ext: dict, out_aux: np.ndarray, system) -> None:
    """Running maxima of the control quantities over the steps of a chunk."""
    v = _lay.aux_views(out_aux)
    vals = {"G": np.linalg.norm(v["a_dragfree"], axis=-1).max(),
            "A": np.abs(v["tm_a_suspension"]).max(),
            "alpha": np.abs(v["tm_alpha_suspension"]).max()}
    if system.free_tms:
        vals["drift"] = np.linalg.norm(v["tm_housing_offset"], axis=-1).max()
    for key, val in vals.items():
        ext[key] = max(ext.get(key, 0.0), float(val))


def format_extremes(ext: dict) -> dict:
    names = {"G": ("max |G_i| (drag-free)", "m/s^2"), "A": ("max |A_c,l| component (suspension)", "m/s^2"),
             "alpha": ("max |alpha_l| component (TM angular)", "rad/s^2"),
             "drift": ("max |TM - EH center| (free TMs)", "m")}
    return {names[k][0]: f"{v:.3e} {names[k][1]}" for k, v in ext.items()}
