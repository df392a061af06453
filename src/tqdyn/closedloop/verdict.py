"""The requirement verdict of a constellation mission's default closed loop and the margin it lacks.

At the mission's documented static working point (:func:`tqdyn.closedloop.model.static_closed_loop_model`:
the first-principles tide and rates, theta = 60 deg), the residual acceleration of both test masses along
their sensitive axes (``tm1_acceleration``, ``tm2_acceleration``; one-sided ASDs, m s^-2/Hz^1/2) against
the mission's requirement (:func:`tqdyn.closedloop.missions.requirement`) over a band [Hz]:

* the largest ratio, its frequency and the sources that make it (per source, the worse TM);
* the *floor*: the TM force-noise input alone over the requirement (what no loop can remove);
* with a plant value (the actuation cross-talk, the TM stiffness) off, the ratio; and the largest fraction
  of it that meets the requirement (:func:`scale_needed`: a bisection on log10; None when that value alone
  cannot close the gap);
* the loop-borne noise alone (every source but the TM force noise) over the requirement, largest in the band;
* the factor by which every loop-borne source together (all but the TM force noise) must fall for the
  total to meet the requirement, ``max_f sqrt(P_loop / (P_req - P_tm_force))`` (P the power ASD^2), over
  the frequencies where the floor leaves room (P_tm_force < P_req).

docs/closed-loop-validation.md (section 7) quotes these numbers for both presets of ``closed_loop.defaults``.
"""

from __future__ import annotations

import math

import numpy as np

from .budget import noise_budget
from .loop import output_names

__all__ = ["BAND_HZ", "requirement_verdict", "scale_needed"]

#: The band [Hz] of the verdict (the missions' measurement band, 0.1 mHz - 1 Hz).
BAND_HZ = (1e-4, 1.0)
_OUTPUTS = ("tm1_acceleration", "tm2_acceleration")


def _model(mission: str, defaults: str, plant: dict | None):
    from ..scenario.closed_loop import ClosedLoopConfig
    from .model import static_closed_loop_model

    raw = {"mission": mission, "defaults": defaults}
    if plant:
        raw["plant"] = dict(plant)
    return static_closed_loop_model(ClosedLoopConfig(raw=raw))


def _per_source(mission: str, defaults: str, f, plant=None):
    """(sources, P [source, f] the worse TM's power per source, the requirement's power, the TM force input's
    power) at frequencies ``f`` [Hz]."""
    from .missions import requirement

    model = _model(mission, defaults, plant)
    b, sources = noise_budget(model.loops[0][0][1], model.noise, f, outputs=list(_OUTPUTS))
    tot = np.sum(b ** 2, axis=1)                                   # (2, f)
    worse = np.argmax(tot, axis=0)
    P = b[worse, :, np.arange(len(f))].T ** 2                      # (source, f): the worse TM per frequency
    return list(sources), P, requirement(mission).asd(f) ** 2, model.noise["tm_force"].asd(f) ** 2


def requirement_verdict(mission: str, defaults: str = "published", n_freq: int = 300, band=BAND_HZ,
                        plant: dict | None = None) -> dict:
    """The verdict of ``mission``'s ``defaults`` preset (module docstring) on ``n_freq`` log-spaced frequencies
    in ``band`` [Hz]; ``plant``: [closed_loop.plant] values replacing the preset's (e.g. ``{"crosstalk": 0}``).
    Keys: ``max_ratio``, ``f_hz`` (its frequency), ``shares`` ({source: its fraction of the total power there,
    the sources above 1 %}), ``dominant``, ``floor_ratio`` and ``floor_f_hz`` (the TM force input over the
    requirement, largest in the band), ``loop_ratio`` and ``loop_ratio_f_hz`` (the loop-borne noise alone over
    the requirement, largest in the band), ``loop_reduction`` (module docstring; <= 1 when the loop-borne noise meets
    the requirement; -inf when the floor exceeds the requirement at every frequency) and ``loop_reduction_f_hz``
    (where it is set)."""
    f = np.logspace(math.log10(band[0]), math.log10(band[1]), n_freq)
    sources, P, R, A = _per_source(mission, defaults, f, plant)
    total = P.sum(axis=0)
    ratio = np.sqrt(total / R)
    k = int(np.argmax(ratio))
    floor = np.sqrt(A / R)
    j = int(np.argmax(floor))
    loop = total - P[sources.index("tm_force")]
    lr = np.sqrt(loop / R)
    q = int(np.argmax(lr))
    room = R - A
    fac = np.where(room > 0, np.sqrt(loop / np.where(room > 0, room, 1.0)), -np.inf)
    n = int(np.argmax(fac))
    shares = {s: float(P[i, k] / total[k]) for i, s in enumerate(sources) if P[i, k] / total[k] > 0.01}
    return {"mission": mission, "defaults": defaults, "max_ratio": float(ratio[k]), "f_hz": float(f[k]),
            "dominant": max(shares, key=shares.get), "shares": shares, "floor_ratio": float(floor[j]),
            "floor_f_hz": float(f[j]), "loop_ratio": float(lr[q]), "loop_ratio_f_hz": float(f[q]),
            "loop_reduction": float(fac[n]), "loop_reduction_f_hz": float(f[n])}


def scale_needed(mission: str, key: str, defaults: str = "published", plant: dict | None = None,
                 measure: str = "max_ratio", n_freq: int = 200, band=BAND_HZ) -> dict:
    """How far the plant value ``key`` ("crosstalk", "stiffness", ...) of ``mission``'s ``defaults`` preset must
    shrink for ``measure`` ("max_ratio": the total, or "loop_ratio": the loop-borne noise alone, of
    :func:`requirement_verdict`) to reach 1, the other plant values the preset's or ``plant``'s.  Keys:
    ``value`` (the preset's), ``ratio_without`` (``measure`` with ``key`` set to 0, at ``f_without_hz``, its largest
    source ``dominant_without``), ``scale_max`` (the largest factor s in [1e-9, 1] on ``value`` with ``measure``
    <= 1: a bisection on log10 s to 1 %; 1.0 when the preset already meets it, None when even 0 does not)."""
    from scipy.optimize import brentq

    from .missions import default_plant

    value = default_plant(mission, defaults)[key]

    def verdict(scale):
        v = np.asarray(value, dtype=float) * scale
        return requirement_verdict(mission, defaults, n_freq, band,
                                   {**(plant or {}), key: float(v) if v.ndim == 0 else v.tolist()})

    v0 = verdict(0.0)
    out = {"key": key, "value": value, "measure": measure, "ratio_without": v0[measure],
           "f_without_hz": v0["f_hz"] if measure == "max_ratio" else v0["loop_ratio_f_hz"],
           "dominant_without": v0["dominant"], "scale_max": None}
    if v0[measure] > 1.0:
        return out
    if verdict(1.0)[measure] <= 1.0:
        out["scale_max"] = 1.0
        return out
    lo = -9.0
    if verdict(10.0 ** lo)[measure] > 1.0:
        return out
    out["scale_max"] = 10.0 ** brentq(lambda x: verdict(10.0 ** x)[measure] - 1.0, lo, 0.0, xtol=0.004)
    return out
