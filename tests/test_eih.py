"""The first post-Newtonian n-body (Einstein-Infeld-Hoffmann) terms, ``forces.relativity_model = "eih"``:
the heliocentric term (tqdyn.forces.eih) and the geocentric one (tqdyn.forces.eih_gcrs), each against an
independent evaluation, their sizes, and short runs with them.

References (tests/eih_support.py; nothing there comes from tqdyn):

* the EIH equations in numpy (Standish & Williams, Explanatory Supplement ch. 8 eq. 8.1; Park et al. 2021,
  AJ 161, 105, eq. 1), checked in tests/test_heliocentric.py against Schwarzschild, its Lorentz boost and
  DE421's Mercury; bodies from DE421 read with jplephem, GMs from the GM file's decimals;
* the same equations transformed to the GCRS by brute force: the IAU 2000 B1.3 transformation applied to
  polynomial worldlines and differentiated numerically in mpmath (``gcrs_reference``);
* general relativity's tidal tensor of a mass seen by a moving observer: the Riemann tensor of the
  Schwarzschild metric in its static orthonormal frame (MTW eq. 31.4), boosted, with the harmonic radius
  r_h = r_s - GM/c^2 of the BCRS.
"""

from __future__ import annotations

import mpmath
import numpy as np
import pytest

from eih_support import C, EIH_BODIES, bary_states, eih_1pn, gcrs_reference, gm_f, newton
from tqdyn.astro.constants import C_LIGHT
from tqdyn.astro.ephemeris import BODIES, HELIOCENTRIC_BODIES
from tqdyn.astro.geocentric import TDB_TO_TT_SCALE, bcrs_to_gcrs
from tqdyn.astro.reference import GEOCENTRIC, HELIOCENTRIC
from tqdyn.astro.timescales import Epoch, tdb_jd
from tqdyn.dynamics import Rows, propagate
from tqdyn.forces.eih import HeliocentricEIH
from tqdyn.forces.eih_gcrs import GeocentricEIH, _fill_geocentric, geocentric_eih_accel
from tqdyn.forces.model import ForceModel, build_force_model, gravity
from tqdyn.numerics.dd import mp_from_dd
from tqdyn.scenario import ScenarioError, load_scenario, loads_scenario

AU = 149597870700.0


def _accel(term, reference, epoch, t, r, v):
    """The term through the compiled dispatcher (a one-term model), float64 [m/s^2]."""
    one = ForceModel([term], reference)
    tdat = one.precompute(epoch, np.array([t]), np.zeros(1))[0]
    return np.array(gravity(*r, *v, tdat, one.params, one.layout))


# ---------------------------------------------------------------------------------------------------------
# 1. heliocentric: EIH_1PN(spacecraft) - EIH_1PN(Sun)

