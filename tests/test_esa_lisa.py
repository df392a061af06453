"""tqdyn's ``lisa`` scenario against ESA's LISA orbit files (the issue's acceptance "ESA reproduction").

Reference: ESA's CReMA 2.0 trailing orbits shipped in tqdyn/data/esa-lisa-orbits (esa/lisa-orbit-files,
commit bf87d55; data/SOURCES.md), read by tqdyn.readers.oem and interpolated as the files say (Hermite 7,
tqdyn.astro.oem_states.states_at).  The scenario starts from their first record (2036-12-09 TDB) with ESA's force model
(Newtonian Sun, Earth, Moon, planetary barycentres; DE421 positions, DE430 GMs) and ESA's self-gravity,
``spacecraft.self_gravity_center = [-2e-9, 2e-9]`` (m/s^2 toward the centroid, linear over the files' span).
ESA integrated with tolerances 1e-9: its files are not exact, and their velocities are rounded to 0.1 mm/s.

Also used: the first record of ESA's ``crema_2p0/tcb_time_scale/mida-20deg/*_no_ovrs.oem`` (the same
integration, 18 digits; ``FULL_DIGIT_STATES_KM`` of tools/make_esa_figure.py, copied here) to separate
the rounding of the shipped files' initial velocities from ESA's integration error.

Measured on the 6 h grid (docs/lisa-orbits.md, tools/make_esa_figure.py prints them all); bounds 3-10x
above, stated with each test.  The whole 10.7-year run takes ~1 s after compilation, so everything here
runs in the default (fast) selection; the module takes ~20 s.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from tqdyn import dynamics
from tqdyn.analysis.metrics import breathing_angles_of
from tqdyn.astro.oem_states import frame_bias_matrix, states_at, to_heliocentric
from tqdyn.constellation import geometry
from tqdyn.forces.heliocentric import SunMonopole
from tqdyn.forces.model import ForceModel, build_force_model
from tqdyn.formats.trajectory import read_trajectory
from tqdyn.readers.oem import esa_lisa_orbit_files, read_oem
from tqdyn.scenario import load_scenario
from tqdyn.workflows.run import run_to_file

SPAN = "3926.5d"      # the files' span 2036-12-09 .. 2047-09-09 13:04:48 TDB, rounded down to whole 6 h steps
DAY = 86400.0
YEAR_D = 365.25

#: First record of ESA's ``..._lisa{1,2,3}_no_ovrs.oem`` (esa/lisa-orbit-files bf87d55, CReMA 2.0, TCB tags,
#: 2036-12-09T00:00:29.327664 TCB = the shipped files' first epoch): x, y, z [km], vx, vy, vz [km/s], file axes.
FULL_DIGIT_STATES_KM = (
    (8.08311557664805502e+07, 1.15255425723354399e+08, 4.94105228485148698e+07,
     -2.51637278817780619e+01, 1.48287454955632700e+01, 6.18146157564898768e+00),
    (8.01922636498114616e+07, 1.16032337930129766e+08, 5.16547231621972769e+07,
     -2.50664489842165636e+01, 1.45255916879309019e+01, 6.32231614430957833e+00),
    (7.86891623803241253e+07, 1.16462661725208640e+08, 4.96982251360123381e+07,
     -2.53128928308957128e+01, 1.44803090497150997e+01, 6.49795774073929078e+00),
)


def _esa(file_axes_icrf=False):
    """ESA's three files, heliocentric; ``file_axes_icrf``: their EME2000 axes taken as ICRF (no frame bias)."""
    out = []
    for path in esa_lisa_orbit_files("TDB"):
        tr = read_oem(path)
        out.append(to_heliocentric(tr, eme2000_frame_bias=not file_axes_icrf))
    return out


def _full_digit_y0(file_axes_icrf):
    y = np.zeros((3, 6, 2))
    rot = np.eye(3) if file_axes_icrf else frame_bias_matrix().T
    for s, row in enumerate(FULL_DIGIT_STATES_KM):
        x = np.array(row) * 1e3
        y[s, 0:3, 0], y[s, 3:6, 0] = rot @ x[:3], rot @ x[3:]
    return y


def _run(overrides=(), duration=SPAN, y0=None, model=None):
    scen = load_scenario("lisa-esa", [f"run.duration={duration}", *overrides])
    blocks = []
    dynamics.propagate(scen, sink=blocks.append, y0=y0, model=model)
    rows = dynamics.Rows.concatenate(blocks)
    return scen, rows.t[0] + rows.t[1], rows.sat_r[0] + rows.sat_r[1], rows.sat_v[0] + rows.sat_v[1]


