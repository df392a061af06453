"""The paper's studies on LISA / Taiji (``tqdyn report --studies --mission lisa``) and the first-order estimates.

References (none is produced by the coupled code under test):

* the first-order closed forms of docs/lisa-coupled.md (derived there and by tools/derive_lisa_estimates.py,
  transcribed below as ``_formula``): max |G| = 4.1204 alpha n^2 d, max suspension component 2.3849 alpha n^2 d
  for the equal-arm Keplerian design (lisaorbits' KeplerianOrbits, tilt pi/3 + 5/8 alpha), alpha = L / (2 a),
  n^2 = GM_sun / a^3, d = 0.30 m;
* the exact identity g_l = d (T u_l - u_l'') with the LISA drag-free scheme (Cramer's rule), written out here
  (``_identity``), evaluated on ESA's CReMA 2.0 orbit files (tqdyn/data/esa-lisa-orbits) or on exact two-body
  orbits of the design (``_kepler_design``, lisaorbits' element formulas);
* the Clohessy-Wiltshire equations (integrated here with scipy) for the common self-gravity and the ramp;
* first-order bounds v/c, v^2/(2 c^2), L v/c^2 for the pointing laws, v and L from ESA's files.

Measured values (docs/lisa-coupled.md) are quoted with each test; bounds are 3-10x the measured deviation.
Runs: one year at the scenarios' 6 h step, ~1-2 s each once the JIT cache is warm (a cold cache compiles the
heliocentric coupled right-hand side once, ~35 s).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from cli_support import run_cli
from tqdyn.constellation import estimates as le
from tqdyn.analysis.metrics import orbit_deviation
from tqdyn.astro.oem_states import states_at, to_heliocentric
from tqdyn.formats.trajectory import read_trajectory
from tqdyn.readers.oem import esa_lisa_orbit_files, read_oem
from tqdyn.scenario import load_scenario
from tqdyn.workflows import studies as st
from tqdyn.workflows import studies_lisa as sl
from tqdyn.workflows.run import run_to_file

AU = 149597870700.0
GM_SUN = 1.3271244004193938e20      # DE430 (tqdyn/data/gm_de431.tpc)
C = 299792458.0
D_TM = 0.30                         # m, the lisa / taiji presets' tm_distance
DAY = 86400.0
NO_RAMP = "spacecraft.self_gravity_center=[0, 0]"
KEPLER_COUPLED = ("spacecraft.architecture=lisa", "spacecraft.self_gravity=off", "constellation.pointing=iterative",
                  "constellation.control=on")
PERM = ((0, 1, 2), (1, 2, 0), (2, 0, 1))
S3 = math.sqrt(3.0)


# --------------------------------------------------------------------------- references written out here


def _formula(tau):
    """docs/lisa-coupled.md, "The estimate": G in S and A_l in OA_l, unit alpha n^2 d, at mean anomaly tau."""
    c1, s1, c3, s3 = np.cos(tau), np.sin(tau), np.cos(3 * tau), np.sin(3 * tau)
    G = np.stack([-13 / 4 * c1 + 3 / 16 * c3, -21 / 8 * s1 + 15 / 16 * s3,
                  S3 / 64 * (36 - 39 * np.cos(2 * tau) + 1.5 * np.cos(4 * tau))], -1)
    az = 81 / 64 * np.sin(2 * tau) - 3 / 128 * np.sin(4 * tau)
    A = np.stack([7 / 8 * (c1 - S3 * s1) + 3 / 8 * c3 + S3 / 2 * s3, az,
                  -7 / 8 * (c1 + S3 * s1) - 3 / 8 * c3 + S3 / 2 * s3, -az], -1)
    return G, A


_TAU = np.linspace(0.0, 2 * np.pi, 200001)
FORMULA_MAX_G = float(np.linalg.norm(_formula(_TAU)[0], axis=-1).max())
FORMULA_MAX_A = float(np.abs(_formula(_TAU)[1]).max())


def _unit(x):
    return x / np.linalg.norm(x, axis=-1, keepdims=True)


def _identity(R, V, A, gm=GM_SUN, d=D_TM):
    """max |G|, max |A component| over (N, 3) states from g_l = d (T u_l - u_l'') and the LISA scheme."""
    maxG = maxA = 0.0
    for i, j, k in PERM:
        us, gs = [], []
        for far in (k, j):
            D, Dd, Ddd = R[:, far] - R[:, i], V[:, far] - V[:, i], A[:, far] - A[:, i]
            L = np.linalg.norm(D, axis=-1, keepdims=True)
            u = D / L
            Ld = np.sum(u * Dd, -1, keepdims=True)
            ud = (Dd - u * Ld) / L
            Ldd = np.sum(u * Ddd, -1, keepdims=True) + np.sum(Dd * ud, -1, keepdims=True)
            udd = (Ddd - u * Ldd - 2 * Ld * ud) / L
            rn = np.linalg.norm(R[:, i], axis=-1, keepdims=True)
            rh = R[:, i] / rn
            us.append(u)
            gs.append(d * (gm / rn ** 3 * (3 * rh * np.sum(rh * u, -1, keepdims=True) - u) - udd))
        e1, e2 = us
        Z = _unit(np.cross(e2, e1))
        det = np.sum(e1 * np.cross(e2, Z), -1, keepdims=True)
        G = (np.sum(e1 * gs[0], -1, keepdims=True) * np.cross(e2, Z)
             + np.sum(e2 * gs[1], -1, keepdims=True) * np.cross(Z, e1)
             + 0.5 * np.sum(Z * (gs[0] + gs[1]), -1, keepdims=True) * np.cross(e1, e2)) / det
        maxG = max(maxG, float(np.linalg.norm(G, axis=-1).max()))
        for e, g in zip(us, gs):
            a = G - g
            comps = np.stack([np.sum(a * np.cross(Z, e), -1), np.sum(a * Z, -1)], -1)
            maxA = max(maxA, float(np.abs(comps).max()))
    return maxG, maxA


def _kepler_design(alpha, t):
    """Exact two-body states (a = 1, GM = 1) of lisaorbits' KeplerianOrbits design: R, V, A (N, 3, 3)."""
    nu = np.pi / 3 + 0.625 * alpha
    e = np.sqrt(1 + 4 * alpha * np.cos(nu) / S3 + 4 * alpha ** 2 / 3) - 1
    inc = np.arctan(alpha * np.sin(nu) / (S3 / 2 + alpha * np.cos(nu)))
    R, V = np.zeros((t.size, 3, 3)), np.zeros((t.size, 3, 3))
    for k in range(3):
        th = 2 * np.pi * k / 3
        M = t - th
        E = M.copy()
        for _ in range(40):
            E = E - (E - e * np.sin(E) - M) / (1 - e * np.cos(E))
        Ed = 1 / (1 - e * np.cos(E))
        p = np.stack([np.cos(inc) * (np.cos(E) - e), np.sqrt(1 - e * e) * np.sin(E), -np.sin(inc) * (np.cos(E) - e)], -1)
        pd = np.stack([-np.cos(inc) * np.sin(E) * Ed, np.sqrt(1 - e * e) * np.cos(E) * Ed, np.sin(inc) * np.sin(E) * Ed], -1)
        Rz = np.array([[np.cos(th), -np.sin(th), 0], [np.sin(th), np.cos(th), 0], [0, 0, 1]])
        R[:, k], V[:, k] = p @ Rz.T, pd @ Rz.T
    return R, V, -R / np.linalg.norm(R, axis=-1, keepdims=True) ** 3