@pytest.mark.parametrize("seed", [1, 2, 3, 4])
def test_heliocentric_term_against_numpy_eih(seed, record_number):
    """The heliocentric term at 5 random instants of 2035-2040 and states (0.7 .. 1.3 au, ~30 km/s, random
    directions) per seed against the numpy EIH of the ten bodies: EIH_1PN(particle at rho + x_sun, rhod +
    v_sun) - EIH_1PN(Sun), barycentric states from jplephem at the TDB date epoch + t.  Measured: the term
    0.7e-10 .. 4.8e-10 m/s^2, the difference <= 2.6e-25 m/s^2 (<= 9e-16 relative: float64 round-off of
    its ~1e-10 parts); bound 1e-24 m/s^2 and 5e-15 relative.  The Sun's terms are >= ~1e-15 m/s^2 each
    (its acceleration's, 0.5 d.a_S and 3.5 GM_S a_S / r, the smallest): a relative error of 1e-6 in any of
    them would show as >= 1e-21 m/s^2."""
    epoch = Epoch.from_tdb("2035-01-01T00:00:00")
    term = HeliocentricEIH(names=HELIOCENTRIC_BODIES)
    mu = np.array([gm_f(b) for b in EIH_BODIES])
    rng = np.random.default_rng(seed)
    errs, rels = [], []
    for _ in range(5):
        t = float(np.round(rng.uniform(0.0, 5 * 365.25) * 86400.0, 3))
        pos, vel = bary_states(EIH_BODIES, np.array([2464328.5 + np.floor(t / 86400.0)]),
                               np.array([(t % 86400.0) / 86400.0]))
        acc = newton(pos, mu)
        n = rng.normal(size=3)
        n /= np.linalg.norm(n)
        w = np.cross(n, rng.normal(size=3))
        w /= np.linalg.norm(w)
        rho, rhod = AU * rng.uniform(0.7, 1.3) * n, 29780.0 * w + 500.0 * rng.normal(size=3)
        ref = (eih_1pn((rho + pos[0, :, 0])[:, None], (rhod + vel[0, :, 0])[:, None], pos, vel, acc, mu)
               - eih_1pn(pos[0], vel[0], pos, vel, acc, mu, skip=0))[:, 0]
        got = _accel(term, HELIOCENTRIC, epoch, t, rho, rhod)
        err = np.linalg.norm(got - ref)
        print(f"t = {t:.0f} s: |a| = {np.linalg.norm(ref):.3e} m/s^2, |tqdyn - numpy| = {err:.1e} "
              f"({err / np.linalg.norm(ref):.1e})")
        assert err < 1e-24 and err < 5e-15 * np.linalg.norm(ref)
        errs.append(float(err))
        rels.append(float(err / np.linalg.norm(ref)))
    record_number(f"eih.helio_vs_numpy_abs.s{seed}", max(errs), "m/s^2")
    record_number(f"eih.helio_vs_numpy_rel.s{seed}", max(rels))


def test_heliocentric_option_replaces_schwarzschild():
    """relativity_model = "eih" puts the EIH term in the Schwarzschild term's place (never both);
    relativity = false switches either off; the default model is unchanged."""
    def names(relativity, model="iers2010"):
        scen = load_scenario("lisa-gravity", [f"forces.relativity={relativity}", f"forces.relativity_model={model}"])
        return {t.name for t in build_force_model(scen.forces, scen.reference).terms}

    rel = {"relativity", "relativity_eih"}
    assert names("true") & rel == {"relativity"} and names("true", "eih") & rel == {"relativity_eih"}
    assert not names("false", "eih") & rel and not names("false") & rel


def _double_integral(t, a):
    """|int_0^T int_0^t a dt' dt| [m] of samples a (m, 3) at times t (m,) (trapezoid rule twice)."""
    v = np.concatenate([np.zeros((1, 3)), np.cumsum(0.5 * (a[1:] + a[:-1]) * np.diff(t)[:, None], axis=0)])
    return np.linalg.norm(np.sum(0.5 * (v[1:] + v[:-1]) * np.diff(t)[:, None], axis=0))


def _runs(name, overrides):
    """{model: (final positions (n_sat, 3) [m], output rows, scenario)} of runs with relativity_model
    iers2010 and eih."""
    out = {}
    for model in ("iers2010", "eih"):
        rows = []
        scen = load_scenario(name, [*overrides, f"forces.relativity_model={model}"])
        res = propagate(scen, sink=rows.append)
        out[model] = (np.array([[float(x) for x in row] for row in mp_from_dd(res.y_final[:, 0:3])]), rows, scen)
    return out


def _term_along(rows, scen, scen_iers):
    """(t (m,), the relativity terms of ``scen`` minus those of ``scen_iers`` [m/s^2] (m, n_sat, 3)) along
    output rows."""
    iers = build_force_model(scen_iers.forces, scen.reference)
    eih = build_force_model(scen.forces, scen.reference)
    rows = Rows.concatenate(rows)
    t, pos, vel = rows.t[0] + rows.t[1], rows.sat_r[0] + rows.sat_r[1], rows.sat_v[0] + rows.sat_v[1]
    out = np.zeros_like(pos)
    for model, sign in ((eih, 1.0), (iers, -1.0)):
        for term in model.terms:
            if term.name.startswith("relativity"):
                one = ForceModel([term], scen.reference)
                tdat = one.precompute(scen.epoch, t, np.zeros_like(t))
                for i in range(t.size):
                    for s in range(pos.shape[1]):
                        out[i, s] += sign * np.array(gravity(*pos[i, s], *vel[i, s], tdat[i], one.params, one.layout))
    return t, out