def _on_grid(orbits, epoch_tdb, t):
    states = [states_at(o, epoch_tdb[0], epoch_tdb[1] + t / DAY) for o in orbits]
    return np.stack([s[0] for s in states], 1), np.stack([s[1] for s in states], 1)


def _row(t, day):
    return int(np.argmin(np.abs(t / DAY - day)))


def _at_steps(orbits, epoch_tdb, t, r, v):
    """(days, |dr| (M, 3)) at ESA's integration steps (every 4th record), tqdyn Hermite-interpolated there."""
    td = (orbits[0].jd1 - epoch_tdb[0]) + (orbits[0].jd2 - epoch_tdb[1])
    idx = np.arange(0, td.size, 4)
    idx = idx[td[idx] <= t[-1] / DAY]
    d = []
    for s, o in enumerate(orbits):
        tq = dataclasses.replace(o, jd1=np.full(t.size, epoch_tdb[0]), jd2=epoch_tdb[1] + t / DAY,
                                 r=r[:, s].copy(), v=v[:, s].copy(), a=None, start=(epoch_tdb[0], epoch_tdb[1]),
                                 stop=(epoch_tdb[0], epoch_tdb[1] + t[-1] / DAY), source="tqdyn")
        d.append(np.linalg.norm(states_at(tq, o.jd1[idx], o.jd2[idx])[0] - o.r[idx], axis=-1))
    return td[idx], np.stack(d, 1)


def _statistics(R, V):
    a = geometry.arms(R, V)
    deg = np.degrees(geometry.breathing_angles(a)[0])
    return {"angle_deg": (deg.min(), deg.max()), "length_m": (a.length.min(), a.length.max()),
            "rate_mps": (a.length_dot.min(), a.length_dot.max())}


@pytest.fixture(scope="module")
def esa():
    # read as the built-in lisa scenario reads them (initial.oem_eme2000 = "icrf": the files' "EME2000" is ICRF)
    return _esa(file_axes_icrf=True)


@pytest.fixture(scope="module")
def lisa_file(tmp_path_factory):
    """``tqdyn run lisa --set run.duration=3926.5d`` to a trajectory file, read back."""
    out = tmp_path_factory.mktemp("esa-lisa") / "lisa.h5"
    scen = load_scenario("lisa-esa", [f"run.duration={SPAN}", f"run.output={out}"])
    run_to_file(scen)
    return read_trajectory(out)


@pytest.fixture(scope="module")
def lisa_vs_esa(lisa_file, esa):
    """t [s], tqdyn r, v and ESA's R, V (N, 3, 3) on the 6 h grid of the file, |dr| (N, 3)."""
    tr = lisa_file
    t = tr["t"]
    hi, lo = tr.dd("sat/r")
    r, v = hi + lo, tr["sat/v"]
    R, V = _on_grid(esa, tr.epoch.tdb, t)
    return t, r, v, R, V, np.linalg.norm(r - R, axis=-1)


def test_file_is_heliocentric_on_the_files_epoch(lisa_file, esa):
    # the run starts at the files' first record: 2036-12-09T00:00:00.00000094 TDB, the same states
    tr = lisa_file
    ep = tr.epoch.tdb
    first = (esa[0].jd1[0] - ep[0]) + (esa[0].jd2[0] - ep[1])
    assert abs(first) * DAY < 1e-6
    assert tr["t"].size == 15707 and tr["t"][-1] == pytest.approx(3926.5 * DAY)
    hi, lo = tr.dd("sat/r")
    for s, o in enumerate(esa):
        assert np.max(np.abs(hi[0, s] + lo[0, s] - o.r[0])) < 1e-3
    assert 1.4e11 < np.linalg.norm(hi[0, 0]) < 1.6e11     # Sun-centred (1 au), not geocentric


def test_ten_days_tens_of_metres(lisa_vs_esa):
    # measured 24.4 / 46.5 / 71.7 m (LISA1 / 2 / 3); bound 250 m (3.5-10x).  Mostly the files' rounding of
    # the initial velocities to 0.1 mm/s (0.05 mm/s x 10 d = 43 m) and ESA's dense output between its steps
    t, *_, d = lisa_vs_esa
    k = _row(t, 10.0)
    assert t[k] == pytest.approx(10 * DAY)
    assert np.all(d[k] < 250.0), d[k]