def _esa():
    return [to_heliocentric(read_oem(p), eme2000_frame_bias=False) for p in esa_lisa_orbit_files("TDB")]


def _esa_records(days):
    esa = _esa()
    td = (esa[0].jd1 - esa[0].jd1[0]) + (esa[0].jd2 - esa[0].jd2[0])
    sel = td <= days + 1e-9
    return (td[sel] * DAY, *(np.stack([getattr(o, f)[sel] for o in esa], 1) for f in ("r", "v", "a")))


# --------------------------------------------------------------------------- runs


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """Lazily run and read one-year studies runs: runs(name) -> Trajectory."""
    work = tmp_path_factory.mktemp("lisa-studies")
    specs = {
        "kepler": ("lisa-kepler", KEPLER_COUPLED),
        "taiji-sun": ("taiji", ("forces.third_bodies=[]", "forces.relativity=false")),
        "lisa0": ("lisa", (NO_RAMP,)),
        "ramp": ("lisa", ()),
        "esa": ("lisa-esa", ()),
        "sg+x": ("lisa", (NO_RAMP, "spacecraft.self_gravity_common=[1e-9, 0, 0]")),
        "sg-y": ("lisa", (NO_RAMP, "spacecraft.self_gravity_common=[0, -1e-9, 0]")),
        "sg+z": ("lisa", (NO_RAMP, "spacecraft.self_gravity_common=[0, 0, 1e-9]")),
    }
    cache = {}

    def get(name):
        if name not in cache:
            scen, over = specs[name]
            out = work / f"{name}.h5"
            run_to_file(load_scenario(scen, [*over, "run.duration=365d", f"run.output={out}"]))
            cache[name] = read_trajectory(out)
        return cache[name]

    return get