def test_lisa_ten_days_moves_by_the_double_integral(record_number):
    """`lisa-gravity` (ESA's start, 2036-12-09; the Sun, Earth, Moon and planets) for 10 days at 6 h with
    relativity on: eih against iers2010.  The positions differ by the double time integral of the term's
    difference, EIH - Schwarzschild (1.9e-14 .. 2.3e-14 m/s^2 here), along the run: 8.0e-3 .. 8.2e-3 m
    (measured: within 0.6 % of it -- over 10 days the orbit's own gravity gradient, (n t)^2 = 0.03, barely
    acts); bounds: within 3 % of the double integral, and below max |da| t^2 / 2 (8.4e-3 .. 8.6e-3 m)."""
    runs = _runs("lisa-gravity", ["forces.relativity=true", "run.duration=10d"])
    (r0, _, scen0), (r1, rows, scen) = runs["iers2010"], runs["eih"]
    t, da = _term_along(rows, scen, scen0)
    size = np.linalg.norm(da, axis=-1)
    record_number("eih.lisa_10d_term", [size.min(), size.max()], "m/s^2")
    for s in range(3):
        moved = np.linalg.norm(r1[s] - r0[s])
        expect = _double_integral(t, da[:, s])
        record_number(f"eih.lisa_10d_moved.LISA{s + 1}", moved, "m")
        record_number(f"eih.lisa_10d_rel.LISA{s + 1}", abs(moved / expect - 1), "|moved / double integral - 1|")
        print(f"LISA{s + 1}: |da| {size[:, s].min():.2e} .. {size[:, s].max():.2e} m/s^2, moved {moved:.4e} m, "
              f"double integral {expect:.4e} m, max |da| t^2/2 = {size[:, s].max() * t[-1] ** 2 / 2:.3e} m")
        assert abs(moved / expect - 1) < 0.03
        assert moved < size[:, s].max() * t[-1] ** 2 / 2


# ---------------------------------------------------------------------------------------------------------
# 2. geocentric: the EIH equations transformed to the GCRS, minus what the model has

@pytest.mark.parametrize("iso, days", [("2004-06-06T00:00:00", (0.0, 11.3, 23.7)),
                                       ("2035-03-01T00:00:00", (0.0, 40.2))])
def test_gcrs_term_against_the_transformed_eih(iso, days, record_number):
    """The GCRS term (the model's dispatcher, all nine third bodies) against ``gcrs_reference`` -- the EIH
    equations of the satellite, the Earth and the bodies transformed to the GCRS and differentiated
    numerically in mpmath, minus the Newtonian third bodies at their GCRS positions, Schwarzschild and de
    Sitter -- at TianQin-like states (1e5 km, 2 km/s, random directions, a radial velocity).  Measured:
    the term 4.0e-14 .. 1.8e-13 m/s^2, the difference 3.5e-17 .. 5.1e-17 m/s^2 (2e-4 .. 1.3e-3 of it): the
    O(c^-4) terms the 1PN transformation leaves undetermined (e.g. 3 b S^2/c^4 = 3 (GM_E/r^2)
    (v_E^2/2 + U_sun)^2/c^4 = 2.5e-17 m/s^2), which the reference keeps and the term drops; bound 2e-16
    m/s^2.  The term's smallest parts the bound still tests: W0'' r/c^2 = 6.6e-16, the Moon's terms
    (<= 1e-14)."""
    epoch = Epoch.from_utc(iso)
    term = GeocentricEIH(names=BODIES)
    rng = np.random.default_rng(len(days))
    sizes, errs = [], []
    for d in days:
        t = d * 86400.0
        j1, j2 = tdb_jd(epoch, t)
        n = rng.normal(size=3)
        n /= np.linalg.norm(n)
        w = np.cross(n, rng.normal(size=3))
        w /= np.linalg.norm(w)
        with mpmath.workdps(40):
            ref, x0, v0 = gcrs_reference(float(j1), float(j2), 1e8 * n, 1996.0 * w + 100.0 * n,
                                         term.gm_earth / TDB_TO_TT_SCALE)
        got = _accel(term, GEOCENTRIC, epoch, t, x0 * TDB_TO_TT_SCALE, v0)
        err = np.linalg.norm(got - ref)
        print(f"{iso} + {d} d: |a| = {np.linalg.norm(ref):.3e} m/s^2, |tqdyn - reference| = {err:.1e} m/s^2")
        assert err < 2e-16
        assert np.linalg.norm(ref) > 1e-14  # the term is there
        sizes.append(float(np.linalg.norm(ref)))
        errs.append(float(err))
    record_number(f"eih.gcrs_vs_transformed_size.{iso[:10]}", sizes, "m/s^2")
    record_number(f"eih.gcrs_vs_transformed_diff.{iso[:10]}", errs, "m/s^2")


