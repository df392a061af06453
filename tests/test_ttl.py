"""Tilt-to-length coupling of the six links (tqdyn.ttl.coupling).

References: (a) the analytic sine (a linear TTL of a sinusoidal jitter is the coefficient times the
sine, delayed by tau for the distant term); (b), (c) LISA Instrument 2.3's own formulas
(``instru/instru_formulas.py`` ``local_ttls``, ``distant_ttls``, ``mosa_total_jitter_phis``,
``mosa_total_jitter_etas``), its defaults (``instru/instru_defaults.py``), its MOSA enum and its
order-7 Lagrange delay (``sigpro/dynamic_delay_numpy.py``), run on the same inputs.
"""

from __future__ import annotations

import inspect
import math

import numpy as np
import pytest

from tqdyn.ttl import coupling as ttl

DT = 0.25  # s, LISA Instrument's default physics step
N = 2000
T = np.arange(N) * DT
TAU = {"12": 8.33242295, "23": 8.30282196, "31": 8.33242298, "13": 8.33159404, "32": 8.30446786, "21": 8.33159402}
"""Light travel times (s): LISA Instrument 2.3's STATIC_PPRS_S."""


def _sines(freq=5e-3, amp=1e-8):
    """phi, eta of each MOSA: amp sin(2 pi f_m t + p_m), frequencies and phases distinct per MOSA."""
    phi = {m: lambda t, k=k: amp * np.sin(2 * np.pi * freq * (1 + 0.1 * k) * t + 0.3 * k) for k, m in enumerate(ttl.MOSAS)}
    eta = {m: lambda t, k=k: 0.7 * amp * np.sin(2 * np.pi * freq * (1.3 + 0.1 * k) * t - 0.2 * k) for k, m in enumerate(ttl.MOSAS)}
    return phi, eta


def test_sinusoidal_jitter_gives_coefficient_times_angle():
    """Acceptance: local = c phi(t) + c eta(t), distant = c phi_ji(t - tau) + ..., against the analytic
    sine, for a constant and a time-varying tau.  The interpolation error (2 pi f dt)^8/8! is ~ 1e-21
    of the amplitude at f <= 1e-2 Hz; what remains is the round-off of the sines' phases
    (ulp(2 pi f t) ~ 1e-15 rad at t = 500 s).  Measured: local 0, distant 3.6e-15 of c A; bounds
    2e-15 and 2e-14."""
    phi_f, eta_f = _sines()
    coeffs = ttl.TTLCoefficients.random(seed=7)
    phi = {m: f(T) for m, f in phi_f.items()}
    eta = {m: f(T) for m, f in eta_f.items()}
    scale = 1e-8 * 2.4e-3
    for delays in (TAU, {m: TAU[m] + 1e-3 * np.sin(2 * np.pi * T / 300.0) for m in ttl.MOSAS}):
        local, distant = ttl.ttl_terms(phi, eta, coeffs, DT, delays)
        total = ttl.link_ttl(phi, eta, coeffs, DT, delays)
        for m in ttl.MOSAS:
            e = ttl.distant_mosa(m)
            ref_local = coeffs.local_phi[m] * phi_f[m](T) + coeffs.local_eta[m] * eta_f[m](T)
            te = T - delays[m]
            ref_distant = coeffs.distant_phi[e] * phi_f[e](te) + coeffs.distant_eta[e] * eta_f[e](te)
            assert np.max(np.abs(local[m] - ref_local)) < 2e-15 * scale
            ok = np.isfinite(distant[m])
            first = int(np.argmax(ok))
            assert ok[first:].all() and first <= math.ceil(np.max(delays[m]) / DT) + 4
            assert np.max(np.abs(distant[m][ok] - ref_distant[ok])) < 2e-14 * scale
            assert np.array_equal(total[m][ok], (local[m] + distant[m])[ok])