def _r(tr):
    hi, lo = tr.dd("sat/r")
    return hi + lo


# --------------------------------------------------------------------------- the estimate


def test_formula_is_the_first_order_of_the_exact_identity():
    # The docs' closed forms against the exact identity on exact two-body orbits of the design: max |G| /
    # (alpha n^2 d) = 4.11951 (alpha = 1e-3), 4.11187 (1e-2) vs the formula's 4.12040; suspension 2.38611, 2.39702
    # vs 2.38490: relative differences <= 0.22 alpha (|G|) and 0.51 alpha (A), i.e. O(alpha).  Bounds: 2 alpha
    # (4x), and the difference shrinks with alpha (first order).
    assert FORMULA_MAX_G == pytest.approx(4.120403, abs=2e-6) and FORMULA_MAX_A == pytest.approx(2.384899, abs=2e-6)
    t = np.linspace(0.0, 2 * np.pi, 2001)
    err = {}
    for alpha in (1e-3, 1e-2):
        mG, mA = _identity(*_kepler_design(alpha, t), gm=1.0, d=1.0)
        err[alpha] = (abs(mG / alpha / FORMULA_MAX_G - 1), abs(mA / alpha / FORMULA_MAX_A - 1))
        assert max(err[alpha]) < 2 * alpha, (alpha, err[alpha])
    assert err[1e-3][0] < 0.3 * err[1e-2][0] and err[1e-3][1] < 0.3 * err[1e-2][1]


@pytest.mark.parametrize("name, L", [("kepler", 2.5e9), ("taiji-sun", 3.0e9)])
def test_coupled_keplerian_designs_match_the_formula(runs, name, L):
    # 1-year coupled runs of the Keplerian designs (Sun only, iterative pointing, no self-gravity).  Measured:
    # LISA max |G| 4.0875e-16, max suspension 2.3921e-16 m/s^2 (formula 4.0943e-16, 2.3698e-16: ratios 0.9983,
    # 1.0094); Taiji 4.9033e-16, 2.8704e-16 (4.9132e-16, 2.8438e-16: 0.9980, 1.0094).  The differences are the
    # O(alpha) terms (-0.17 % for |G| on the exact design, previous test) and, for the suspension, the TMs sitting
    # on the received (aberrated, ~1e-4 rad) beams (~+0.5 %).  Bounds: |G| within 1 %, suspension within 3 %.
    tr = runs(name)
    scale = L / (2 * AU) * GM_SUN / AU ** 3 * D_TM
    mG = float(np.linalg.norm(tr["sat/a_dragfree"], axis=-1).max())
    mA = float(np.abs(tr["tm/a_suspension"]).max())
    assert mG / (FORMULA_MAX_G * scale) == pytest.approx(1.0, abs=0.01)
    assert mA / (FORMULA_MAX_A * scale) == pytest.approx(1.0, abs=0.03)


def test_coupled_lisa_on_esas_orbit_matches_the_identity_on_esas_files(runs):
    # ESA's orbit flexes more (corner angles 59..61 deg) than the Keplerian design (59.78..60.22 deg): measured
    # max |G| 7.9447e-16, suspension 6.3973e-16 m/s^2; the identity on ESA's 110 records of the first year gives
    # 7.9443e-16, 6.4056e-16 (ratios 1.0000, 0.9987).  Bound 1 % (7x).  The first-order Keplerian formula
    # (4.09e-16) is a factor 1.9 below: the flexing terms 2 (L'/L) u' + (L''/L) u of g_l dominate.
    tr = runs("lisa0")
    _, R, V, A = _esa_records(365.0)
    iG, iA = _identity(R, V, A)
    mG = float(np.linalg.norm(tr["sat/a_dragfree"], axis=-1).max())
    mA = float(np.abs(tr["tm/a_suspension"]).max())
    assert mG / iG == pytest.approx(1.0, abs=0.01) and mA / iA == pytest.approx(1.0, abs=0.01)
    assert 1.5 < mG / (FORMULA_MAX_G * 2.5e9 / (2 * AU) * GM_SUN / AU ** 3 * D_TM) < 2.5


# --------------------------------------------------------------------------- common self-gravity