@pytest.mark.parametrize("speed_factor", [1.0, 2.0])
def test_gcrs_term_is_the_tidal_tensor_of_general_relativity(speed_factor, record_number):
    """The Sun alone, at rest, a massless Earth at R = 1 au moving at v perpendicular to the Sun's direction n
    (circular speed, and twice it), a satellite at rest at +-h e (h = 1e8 m) along n, v and their normal.
    The Riemann tensor of the Schwarzschild field in the frame moving at v (boosted from the static frame,
    MTW eq. 31.4) gives the tidal acceleration GM/r_s^3 diag(2 + 3 b^2, -1, -(1 + 3 b^2)) h, b = v/c, with
    the areal r_s = R + GM/c^2 (R harmonic, the BCRS): GM/R^3 [2 - 6 U + 3 b^2, -(1 - 3 U), -(1 - 3 U +
    3 b^2)], U = GM/(c^2 R).  The model's Newtonian tide of the Sun at its GCRS position (moved out by
    3/2 U) gives GM/R^3 (1 - 9/2 U) diag(2, -1, -1); the term must be the difference, GM/R^3 h [3 U + 3 b^2,
    -3/2 U, -3/2 U - 3 b^2] (2.3e-13 m/s^2 along n on a circular orbit).  Odd part in h (the octupole
    cancels).  Measured: 1.8e-7 .. 7.6e-7 relative (the hexadecapole's (h/R)^2 = 4.5e-7 and O(c^-4));
    bound 3e-6."""
    gm, big_r = 1.32712440041939e20, AU
    n, ev, ez = np.array([0.6, 0.8, 0.0]), np.array([-0.8, 0.6, 0.0]), np.array([0.0, 0.0, 1.0])
    v = speed_factor * np.sqrt(gm / big_r)
    pos = np.array([[big_r * n, 3.8e8 * ez]])    # the Sun and a massless Moon, from the Earth
    vel = np.array([[-v * ev, -v * ev]])          # relative velocities: the Sun at rest, the Earth at v ev
    mu = np.array([0.0, gm, 0.0])                 # Earth, Sun, Moon
    delta = bcrs_to_gcrs(pos, vel, np.array([v * ev]), mu[1:]) / TDB_TO_TT_SCALE - pos
    tdat = np.empty((1, 10 * 3 + 3 * 2 + 8))
    _fill_geocentric(pos, vel, np.array([v * ev]), delta, mu, C_LIGHT, tdat)
    params = np.concatenate([[TDB_TO_TT_SCALE, C_LIGHT, 0.0, 2, 0], mu])
    u, b2, h = gm / (C**2 * big_r), v**2 / C**2, 1e8
    rels = []
    for e, coef in ((n, 3 * u + 3 * b2), (ev, -1.5 * u), (ez, -1.5 * u - 3 * b2)):
        plus = np.array(geocentric_eih_accel(*(h * e * TDB_TO_TT_SCALE), 0.0, 0.0, 0.0, tdat[0], params))
        minus = np.array(geocentric_eih_accel(*(-h * e * TDB_TO_TT_SCALE), 0.0, 0.0, 0.0, tdat[0], params))
        got, want = (plus - minus) / 2, coef * gm / big_r**3 * h * e
        rel = np.linalg.norm(got - want) / np.linalg.norm(want)
        print(f"v = {speed_factor} v_circ, along {e}: {np.linalg.norm(got):.4e} m/s^2 vs GR {np.linalg.norm(want):.4e} "
              f"({rel:.1e})")
        assert rel < 3e-6
        rels.append(float(rel))
    record_number(f"eih.gcrs_tidal_tensor_rel.v{speed_factor:g}", rels)


