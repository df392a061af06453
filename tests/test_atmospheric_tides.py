"""Tests of tqdyn.forces.atmospheric_tides (not modelled; estimate only).

Reference: the estimate's own closed form, 3 * (sqrt(15)/2) * GM/r^2 *
(R/r)^2 * dC22 with dC22 = 3 (1 + k'_2) (p0 / (sqrt(15)/2) / g) /
(rho_E R 5) (derivation in the module docstring; numbers typed in here).
"""

from __future__ import annotations

import math

import pytest

from tqdyn.forces import atmospheric_tides as at


def test_flag_and_description():
    assert at.NOT_MODELLED is True
    assert "NOT modelled" in at.DESCRIPTION
    assert at.NAME == "atmospheric_tides"


def test_estimate_values():
    p22 = 120.0 / (math.sqrt(15.0) / 2.0)                    # Pa
    dc22 = 3.0 * (1.0 - 0.3075) * (p22 / 9.80665) / (5517.0 * 6378136.3 * 5.0)
    assert at.estimated_dc22() == pytest.approx(dc22, rel=1e-12)
    assert 1e-11 < dc22 < 1e-10                              # published S2 range 1e-11 .. 1e-10
    a = at.estimate_accel(1e8)
    ref = 3.0 * math.sqrt(15.0) / 2.0 * 3.986004415e14 / 1e16 * (6378136.3 / 1e8) ** 2 * dc22
    assert a == pytest.approx(ref, rel=1e-12)
    print(f"\natmospheric S2 tide (not modelled): dC22 ~ {dc22:.2e}, acceleration at r = 1e8 m ~ {a:.2e} m/s^2")
    # README (force model, budget): ~7e-14 m/s^2 at 1e5 km; measured 7.03e-14 m/s^2, ~3x either side
    assert 2e-14 < a < 2e-13
    # r^-4 scaling
    assert at.estimate_accel(2e8) == pytest.approx(a / 16.0, rel=1e-12)


def test_bad_distance():
    with pytest.raises(ValueError, match="must be positive"):
        at.estimate_accel(0.0)