def test_cw_closed_forms_solve_the_hill_equations():
    # tqdyn.constellation.estimates.cartwheel_sg_displacement (the docs' closed forms) against scipy's integration
    # of x'' = 3n^2 x + 2n y' + f_x, y'' = -2n x' + f_y, z'' = -n^2 z + f_z with f along X_S = -rho_hat,
    # Y_S = N x rho_hat, Z_S = -N of a cartwheel satellite.  Measured agreement ~1e-10 relative; bound 1e-7.
    from scipy.integrate import solve_ivp

    n, phi, f0 = 2e-7, 0.7, 1e-9
    u0, w0 = np.array([0.5, 0, S3 / 2]), np.array([0, -1.0, 0])
    N = np.cross(u0, w0)
    t = np.linspace(0, 3.2e7, 201)
    for axis in "xyz":
        def force(s):
            rho = np.cos(n * s + phi) * u0 + np.sin(n * s + phi) * w0
            return f0 * {"x": -rho, "y": np.cross(N, rho), "z": -N}[axis]

        def rhs(s, y):
            f = force(s)
            return [y[3], y[4], y[5], 3 * n * n * y[0] + 2 * n * y[4] + f[0], -2 * n * y[3] + f[1], -n * n * y[2] + f[2]]

        sol = solve_ivp(rhs, (0, t[-1]), np.zeros(6), t_eval=t, rtol=1e-11, atol=1e-9, method="DOP853")
        dr, dv = le.cartwheel_sg_displacement(axis, f0, n, t, phi)
        assert np.max(np.abs(sol.y[:3].T - dr)) < 1e-7 * np.max(np.abs(dr)), axis
        assert np.max(np.abs(sol.y[3:].T - dv)) < 1e-7 * np.max(np.abs(dv)), axis


@pytest.mark.parametrize("label", ["+x", "-y", "+z"])
def test_common_self_gravity_changes_the_arms_as_hill_says(runs, label):
    # 1e-9 m/s^2 on both TMs along an axis of S, ESA's orbit, ramp off, one year, minus the no-self-gravity run.
    # Reference: the CW response on the rigid cartwheel from ESA's first record (phases from ESA's file, not from
    # the runs).  Measured max |dL| per arm: +x 781 / 891 / 441 km (Hill 769 / 891 / 441: ratios 1.016 / 0.999 /
    # 0.999); -y 1154 / 493 / 1504 km (1142 / 502 / 1494: 1.011 / 0.982 / 1.006); max |dL/dt| and |d alpha|
    # within 1.9 % as well (+x: 140 / 235 / 110 mm/s, 0.019 / 0.022 / 0.024 deg).  Along +-Z_S (the same push on
    # all three) first order gives zero; measured 6.3 / 6.8 / 2.8 km.  Bounds: 6 % (3x), and < 20 km for z.
    from tqdyn.constellation import geometry

    base, tr = runs("lisa0"), runs(f"sg{label}")
    esa = _esa()
    R0, V0 = np.stack([o.r[0] for o in esa]), np.stack([o.v[0] for o in esa])
    t = tr["t"]
    a0 = geometry.arms(base.dd("sat/r"), base.dd("sat/v"))
    a1 = geometry.arms(tr.dd("sat/r"), tr.dd("sat/v"))
    dL = np.abs(a1.length - a0.length)[:, :3].max(axis=0)
    dLd = np.abs(a1.length_dot - a0.length_dot)[:, :3].max(axis=0)
    dal = np.abs(geometry.breathing_angles(a1)[0] - geometry.breathing_angles(a0)[0]).max(axis=0)
    f = 1e-9 if label[0] == "+" else -1e-9
    eL, eLd, eal = le.common_sg_arm_response(label[1], f, t, R0, V0, gm=GM_SUN)
    if label[1] == "z":
        assert np.all(dL < 20e3), dL
        assert np.all(eL == 0.0)
        return
    for meas, est in ((dL, np.abs(eL).max(axis=0)), (dLd, np.abs(eLd).max(axis=0)), (dal, np.abs(eal).max(axis=0))):
        assert np.all(np.abs(meas / est - 1) < 0.06), (meas, est)
    # the sign: the arm changes at the end follow the estimate's
    end = (a1.length - a0.length)[-1, :3]
    assert np.all(np.sign(end) == np.sign(eL[-1])), (end, eL[-1])


# --------------------------------------------------------------------------- pointing