def test_gcrs_term_size_at_tianqin(record_number):
    """Size of the 1PN n-body terms beyond eq. 10.12 on TianQin's orbits (the brief of the term: a 1PN term
    above 1e-15 m/s^2 at 1e5 km belongs in the model): the three satellites of `tianqin-gravity` over one
    orbit (3.65 d from 2004-06-06), 3 h samples on their Kepler orbits, all nine bodies: 1.39e-13 ..
    1.81e-13 m/s^2 (measured).  The Moon's share (``gcrs_reference`` with only the Earth and the Moon, at 4
    of Sat1's states): 2.4e-15 .. 1.6e-14 m/s^2; the planets' (Mercury .. Neptune, at 2 states) 8e-17 .. 1e-16;
    the rest is the Sun's.  Bounds: 5e-14 .. 5e-13 overall, the Moon 5e-16 .. 5e-14 (both above the 1e-15
    m/s^2 of the brief), the planets below 1e-15."""
    scen = load_scenario("tianqin-gravity", ["forces.relativity_model=eih", "run.duration=1d"])
    model = build_force_model(scen.forces, scen.reference)
    (term,) = [t for t in model.terms if t.name == "relativity_eih_gcrs"]
    from tqdyn.dynamics.initial import satellite_states

    gm = float(scen.forces.gm_earth)
    planets = [EIH_BODIES.index(b) for b in ("mercury", "venus", "mars", "jupiter", "saturn", "uranus", "neptune")]
    sizes, moon, others = [], [], []
    for s, (r0, v0) in enumerate(satellite_states(scen)):
        for k, t in enumerate(np.arange(0.0, 3.65 * 86400.0, 3 * 3600.0)):
            r, v = _kepler(np.array([float(x) for x in r0]), np.array([float(x) for x in v0]), gm, t)
            a = _accel(term, GEOCENTRIC, scen.epoch, t, r, v)
            sizes.append(np.linalg.norm(a))
            if s == 0 and k % 8 == 0:
                j1, j2 = tdb_jd(scen.epoch, t)
                with mpmath.workdps(40):
                    for sources, out in (([EIH_BODIES.index("moon")], moon), (planets, others)):
                        if out is moon or k % 16 == 0:
                            m, _, _ = gcrs_reference(float(j1), float(j2), r / TDB_TO_TT_SCALE, v,
                                                     gm / TDB_TO_TT_SCALE, sources=sources)
                            out.append(np.linalg.norm(m))
    print(f"TianQin, one orbit: |a| {min(sizes):.2e} .. {max(sizes):.2e} m/s^2; the Moon's part "
          f"{min(moon):.2e} .. {max(moon):.2e}, the planets' {min(others):.2e} .. {max(others):.2e} m/s^2")
    record_number("eih.gcrs_size_tianqin", {"all": [min(sizes), max(sizes)], "moon": [min(moon), max(moon)],
                                            "planets": [min(others), max(others)]}, "m/s^2")
    assert 5e-14 < min(sizes) and max(sizes) < 5e-13
    assert 5e-16 < min(moon) and max(moon) < 5e-14
    assert max(others) < 1e-15


