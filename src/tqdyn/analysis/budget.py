"""Force budget: the size of every force term along an orbit.

Each term of a force model is evaluated alone (a one-term ForceModel through
the same compiled dispatcher the propagator uses, float64) at sampled states
of a trajectory; the Earth's field is split into its static part and each
tide model.  Reported per term: max and RMS of |a| [m/s^2] over the samples
and satellites.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from ..forces.model import ForceModel, gravity

__all__ = ["TermBudget", "force_budget", "split_terms"]


@dataclass(frozen=True)
class TermBudget:
    """Budget of one term: name, description, source, and |a| [m/s^2]
    statistics over all samples and satellites; ``series`` (n_t, n_sat)."""

    name: str
    description: str
    source: str
    max: float
    rms: float
    series: np.ndarray


@njit(cache=True)
def _batch(r, v, tdat, params, layout, out):
    """|a| of one force model at many states: r, v (n, 3) float64 GCRS
    [m, m/s]; tdat (n, n_tdat); out (n,) [m/s^2]."""
    for i in range(r.shape[0]):
        ax, ay, az = gravity(r[i, 0], r[i, 1], r[i, 2], v[i, 0], v[i, 1], v[i, 2], tdat[i], params, layout)
        out[i] = np.sqrt(ax * ax + ay * ay + az * az)


def _model_evaluator(one: ForceModel):
    """|a| of a one-term model at states (n, 3) via the compiled dispatcher."""

    def evaluate(epoch, t_hi, t_lo, r, v):
        n_t, n_sat = r.shape[:2]
        tdat = one.precompute(epoch, t_hi, t_lo)  # (n_t, n_tdat)
        tdat = np.ascontiguousarray(np.repeat(tdat[:, None, :], n_sat, axis=1).reshape(n_t * n_sat, -1))
        acc = np.empty(n_t * n_sat)
        _batch(np.ascontiguousarray(r.reshape(-1, 3)), np.ascontiguousarray(v.reshape(-1, 3)), tdat,
               one.params, one.layout, acc)
        return acc.reshape(n_t, n_sat)

    return evaluate


def _tide_evaluator(field):
    """|a| of an Earth field's coefficient corrections only (one tide model)."""
    from ..forces.earth import earth_field_accel_batch

    def evaluate(epoch, t_hi, t_lo, r, v):
        n_t, n_sat = r.shape[:2]
        tdat = field.precompute(epoch, t_hi, t_lo)
        tdat = np.repeat(tdat[:, None, :], n_sat, axis=1).reshape(n_t * n_sat, -1)
        acc = earth_field_accel_batch(r.reshape(-1, 3), tdat, field.params(), part="tides")
        return np.linalg.norm(acc, axis=1).reshape(n_t, n_sat)

    return evaluate


def split_terms(model: ForceModel) -> list[tuple[str, str, str, object]]:
    """(name, description, source, evaluator) for each term of ``model``;
    an Earth field with tide models is split into its static part and one
    entry per tide model (its coefficient corrections alone), point-mass
    third bodies into one entry per body.  An evaluator
    maps (epoch, t_hi (n_t,), t_lo, r (n_t, n_sat, 3), v) to |a| (n_t, n_sat)."""
    out = []
    for term in model.terms:
        tides = getattr(term, "tides", ())
        if tides:
            static = type(term)(degree=term.degree, order=term.order, model=term.model, rotation=term.rotation)
            out.append((term.name, static.description, static.source, _model_evaluator(ForceModel([static]))))
            for provider in tides:
                one = type(term)(degree=term.degree, order=term.order, model=term.model, rotation=term.rotation,
                                 tides=(provider,))
                label = getattr(provider, "name", type(provider).__name__)
                out.append((label, getattr(provider, "description", label), getattr(provider, "source", ""),
                            _tide_evaluator(one)))
        elif hasattr(term, "split") and len(term.names) > 1:
            for one in term.split():
                out.append((f"{term.name}:{one.names[0]}", term.description, term.source,
                            _model_evaluator(ForceModel([one]))))
        else:
            out.append((term.name, term.description, term.source, _model_evaluator(ForceModel([term]))))
    return out


def force_budget(model: ForceModel, epoch, t_hi, t_lo, r, v) -> list[TermBudget]:
    """Budget of every term of ``model`` at the states r, v (n_t, n_sat, 3)
    [m, m/s, GCRS, float64] at times t_hi + t_lo (n_t,) [s TT since
    ``epoch``]."""
    r = np.asarray(r, dtype=np.float64)
    v = np.asarray(v, dtype=np.float64)
    t_hi = np.asarray(t_hi, dtype=np.float64)
    t_lo = np.asarray(t_lo, dtype=np.float64)
    out = []
    for name, description, source, evaluate in split_terms(model):
        acc = evaluate(epoch, t_hi, t_lo, r, v)
        out.append(TermBudget(name, description, source, float(acc.max()), float(np.sqrt(np.mean(acc ** 2))), acc))
    return out