def test_self_gravity_sign_and_size():
    # ESA's ramp starts at -2 nm/s^2 (away from the centre): the opposite sign misses the files by 1.50-1.54 km
    # after 10 days, no self-gravity by 0.76-0.79 km (1/2 g t^2 = 0.75 km for 2 nm/s^2), the scenario's by
    # 24-72 m.  Bounds: flipped > 1.1 km, none in 0.5..1.1 km, nominal < 250 m.
    esa = _esa(file_axes_icrf=True)
    out = {}
    for name, ov in (("nominal", []), ("flipped", ["spacecraft.self_gravity_center=[2e-9, -2e-9]"]),
                     ("none", ["spacecraft.self_gravity_center=[0, 0]"])):
        scen, t, r, _ = _run(ov, duration="10d")
        R, _ = _on_grid(esa, scen.epoch.tdb, t[-1:])
        out[name] = np.linalg.norm(r[-1] - R[0], axis=-1)
    assert np.all(out["nominal"] < 250.0), out
    assert np.all(out["flipped"] > 1100.0), out
    assert np.all((out["none"] > 500.0) & (out["none"] < 1100.0)), out


def test_self_gravity_ramp_in_the_files_accelerations(esa):
    # The files' accelerations (rounded to 1e-12 km/s^2 = 1e-9 m/s^2) minus tqdyn's gravity at the files'
    # states, projected on the direction to the centroid and fitted by g0 (1 - s) + g1 s (s = the fraction of
    # the span): measured g0 = -2.003e-9, g1 = +2.004e-9 m/s^2 (residual rms 3.0e-10 m/s^2, the rounding's
    # 1e-9/sqrt(12) = 2.9e-10).  Bounds: g0, g1 within 0.1 nm/s^2 (~20 sigma) of -+2 nm/s^2, rms < 4e-10.
    from tqdyn.dynamics import layout
    from tqdyn.dynamics.rhs import evaluate_rhs

    scen = load_scenario("lisa-esa", [f"run.duration={SPAN}"])
    model = build_force_model(scen.forces, scen.reference)
    ep = scen.epoch.tdb
    t = np.clip(((esa[0].jd1 - ep[0]) + (esa[0].jd2 - ep[1])) * DAY, 0.0, None)
    tdat = model.precompute(scen.epoch, t, np.zeros_like(t))
    R = np.stack([o.r for o in esa], 1)
    V = np.stack([o.v for o in esa], 1)
    A = np.stack([o.a for o in esa], 1)
    cpar = layout.make_cpar(layout.MODE_POINT_MASS)
    grav = np.zeros_like(R)
    for k in range(t.size):
        y = np.zeros((3, 6, 2))
        y[:, 0:3, 0], y[:, 3:6, 0] = R[k], V[k]
        kk = evaluate_rhs(y, tdat[k], model, cpar)
        grav[k] = kk[:, 3:6, 0] + kk[:, 3:6, 1]
    c = R.mean(axis=1, keepdims=True) - R
    c /= np.linalg.norm(c, axis=-1, keepdims=True)
    g = np.einsum("nsk,nsk->ns", A - grav, c)
    s = t / t[-1]
    X = np.tile(np.stack([1.0 - s, s], 1), (3, 1))
    (g0, g1), *_ = np.linalg.lstsq(X, g.T.ravel(), rcond=None)
    rms = np.std(g.T.ravel() - X @ np.array([g0, g1]))
    assert abs(g0 + 2e-9) < 1e-10 and abs(g1 - 2e-9) < 1e-10, (g0, g1)
    assert rms < 4e-10, rms


def test_one_year_and_whole_span(lisa_vs_esa):
    # the files read as the lisa scenario reads them (their "EME2000" as ICRF axes): measured |dr| after 1 year
    # 1580 / 354 / 6147 m, after 3926.5 d (10.75 years) 2.30 / 11.7 / 63.9 km, >= 99.4 % along-track;
    # bounds 10 / 3 / 30 km and 15 / 80 / 300 km (4.7-8.5x).  With the frame bias applied to the files (the
    # standard reading of EME2000) it would be 6.48 / 16.0 / 67.8 km (docs/lisa-orbits.md).
    t, r, _, R, V, d = lisa_vs_esa
    one = d[_row(t, YEAR_D)]
    end = d[-1]
    assert np.all(one < np.array([10e3, 3e3, 30e3])), one
    assert np.all(end < np.array([15e3, 80e3, 300e3])), end
    rh = R[-1] / np.linalg.norm(R[-1], axis=-1, keepdims=True)
    h = np.cross(R[-1], V[-1])
    th = np.cross(h / np.linalg.norm(h, axis=-1, keepdims=True), rh)
    along = np.abs(np.einsum("sk,sk->s", r[-1] - R[-1], th))
    assert np.all(along > 0.98 * end), (along, end)