def test_pointing_law_costs_at_lisa(runs):
    # Along the 1-year drag-free orbit (6 h grid, every 4th row): global vs iterative per beam 9.980e-5 rad, X_S
    # 8.66e-5, theta 9.985e-5 (MOSA angle theta/2 = 4.99e-5); taylor1 / taylor2 4.96e-9 / 4.99e-9 rad per beam;
    # tau = L/c off by 8.40e-4 s.  References (first order, v = max |v| and L = max arm of ESA's files over the
    # year): v/c = 9.99e-5 rad, v^2/(2c^2) = 4.99e-9 rad, L v/c^2 = 8.42e-4 s.  Bounds: within [0.8, 1.01] of
    # each (measured 0.99-1.00).
    from tqdyn.analysis.pointing_study import pointing_study_of

    tr = runs("lisa0")
    _, R, V, _ = _esa_records(365.0)
    v = float(np.linalg.norm(V, axis=-1).max())
    L = float(max(np.linalg.norm(R[:, j] - R[:, i], axis=-1).max() for i, j, _ in PERM))
    study = pointing_study_of(tr, stride=4)
    g, t1, t2 = (study.laws[k] for k in ("global", "taylor1", "taylor2"))
    assert 0.8 < g.max_per_beam / (v / C) < 1.01
    assert 0.8 < g.max_theta / (v / C) < 1.01
    for law in (t1, t2):
        assert 0.8 < law.max_per_beam / (v * v / (2 * C * C)) < 1.01
    assert 0.8 < float(np.max(study.tau_error)) / (L * v / C ** 2) < 1.01


@pytest.mark.slow
def test_global_pointing_in_the_loop_costs_nothing_dynamically(runs, tmp_path):
    # The coupled run with global (instantaneous) pointing instead of iterative: the TMs turn with the beams by
    # delta <= v/c = 1e-4 rad, so g_l changes by ~ d n^2 delta = 1.2e-18 m/s^2 (first order).  Measured over a
    # year: max |dG| 1.33e-18, max |dA| 2.41e-18 m/s^2, orbits 1.8 mm apart.  Bounds: dG, dA < 1e-17 (3x the
    # estimate ... 7x the measured), orbits < 1 cm (5x).  Slow only because the global-pointing right-hand side
    # is a separate compilation (~40 s with a cold JIT cache; the run itself takes ~1 s).
    out = tmp_path / "global.h5"
    run_to_file(load_scenario("lisa", [NO_RAMP, "constellation.pointing=global", "run.duration=365d",
                                       f"run.output={out}"]))
    g, it = read_trajectory(out), runs("lisa0")
    estimate = D_TM * GM_SUN / AU ** 3 * 29.9e3 / C
    assert estimate == pytest.approx(1.19e-18, rel=0.02)
    assert float(np.linalg.norm(g["sat/a_dragfree"] - it["sat/a_dragfree"], axis=-1).max()) < 1e-17
    assert float(np.abs(g["tm/a_suspension"] - it["tm/a_suspension"]).max()) < 1e-17
    assert np.all(orbit_deviation(g, it).norm.max(axis=0) < 0.01)


# --------------------------------------------------------------------------- ESA's ramp


