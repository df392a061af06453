"""The heliocentric propagation against the exact two-body solution: the
built-in ``lisa-kepler`` scenario (LISA's equal-arm Keplerian design under
the Sun's point mass, GM of DE430) over one year.

Reference: each satellite's initial dd state, converted exactly to mpmath,
turned into osculating elements and propagated analytically with
:func:`tqdyn.astro.elements.kepler_state_at` (Kepler's equation solved by
Newton in mpmath at 50 digits) -- the exact solution of the Sun-only
problem, so the difference is the total numerical error of the run.
"""

from __future__ import annotations

import mpmath
import numpy as np
import pytest

from tqdyn import dynamics as prop
from tqdyn.astro import elements as el
from tqdyn.astro.reference import HELIOCENTRIC
from tqdyn.dynamics.initial import central_gm, initial_state
from tqdyn.numerics import dd as P
from tqdyn.scenario import load_scenario

YEAR_S = 365 * 86400


def _final_errors(scen, precision):
    """|r_final - r_kepler| [m] per satellite after the run, and the result."""
    y0 = initial_state(scen)
    result = prop.propagate(scen, precision=precision)
    gm = central_gm(scen)
    errs = []
    with mpmath.workdps(50):
        t = el.from_dd(*result.t_final)
        for b in range(len(scen.satellites)):
            r0 = P.mp_from_dd(y0[b, 0:3])
            v0 = P.mp_from_dd(y0[b, 3:6])
            k = el.state_to_elements(list(r0), list(v0), gm)
            r_ref, _ = el.kepler_state_at(k["a"], k["e"], k["i"], k["raan"], k["argp"], k["nu"], gm, t)
            r = P.mp_from_dd(result.y_final[b, 0:3])
            errs.append(float(mpmath.sqrt(sum((mpmath.mpf(x) - y) ** 2 for x, y in zip(r, r_ref)))))
    return np.array(errs), result


def test_lisa_kepler_one_year_vs_two_body():
    """Issue acceptance: one year, dd error < 1e-6 m, float64 visibly worse (values in docs/precision.md)."""
    scen = load_scenario("lisa-kepler")
    assert scen.reference is HELIOCENTRIC and float(scen.run.duration_s) == YEAR_S
    assert float(scen.integrator.step_s) == 21600.0
    dd, res = _final_errors(scen, "dd")
    f64, _ = _final_errors(scen, "float64")
    print(f"\n[lisa-kepler] 1 year, 6 h steps: dd {dd} m, float64 {f64} m; energy drift {res.energy_rel_drift}")
    # measured (6 h steps, 1460 steps): dd 1.3e-14 .. 2.6e-14 m (the issue asks < 1e-6 m), float64
    # 1.8e-5 .. 1.6e-4 m (round-off of a 1.5e11 m state, ulp 3e-5 m); bounds ~4x either side
    assert 3e-15 < dd.max() < 1e-13
    assert 4e-6 < f64.min() and f64.max() < 7e-4
    # energy: the relative drift of the two-body energy, measured -1.45e-26
    assert np.all(np.abs(res.energy_rel_drift) < 6e-26)