def test_what_remains_is_the_rounding_and_esas_integration():
    # From the full-digit first record (18 digits, the files' axes taken as ICRF) the three spacecraft move
    # alike: at ESA's integration steps 0.2 m after 11.2 d, 526 / 532 / 500 m after 360.6 d and
    # 19.2 / 18.9 / 19.0 km after 3917 d -- ESA's 1e-9 integration (tqdyn matches ESA's 1e-15 integration of
    # the same model to 1.1 m after a year and 52 m after 10.7 years: docs/lisa-orbits.md).  The rounded
    # start minus the full-digit one: 26 / 42 / 62 m after 10 d, 2.1 / 0.9 / 5.6 km after 1 year.
    # Bounds: 2 m, 2.5 km, 60 km; the three within 10 % of each other at the end (measured 1.8 %);
    # rounding effect at 1 year > 0.5 km for each (measured 0.92-5.6 km).
    esa_icrf = _esa(file_axes_icrf=True)
    scen, t, r, v = _run(y0=_full_digit_y0(True))
    ep = scen.epoch.tdb
    days, d = _at_steps(esa_icrf, ep, t, r, v)
    assert days[1] == pytest.approx(11.235, abs=1e-3)
    assert np.all(d[1] < 2.0), d[1]
    one = d[int(np.argmin(np.abs(days - 360.55)))]
    assert np.all(one < 2.5e3), one
    assert np.all(d[-1] < 60e3), d[-1]
    assert np.ptp(d[-1]) < 0.1 * d[-1].mean(), d[-1]
    _, _, r_rounded, _ = _run(y0=np.stack([np.stack([np.r_[o.r[0], o.v[0]], np.zeros(6)], -1) for o in esa_icrf]))
    rounding = np.linalg.norm(r_rounded - r, axis=-1)[_row(t, YEAR_D)]
    assert np.all(rounding > 500.0), rounding


def test_gm_sun_sensitivity():
    # GM_Sun x (1 + 1e-9): measured 1.89 / 1.85 / 1.89 km after 1 year and 14.90 / 14.68 / 14.96 km after
    # 10.75 years (1.39 km/yr); first-order theory 3 pi a dGM/GM = 1.41 km per orbit.  Bound: the 10.75-year
    # drift within 15 % of 10.75 x the theory.
    y0 = _full_digit_y0(False)
    scen, t, r1, _ = _run(y0=y0)
    model = build_force_model(scen.forces, scen.reference)
    gm = float(SunMonopole().gm)
    scaled = ForceModel([SunMonopole(gm=repr(gm * (1 + 1e-9))) if term.name == "sun_monopole" else term
                         for term in model.terms], model.reference)
    _, _, r2, _ = _run(y0=y0, model=scaled)
    drift = np.linalg.norm(r2[-1] - r1[-1], axis=-1)
    a = np.linalg.norm(r1, axis=-1).mean()
    theory = 3 * np.pi * a * 1e-9 * t[-1] / DAY / YEAR_D
    assert np.all(np.abs(drift / theory - 1) < 0.15), (drift, theory)


def test_constellation_statistics_match_esa(lisa_file, lisa_vs_esa):
    # Over the span, 6 h grid, tqdyn | ESA's files (interpolated):
    #   corner angles   58.999553 .. 61.005364 | 58.999487 .. 61.005031 deg  (differences 6.6e-5, 3.3e-4 deg)
    #   arm lengths     2.4578975 .. 2.5327942 | 2.4579033 .. 2.5327886 Gm   (-5.8, +5.6 km)
    #   arm-length rate -10.04792 .. 10.05246  | -10.04974 .. 10.05254 m/s   (1.8, -0.08 mm/s)
    # Bounds: 2e-3 deg, 30 km, 10 mm/s (5-6x); ESA's values themselves to 1e-5 deg, 0.1 km, 0.1 mm/s (they
    # are properties of the shipped files and of the reader).
    _, r, v, R, V, _ = lisa_vs_esa
    st, se = _statistics(r, v), _statistics(R, V)
    for k in (0, 1):
        assert abs(st["angle_deg"][k] - se["angle_deg"][k]) < 2e-3
        assert abs(st["length_m"][k] - se["length_m"][k]) < 30e3
        assert abs(st["rate_mps"][k] - se["rate_mps"][k]) < 10e-3
    assert se["angle_deg"] == pytest.approx((58.999487, 61.005031), abs=1e-5)
    assert se["length_m"] == pytest.approx((2457903303.7, 2532788623.5), abs=100.0)
    assert se["rate_mps"] == pytest.approx((-10.049738, 10.052537), abs=1e-4)
    # the metrics module's breathing angles of the heliocentric file are the same angles
    alpha = np.degrees(breathing_angles_of(lisa_file))
    assert alpha.min() == pytest.approx(st["angle_deg"][0], abs=1e-9)
    assert alpha.max() == pytest.approx(st["angle_deg"][1], abs=1e-9)