def test_esa_ramp_residual_is_the_bisector_vs_centroid_push(runs):
    # Coupled lisa (the ramp as a common TM self-gravity along +X_S, the beams' bisector) minus lisa-esa (the ramp
    # toward the centroid) after 364 d: along-track 5675 / -3062 / -275 m.  Reference: the CW response, on ESA's
    # orbit (the files interpolated on the run's grid), to g(t) (X_beam - c_hat) with X_beam the bisector of the
    # beams from the emitters' positions L/c earlier (first order in v/c) and c_hat the direction to the centroid,
    # g(t) = -2 + 4 t / T nm/s^2 over the files' span T: 5642 / -3076 / -263 m (0.6 / 0.4 / 4.3 %).  Without the
    # aberration (instantaneous bisector) Sat3 gets -161 m: the beams' aberration is 40 % of its difference.
    # Bounds: max(3 %, 40 m); the aberration-free prediction misses Sat3 by > 80 m (measured 114 m).
    c, e = runs("ramp"), runs("esa")
    esa = _esa()
    dev = orbit_deviation(c, e)
    t = c["t"]
    ep = c.epoch.tdb
    st_ = [states_at(o, ep[0], ep[1] + t / DAY) for o in esa]
    R, V = np.stack([s[0] for s in st_], 1), np.stack([s[1] for s in st_], 1)
    span = ((esa[0].stop[0] - esa[0].start[0]) + (esa[0].stop[1] - esa[0].start[1])) * DAY
    g = -2e-9 + 4e-9 * t / span
    Xb, Xi = np.zeros_like(R), np.zeros_like(R)
    for i, j, k in PERM:
        ub, ui = [], []
        for far in (j, k):
            D = R[:, far] - R[:, i]
            L = np.linalg.norm(D, axis=-1, keepdims=True)
            ui.append(D / L)
            ub.append(_unit(D - V[:, far] * L / C))
        Xb[:, i], Xi[:, i] = _unit(ub[0] + ub[1]), _unit(ui[0] + ui[1])
    ch = _unit(R.mean(axis=1, keepdims=True) - R)
    pred = le.cw_response(t, R, V, g[:, None, None] * (Xb - ch), gm=GM_SUN)[-1, :, 1]
    pred_inst = le.cw_response(t, R, V, g[:, None, None] * (Xi - ch), gm=GM_SUN)[-1, :, 1]
    meas = dev.along[-1]
    assert np.all(np.abs(pred - meas) < np.maximum(0.03 * np.abs(meas), 40.0)), (pred, meas)
    assert abs(pred_inst[2] - meas[2]) > 80.0, (pred_inst, meas)
    # the angle between X_S and the centroid direction: first order (L_ik - L_ij) / (2 sqrt(3) L) from ESA's files;
    # measured max 0.2837 / 0.3048 / 0.2617 deg, first order 0.2890 / 0.3010 / 0.2617, max difference 0.0063 deg
    X = c["sat/T_S_I"][:, :, 0, :]
    ang = np.arctan2(np.einsum("nsk,nsk->ns", ch, c["sat/T_S_I"][:, :, 1, :]), np.einsum("nsk,nsk->ns", ch, X))
    for i, j, k in PERM:
        Lij, Lik = (np.linalg.norm(R[:, f] - R[:, i], axis=-1) for f in (j, k))
        est = (Lik - Lij) / (2 * S3 * 0.5 * (Lij + Lik))
        assert np.max(np.abs(np.degrees(ang[:, i] - est))) < 0.02


def test_esa_ramp_over_esas_whole_span(tmp_path):
    # Coupled lisa vs lisa-esa over ESA's whole span (3926.5 d = 10.75 yr): along-track 17.35 / -15.43 / -4.43 km
    # (|dr| 17.4 / 15.4 / 4.5 km).  The first-order (circular CW) response to the run's own push difference
    # G - g(t) c_hat holds to 1-4 % for ~3 years and then overestimates (1.59 / 1.54 / 1.37 at the end): the
    # along-track drift then comes from the mean along-track push, ~0.5 % of its amplitude, to which the orbits'
    # eccentricity (~0.005) contributes as much (docs/lisa-coupled.md).  Bounds: 2 years within 5 %; the end
    # within a factor (1, 2.2) of the theory (the sign and order of the effect).  ~3 s.
    from tqdyn.dynamics.system import centre_ramp
    from tqdyn.scenario import loads_scenario

    trs = {}
    for name in ("lisa", "lisa-esa"):
        out = tmp_path / f"{name}.h5"
        run_to_file(load_scenario(name, ["run.duration=3926.5d", f"run.output={out}"]))
        trs[name] = read_trajectory(out)
    c, e = trs["lisa"], trs["lisa-esa"]
    dev = orbit_deviation(c, e)
    t = c["t"]
    r = _r(c)
    g = centre_ramp(loads_scenario(c.scenario_toml).self_gravity_centre_ramp(), t)
    ch = _unit(r.mean(axis=1, keepdims=True) - r)
    pred = le.cw_response(t, r, c["sat/v"], c["sat/a_dragfree"] - g[:, None, None] * ch, gm=GM_SUN)[:, :, 1]
    k2 = int(np.argmin(np.abs(t - 2 * 365.25 * DAY)))
    assert np.all(np.abs(pred[k2] / dev.along[k2] - 1) < 0.05), (pred[k2], dev.along[k2])
    ratio = pred[-1] / dev.along[-1]
    assert np.all((ratio > 1.0) & (ratio < 2.2)), ratio
    assert np.all(np.abs(dev.along[-1]) > 3e3) and np.all(np.abs(dev.along[-1]) < 60e3), dev.along[-1]