def test_quadratic_terms():
    """The quadratic part alone gives q phi^2 + q eta^2 + q phi eta (analytic, local and emitted
    terms; measured <= 3.8e-16 of max|ref|, bound 2e-15); the linear part adds to it."""
    phi_f, eta_f = _sines()
    phi = {m: f(T) for m, f in phi_f.items()}
    eta = {m: f(T) for m, f in eta_f.items()}
    zero = {m: 0.0 for m in ttl.MOSAS}
    q = {m: 5.0 for m in ttl.MOSAS}
    quad = ttl.TTLCoefficients(zero, zero, zero, zero, local_phiphi=q, local_etaeta=q, local_phieta=q,
                               distant_phiphi=q, distant_etaeta=q, distant_phieta=q)
    for kind in ("local", "distant"):
        for m in ttl.MOSAS:
            ref = 5.0 * (phi[m] ** 2 + eta[m] ** 2 + phi[m] * eta[m])
            got = quad.polynomial(kind, m, phi[m], eta[m])
            assert np.max(np.abs(got - ref)) < 2e-15 * np.max(np.abs(ref))
    both = ttl.TTLCoefficients({m: 1e-3 for m in ttl.MOSAS}, zero, zero, zero, local_phiphi=q)
    got = both.polynomial("local", "12", phi["12"], eta["12"])
    assert np.max(np.abs(got - (1e-3 * phi["12"] + 5.0 * phi["12"] ** 2))) < 1e-15 * 1e-3 * 1e-8


def _li():
    pytest.importorskip("lisainstrument")
    from lisainstrument.instru import instru_defaults, instru_formulas
    from lisainstrument.streams.expression import StreamConst
    return instru_formulas, instru_defaults, StreamConst


def test_against_lisa_instrument_ttl_and_delay():
    """LISA Instrument 2.3's local_ttls and distant_ttls (on random-walk angles and its default
    coefficients), the distant one delayed by its order-7 Lagrange dynamic shift: equal to round-off
    (measured: local 0, distant 7e-16 of max|s|; bound 3e-15)."""
    F, D, SC = _li()
    from lisainstrument.sigpro.dynamic_delay_numpy import ShiftBC, make_dynamic_shift_lagrange_numpy
    rng = np.random.default_rng(3)
    phi = {m: 1e-8 * np.cumsum(rng.standard_normal(N)) / 30 for m in ttl.MOSAS}
    eta = {m: 1e-8 * np.cumsum(rng.standard_normal(N)) / 30 for m in ttl.MOSAS}
    li = {k: {m.value: v for m, v in getattr(D, f"TTL_COEFFS_{k}").items()}
          for k in ("LOCAL_PHIS", "LOCAL_ETAS", "DISTANT_PHIS", "DISTANT_ETAS")}
    coeffs = ttl.TTLCoefficients(local_phi=li["LOCAL_PHIS"], local_eta=li["LOCAL_ETAS"],
                                 distant_phi=li["DISTANT_PHIS"], distant_eta=li["DISTANT_ETAS"])
    wrap = lambda d: {m: SC(np.asarray(v, dtype=float)) for m, v in d.items()}  # noqa: E731
    ref_local = F.local_ttls(wrap(phi), wrap(eta), wrap(li["LOCAL_PHIS"]), wrap(li["LOCAL_ETAS"]))
    ref_emit = F.distant_ttls(wrap(phi), wrap(eta), wrap(li["DISTANT_PHIS"]), wrap(li["DISTANT_ETAS"]))
    delays = {m: TAU[m] + 2e-3 * np.sin(2 * np.pi * T / 200.0) for m in ttl.MOSAS}
    local, distant = ttl.ttl_terms(phi, eta, coeffs, DT, delays)
    for m in ttl.MOSAS:
        shift = make_dynamic_shift_lagrange_numpy(7, 30.0, 40.0, ShiftBC.FLAT, ShiftBC.FLAT)
        ref_distant = shift(ref_emit[ttl.distant_mosa(m)].const, -delays[m] / DT)
        scale = np.max(np.abs(ref_local[m].const))
        assert np.max(np.abs(local[m] - ref_local[m].const)) < 3e-15 * scale
        ok = np.isfinite(distant[m])
        assert ok.sum() > N - 50
        scale = np.max(np.abs(ref_distant))
        assert np.max(np.abs(distant[m][ok] - ref_distant[ok])) < 3e-15 * scale