def _kepler(r0, v0, gm, t):
    """Two-body state [m, m/s] at t [s] from r0, v0 (scipy's DOP853; the term's size needs no more)."""
    from scipy.integrate import solve_ivp

    if t == 0.0:
        return np.asarray(r0, float), np.asarray(v0, float)
    sol = solve_ivp(lambda _, y: np.concatenate([y[3:], -gm * y[:3] / np.linalg.norm(y[:3]) ** 3]), (0.0, t),
                    np.concatenate([r0, v0]), method="DOP853", rtol=1e-12, atol=1e-6)
    return sol.y[:3, -1], sol.y[3:, -1]


def test_tianqin_two_hours_move_by_the_double_integral(record_number):
    """`tianqin-gravity` for two hours (50 s steps) with relativity_model = "eih" against "iers2010": each
    satellite moves by the double time integral of the term along the run (1.5e-13 .. 1.7e-13 m/s^2 here),
    3.9e-6 .. 4.4e-6 m (measured: within 0.15 % of it; two hours are 0.023 orbits, (n t)^2 = 0.02: the orbit's gravity
    gradient barely acts -- over a whole day, 0.27 orbits, it does, and the satellites move 0.44 .. 0.82 mm,
    up to 1.45x the double integral); bounds: within 5 % of the double integral, below 1.05 max |da| t^2/2."""
    runs = _runs("tianqin-gravity", ["run.duration=2h", "run.output_every=6"])
    (r0, _, scen0), (r1, rows, scen) = runs["iers2010"], runs["eih"]
    t, da = _term_along(rows, scen, scen0)
    size = np.linalg.norm(da, axis=-1)
    for s in range(3):
        moved = np.linalg.norm(r1[s] - r0[s])
        expect = _double_integral(t, da[:, s])
        record_number(f"eih.tianqin_2h_moved.Sat{s + 1}", moved, "m")
        record_number(f"eih.tianqin_2h_rel.Sat{s + 1}", abs(moved / expect - 1), "|moved / double integral - 1|")
        print(f"Sat{s + 1}: |da| {size[:, s].min():.2e} .. {size[:, s].max():.2e} m/s^2, moved {moved:.4e} m, "
              f"double integral {expect:.4e} m, max |da| t^2/2 = {size[:, s].max() * t[-1] ** 2 / 2:.3e} m")
        assert abs(moved / expect - 1) < 0.05
        assert moved < 1.05 * size[:, s].max() * t[-1] ** 2 / 2


# ---------------------------------------------------------------------------------------------------------
# 3. the scenario key

def test_relativity_model_key():
    """forces.relativity_model: "iers2010" (default, left out of the resolved TOML, so files of the default
    model keep their text) | "eih" (written); a bad value or a geocentric "eih" without the Sun and the Moon
    in the GCRS is one ScenarioError naming the key."""
    scen = load_scenario("tianqin-gravity", ["forces.relativity_model=eih"])
    assert scen.forces.relativity_model == "eih" and 'relativity_model = "eih"' in scen.to_toml()
    assert loads_scenario(scen.to_toml()) == scen
    assert "relativity_model" not in load_scenario("tianqin-gravity").to_toml()
    for bad, words in ((["forces.relativity_model=eih2"], "is not a valid choice"),
                       (["forces.relativity_model=eih", 'forces.third_bodies=["sun"]'], "lacks ['moon']"),
                       (["forces.relativity_model=eih", "forces.third_bodies_gcrs=false"], "third_bodies_gcrs")):
        with pytest.raises(ScenarioError) as info:
            load_scenario("tianqin-gravity", bad)
        msg = str(info.value)
        assert "forces.relativity_model" in msg and words in msg and "\n" not in msg, msg
    # relativity = false: the key asks for nothing
    off = load_scenario("tianqin-gravity", ["forces.relativity=false", "forces.relativity_model=eih",
                                            'forces.third_bodies=["sun"]'])
    assert not [t for t in build_force_model(off.forces, off.reference).terms if t.name.startswith("relativity")]