def test_bisector_median_angle_first_order():
    # Exact angle between the bisector and the median of a triangle with corner 60 deg +- 1 and adjacent arms
    # differing by up to 3 %: the first-order formula (L_ik - L_ij) / (2 sqrt(3) L) within 3 % of it + 1e-5 rad
    # (measured: second-order differences ~1 % of the angle).
    rng = np.random.default_rng(3)
    for _ in range(200):
        alpha = math.radians(60 + rng.uniform(-1, 1))
        Lij, Lik = 2.5e9 * (1 + rng.uniform(-0.015, 0.015, 2))
        a = np.array([Lij, 0, 0])
        b = Lik * np.array([math.cos(alpha), math.sin(alpha), 0])
        bis = _unit(_unit(a) + _unit(b))
        med = _unit((a + b) / 3)
        exact = math.atan2(np.cross(bis, med)[2], bis @ med)
        est = float(le.bisector_median_angle(Lij, Lik))
        assert abs(est - exact) < 0.03 * abs(exact) + 1e-5, (est, exact)


def test_lisa_scheme_constant_meets_the_scheme_conditions():
    # Reference: the scheme's defining conditions, checked directly in S (first principles): G = A_l + g_l for
    # both TMs, no actuation along the sensitive axes X_OA_l, equal and opposite out-of-plane actuation; and the
    # control module's own solution (constellation.control.dragfree_general), another implementation.  Table IV's
    # self-gravity at theta = 60 and 61.3 deg; measured: conditions to 4e-27 m/s^2 on ~1e-10 m/s^2.
    from tqdyn.constellation.control import dragfree_general, oa_rotation
    from tqdyn.constellation.spacecraft import TABLE_IV_SELF_GRAVITY

    sg = np.asarray(TABLE_IV_SELF_GRAVITY)
    for theta in (math.pi / 3, math.radians(61.3)):
        G, A = le.lisa_scheme_constant(sg, theta)
        T = oa_rotation(theta)                                     # (2, 3, 3): S -> OA_l
        g_S = np.einsum("lji,lj->li", T, sg)                       # g_l in S
        A_S = np.einsum("lji,lj->li", T, A)
        assert np.abs(G[None] - (A_S + g_S)).max() < 1e-25
        assert np.abs(A[:, 0]).max() < 1e-25 and abs(A[0, 2] + A[1, 2]) < 1e-25
        G2, A2 = dragfree_general(g_S, theta)
        assert np.abs(G - G2).max() < 1e-25 and np.abs(A - A2).max() < 1e-25


def test_control_terms_of_a_uniformly_turning_frame():
    # Reference: first principles for S fixed to the inertial axes' orientation at t = 0 and turning at
    # n = sqrt(GM/R^3) about Z_S, the satellites on the x axis at R (T_S_I = I held, a frozen snapshot), the TMs at
    # d (cos 30, +-sin 30, 0) (theta = 60 deg, constant): centrifugal n^2 d, Euler and MOSA terms 0, the Sun's
    # tide GM/R^3 d sqrt(13)/2, and tide + centrifugal = 3 cos 30 n^2 d (the x parts add, the y parts cancel).
    from tqdyn.analysis.metrics import control_terms

    N, R, d = 9, AU, D_TM
    n2 = GM_SUN / R ** 3
    t = np.arange(N) * 3600.0
    r = np.zeros((N, 3, 3))
    r[..., 0] = R
    fields = {"sat/T_S_I": np.broadcast_to(np.eye(3), (N, 3, 3, 3)), "sat/omega_dot": np.zeros((N, 3, 3)),
              "sat/omega": np.broadcast_to([0.0, 0.0, math.sqrt(n2)], (N, 3, 3)),
              "mosa/angle": np.broadcast_to([math.pi / 6, -math.pi / 6], (N, 3, 2))}
    dd = {"t": (t, 0 * t), "sat/r": (r, 0 * r)}
    tr = type("Run", (), {"dd": lambda self, k: dd[k], "__getitem__": lambda self, k: fields[k]})()
    m = control_terms(tr, d, GM_SUN)
    assert m["centrifugal"] == pytest.approx(n2 * d, rel=1e-12)
    assert m["tide"] == pytest.approx(n2 * d * math.sqrt(13) / 2, rel=1e-12)
    assert m["rigid"] == pytest.approx(3 * math.cos(math.pi / 6) * n2 * d, rel=1e-12)
    assert m["euler"] == m["mosa"] == m["alpha_dot_max"] == m["alpha_ddot_max"] == 0.0
    assert control_terms(type("Run", (), {"dd": lambda self, k: (t[:4], 0 * t[:4])})(), d, GM_SUN) == {}