def test_mosa_angles_and_conventions_match_lisa_instrument():
    """phi/eta of the MOSAs vs LISA Instrument's mosa_total_jitter_phis/etas (its default opening
    angles, in deg): equal to round-off (bound 1e-23 rad on 1e-8 rad angles); the MOSA order, emitter, host spacecraft, default opening
    angles and random-coefficient ranges are LISA Instrument's."""
    F, D, SC = _li()
    from lisainstrument.orbiting.constellation_enums import MosaID
    rng = np.random.default_rng(5)
    sc = {k: {s: rng.standard_normal(50) * 1e-8 for s in ttl.SPACECRAFT} for k in ("phi", "eta", "theta")}
    mo = {k: {m: rng.standard_normal(50) * 1e-8 for m in ttl.MOSAS} for k in ("phi", "eta")}
    phi, eta = ttl.mosa_angles(sc["phi"], sc["eta"], sc["theta"], mo["phi"], mo["eta"])
    for m in ttl.MOSAS:
        s = m[0]
        rp = F.mosa_total_jitter_phis(SC(sc["phi"][s]), SC(mo["phi"][m])).const
        re = F.mosa_total_jitter_etas(SC(sc["eta"][s]), SC(sc["theta"][s]), SC(mo["eta"][m]),
                                      mosa_angles=D.MOSA_ANGLES[m]).const
        assert np.max(np.abs(phi[m] - rp)) < 1e-23 and np.max(np.abs(eta[m] - re)) < 1e-23
        assert ttl.MOSA_OPENING_ANGLES_RAD[m] == pytest.approx(D.MOSA_ANGLES[m] * np.pi / 180, rel=1e-15)
        mid = MosaID(m)
        assert mid.distant.value == ttl.distant_mosa(m) and mid.sat.value == m[0]
    assert set(ttl.MOSAS) == MosaID.names()
    for kind in ("local", "distant"):
        for ang in ("phis", "etas"):
            sig = inspect.signature(getattr(D, f"random_ttl_coeffs_{kind}_{ang}"))
            assert sig.parameters["high"].default == ttl.RANDOM_HALF_WIDTH_M_PER_RAD[kind]
            assert sig.parameters["low"].default == -ttl.RANDOM_HALF_WIDTH_M_PER_RAD[kind]


def test_random_coefficients_seeded_and_in_range():
    """Same seed, same draw; different seed, different; every value inside [-w, w)."""
    a, b, c = ttl.TTLCoefficients.random(1), ttl.TTLCoefficients.random(1), ttl.TTLCoefficients.random(2)
    assert a == b and a != c
    for name, w in (("local_phi", 2.2e-3), ("local_eta", 2.2e-3), ("distant_phi", 2.4e-3), ("distant_eta", 2.4e-3)):
        assert all(-w <= v < w for v in getattr(a, name).values())
    assert all(v == 0.0 for v in a.local_phiphi.values())


@pytest.mark.parametrize("make, match", [
    (lambda: ttl.TTLCoefficients.constant(1e-3, 1e-3, 1e-3, float("nan")), r"ttl\.distant_eta\['12'\] = nan: must be a finite"),
    (lambda: ttl.TTLCoefficients({**{m: 0.0 for m in ttl.MOSAS}, "14": 1.0}, *({m: 0.0 for m in ttl.MOSAS},) * 3),
     r"ttl\.local_phi: '14' is not a key; allowed: 12, 23, 31, 13, 32, 21"),
    (lambda: ttl.TTLCoefficients({"12": 0.0}, *({m: 0.0 for m in ttl.MOSAS},) * 3), r"ttl\.local_phi: missing key '23'"),
    (lambda: ttl.TTLCoefficients.random(0, local_half_width=float("inf")), r"ttl\.local_half_width = inf"),
    (lambda: ttl.mosa_angles(*({s: 0.0 for s in "123"},) * 3, {m: 0.0 for m in ttl.MOSAS}, {m: 0.0 for m in ttl.MOSAS},
                             opening_rad={**ttl.MOSA_OPENING_ANGLES_RAD, "12": float("nan")}), r"mosa_opening_rad\['12'\] = nan"),
    (lambda: ttl.link_ttl(*({m: np.zeros(40) for m in ttl.MOSAS},) * 2, ttl.TTLCoefficients.constant(0, 0, 0, 0), DT,
                          {**TAU, "21": -1.0}), r"delays\['21'\] = -1.0: must be a finite number >= 0"),
    (lambda: ttl.link_ttl(*({m: np.zeros(40) for m in ttl.MOSAS},) * 2, ttl.TTLCoefficients.constant(0, 0, 0, 0), 0.0, TAU),
     r"dt = 0.0: must be > 0"),
])
def test_refusals(make, match):
    """Bad input: one ValueError line naming the field, the value and what is allowed."""
    with pytest.raises(ValueError, match=match) as e:
        make()
    assert "\n" not in str(e.value)