def test_esa_states_on_grid_at_the_records():
    # Reference: ESA's file records themselves (Hermite interpolation at its nodes returns them, to the rounding
    # of the polynomial at 1.5e11 m): a trajectory whose rows are the first 20 records' times (measured 3.2e-4 m,
    # 3.5e-9 m/s), and esa_records over the same span (the records as stored).
    from types import SimpleNamespace

    from tqdyn.analysis.esa_orbits import esa_records, esa_states_on_grid

    esa = _esa()
    tdb = (float(esa[0].jd1[0]), float(esa[0].jd2[0]))
    t = ((esa[0].jd1[:20] - tdb[0]) + (esa[0].jd2[:20] - tdb[1])) * DAY
    traj = SimpleNamespace(epoch=SimpleNamespace(tdb=tdb), dd=lambda name: (t, np.zeros_like(t)))
    rows, R, V = esa_states_on_grid(traj)
    assert np.array_equal(rows, np.arange(20))
    ref = np.stack([o.r[:20] for o in esa], 1)
    assert np.abs(R - ref).max() < 2e-3 and np.abs(V - np.stack([o.v[:20] for o in esa], 1)).max() < 2e-8
    tr, Rr, Vr, Ar = esa_records(float(t[-1]), tdb)
    assert tr.size == 20 and np.array_equal(Rr, ref) and Ar.shape == (20, 3, 3)


# --------------------------------------------------------------------------- catalogue and CLI


def test_lisa_catalogue():
    for s in sl.STUDIES.values():
        assert s.runs and all(r in sl.RUNS for r in s.runs)
    assert st.scaled_duration_s(sl.YEAR_DAYS, sl.QUICK_SCALE, 21600.0) == 16 * 21600
    assert "spacecraft.self_gravity_common=[0, 1e-9, 0]" in sl.RUNS["sg+y-1y"].overrides
    assert sl.NO_RAMP in sl.RUNS["sg+y-1y"].overrides and sl.RUNS["sg+y-1y"].scenario == "lisa"
    with pytest.raises(ValueError, match="study: 'fig5' is not a study; allowed: one of the 7 names in docs/report"):
        st.plan_studies("x", studies=["fig5"], catalogue=sl.STUDIES, runs=sl.RUNS)
    # the TianQin set is unchanged by the catalogue arguments
    assert st.plan_studies("/nonexistent/runs", studies=["extreme"], duration_scale=st.QUICK_SCALE,
                           check_data=False)[0].spec.scenario in ("tianqin-gravity", "tianqin-extreme")


def test_cli_lisa_quick(tmp_path, capsys):
    # all seven studies at durations x 1/90 (365 d -> 4 d, 3926.5 d -> 43.6 d): ~15 s with a warm JIT cache
    out = tmp_path / "s"
    status, stdout, err = run_cli(["report", "--studies", "--mission", "lisa", "--quick", "--workers", "1", "-q",
                                "--out", str(out)], capsys)
    assert status == 0, err
    summary = (out / "summary.md").read_text()
    assert summary.startswith("# tqdyn: the paper's studies on LISA and Taiji (durations x 0.01111)")
    assert "| quantity | reference | tqdyn | notes |" in summary
    for stem in ("lisa-estimate", "lisa-deviation", "lisa-control-no-sg", "lisa-control-table-iv", "lisa-control-ramp",
                 "lisa-common-self-gravity", "lisa-pointing", "lisa-esa-ramp", "lisa-esa-ramp-span"):
        for ext in ("png", "pdf"):
            assert (out / f"{stem}.{ext}").stat().st_size > 1000, stem
    assert "max |G| drag-free, LISA Keplerian design" in summary.replace("\\|", "|")
    assert "summary:" in stdout and "skipped" not in summary
    assert len(list((out / "runs").glob("*.h5"))) == len({r for s in sl.STUDIES.values() for r in s.runs})


@pytest.mark.parametrize("args, match", [
    (["report", "--mission", "lisa", "x.h5"], "--mission: only applies with --studies"),
    (["report", "--studies", "--mission", "mars"], "'mars' is not allowed; allowed: 'tianqin', 'lisa'"),
    (["report", "--studies", "--mission", "lisa", "--study", "fig5"],
     "study: 'fig5' is not a study; allowed: one of the 7 names in docs/report.md#studies"),
    (["report", "--studies", "--mission", "lisa", "--quick", "--duration-scale", "0.5"], "conflicts"),
    (["report", "--studies", "--mission", "lisa", "--set", "spacecraft.tm_distance=-1"], "spacecraft.tm_distance"),
])
def test_cli_lisa_bad_input(args, match, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    status, _, err = run_cli(args, capsys)
    assert status == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("tqdyn: error: ") and match in lines[0], err
    assert not (tmp_path / "tqdyn-studies").exists()
